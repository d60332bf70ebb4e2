//! How far each voxel is from a set of voxels, in cells, by the chessboard
//! (Chebyshev) metric: the envelope the simplified cage may not leave.
//!
//! Two raster passes (Rosenfeld and Pfaltz 1966), each taking from the 13
//! neighbours already passed: in an open grid any shortest path can put its
//! steps forward in raster order first and the rest after, so the passes are
//! exact. A breadth-first search over the 26 neighbours gave the same
//! distances at about five times the work (7 % of a generation on the
//! bundled scan).

/// Distances from the cells where `inside` holds (x fastest, then y, then
/// z), saturating at `u16::MAX`.
pub(super) fn distance_from_set(inside: &[bool], dims: [usize; 3]) -> Vec<u16> {
    let mut distance: Vec<u16> = inside
        .iter()
        .map(|&set| if set { 0 } else { u16::MAX })
        .collect();
    forward_pass(&mut distance, dims);
    // The backward pass is the forward one over the grid turned end to end,
    // which is the grid reflected through its centre.
    distance.reverse();
    forward_pass(&mut distance, dims);
    distance.reverse();
    distance
}

/// Lower each cell to one more than its least neighbour among those before
/// it in raster order: the whole plane below (3 × 3), the row before in its
/// plane (3 cells) and the cell before in its row.
fn forward_pass(distance: &mut [u16], [nx, ny, nz]: [usize; 3]) {
    let plane = nx * ny;
    let mut below = vec![u16::MAX; plane];
    let mut rows = vec![u16::MAX; plane];
    let mut before = vec![u16::MAX; nx];
    for z in 0..nz {
        if z > 0 {
            // The least of each 3 × 3 block of the plane below.
            let previous = &distance[(z - 1) * plane..z * plane];
            for y in 0..ny {
                min_of_three(
                    &previous[y * nx..(y + 1) * nx],
                    &mut rows[y * nx..(y + 1) * nx],
                );
            }
            for y in 0..ny {
                for x in 0..nx {
                    let mut least = rows[y * nx + x];
                    if y > 0 {
                        least = least.min(rows[(y - 1) * nx + x]);
                    }
                    if y + 1 < ny {
                        least = least.min(rows[(y + 1) * nx + x]);
                    }
                    below[y * nx + x] = least;
                }
            }
        }
        let current = &mut distance[z * plane..(z + 1) * plane];
        for y in 0..ny {
            if y > 0 {
                min_of_three(&current[(y - 1) * nx..y * nx], &mut before);
            }
            let row = &mut current[y * nx..(y + 1) * nx];
            let mut previous_cell = u16::MAX;
            for x in 0..nx {
                let mut least = previous_cell;
                if z > 0 {
                    least = least.min(below[y * nx + x]);
                }
                if y > 0 {
                    least = least.min(before[x]);
                }
                row[x] = row[x].min(least.saturating_add(1));
                previous_cell = row[x];
            }
        }
    }
}

/// Each cell's least value among itself and its two neighbours in the row.
fn min_of_three(source: &[u16], target: &mut [u16]) {
    let n = source.len();
    for x in 0..n {
        let mut least = source[x];
        if x > 0 {
            least = least.min(source[x - 1]);
        }
        if x + 1 < n {
            least = least.min(source[x + 1]);
        }
        target[x] = least;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::procedural::SplitMix64;

    /// Against the definition: the least, over the set's cells, of the
    /// largest coordinate difference.
    fn by_definition(inside: &[bool], [nx, ny, _]: [usize; 3]) -> Vec<u16> {
        let at = |i: usize| [i % nx, (i / nx) % ny, i / (nx * ny)];
        let set: Vec<[usize; 3]> = (0..inside.len()).filter(|&i| inside[i]).map(at).collect();
        (0..inside.len())
            .map(|i| {
                let c = at(i);
                set.iter()
                    .map(|s| (0..3).map(|k| c[k].abs_diff(s[k])).max().unwrap_or(0))
                    .min()
                    .map_or(u16::MAX, |d| d as u16)
            })
            .collect()
    }

    #[test]
    fn two_passes_give_the_chessboard_distance() {
        let mut random = SplitMix64(5);
        // Sparse sets leave long distances; thin grids test the borders.
        for (dims, density) in [
            ([9, 7, 6], 0.01),
            ([5, 11, 8], 0.05),
            ([1, 6, 9], 0.1),
            ([12, 1, 1], 0.2),
            ([8, 8, 8], 0.002),
        ] {
            let count = dims[0] * dims[1] * dims[2];
            let mut inside: Vec<bool> = (0..count).map(|_| random.unit() < density).collect();
            inside[count / 3] = true;
            assert_eq!(
                distance_from_set(&inside, dims),
                by_definition(&inside, dims),
                "{dims:?}"
            );
        }
    }

    #[test]
    fn an_empty_set_is_infinitely_far() {
        let distance = distance_from_set(&[false; 24], [2, 3, 4]);
        assert!(distance.iter().all(|&d| d == u16::MAX));
    }
}
