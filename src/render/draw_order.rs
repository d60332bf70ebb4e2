//! The mesh's indices as the viewport draws them, with no GPU: triangles
//! reordered for the vertex cache (each vertex shader invocation blends a
//! whole weights row) and each edge once for the wireframe.

/// The triangles' corners as drawn: triangles whose corners are all vertices,
/// reordered so that consecutive triangles share vertices. Each vertex shader
/// invocation blends a whole weights row, and a GPU (lavapipe too) reuses a
/// shaded vertex only while it is in its small cache.
pub fn draw_order(triangles: &[[u32; 3]], vertex_count: usize) -> Vec<u32> {
    let corners: Vec<u32> = triangles
        .iter()
        .filter(|t| t.iter().all(|&i| (i as usize) < vertex_count))
        .flatten()
        .copied()
        .collect();
    meshopt::optimize_vertex_cache(&corners, vertex_count)
}

/// Every edge of `triangles` once (as its two vertices, smaller first), in a
/// fixed order so that frames are deterministic.
pub fn unique_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut edges: Vec<[u32; 2]> = triangles
        .iter()
        .flat_map(|&[a, b, c]| [[a, b], [b, c], [c, a]])
        .map(|[u, v]| [u.min(v), u.max(v)])
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_draw_order_keeps_every_triangle_and_shares_more_vertices() {
        // A grid's triangles in a scattered order: each one far from the last.
        let side = 40u32;
        let mut triangles = Vec::new();
        for row in 0..side - 1 {
            for column in 0..side - 1 {
                let a = row * side + column;
                triangles.push([a, a + 1, a + side + 1]);
                triangles.push([a, a + side + 1, a + side]);
            }
        }
        let count = triangles.len();
        let scattered: Vec<[u32; 3]> = (0..count).map(|k| triangles[(k * 997) % count]).collect();
        let vertices = (side * side) as usize;
        let drawn = draw_order(&scattered, vertices);
        // The same triangles, each with its corners in the same cyclic order.
        let canonical = |t: &[u32]| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        };
        let mut before: Vec<[u32; 3]> = scattered.iter().map(|t| canonical(t)).collect();
        let mut after: Vec<[u32; 3]> = drawn.chunks(3).map(canonical).collect();
        before.sort_unstable();
        after.sort_unstable();
        assert_eq!(before, after);
        // Vertices shaded per vertex with a 32-entry FIFO cache.
        let shaded = |corners: &[u32]| {
            let mut cache = std::collections::VecDeque::new();
            let mut misses = 0;
            for &corner in corners {
                if !cache.contains(&corner) {
                    misses += 1;
                    cache.push_back(corner);
                    if cache.len() > 32 {
                        cache.pop_front();
                    }
                }
            }
            misses as f64 / vertices as f64
        };
        let scattered_corners: Vec<u32> = scattered.iter().flatten().copied().collect();
        assert!(shaded(&scattered_corners) > 4.0);
        assert!(shaded(&drawn) < 1.5, "{}", shaded(&drawn));
        // Corners beyond the vertices are left out rather than drawn.
        assert_eq!(draw_order(&[[0, 1, 7]], 3), Vec::<u32>::new());
    }

    #[test]
    fn two_triangles_sharing_a_side_have_five_edges() {
        let edges = unique_edges(&[[0, 1, 2], [2, 1, 3]]);
        assert_eq!(edges, vec![[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]);
    }
}
