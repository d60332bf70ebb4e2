//! Self-intersection of a closed triangle mesh: two triangles that cross, a
//! triangle folded flat onto its neighbour, and shells nested with the same
//! orientation. A cage that crosses itself has no well-defined inside, and MVC
//! then go far negative even for points that look inside.

use glam::DVec3;

/// Two triangles (indices into the triangle list) that cross each other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crossing {
    pub first: usize,
    pub second: usize,
}

/// The first pair of crossing triangles, in order of the first triangle, or
/// `None`. Contacts within rounding of the mesh's size `diagonal` (1e-9 of it
/// for distances, 1e-12 of its cube for the orientation volumes) count as
/// touching, not crossing.
pub fn find_crossing(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    diagonal: f64,
) -> Option<Crossing> {
    let tolerance = 1e-9 * diagonal;
    let volume_tolerance = 1e-12 * diagonal.powi(3);
    let corners = |t: usize| triangles[t].map(|i| positions[i as usize]);
    let boxes: Vec<(DVec3, DVec3)> = (0..triangles.len())
        .map(|t| {
            let [a, b, c] = corners(t);
            (
                a.min(b).min(c) - DVec3::splat(tolerance),
                a.max(b).max(c) + DVec3::splat(tolerance),
            )
        })
        .collect();
    // Sweep along x: candidate pairs overlap in x, then in y and z.
    let mut order: Vec<usize> = (0..triangles.len()).collect();
    order.sort_unstable_by(|&a, &b| boxes[a].0.x.total_cmp(&boxes[b].0.x));
    let mut best: Option<Crossing> = None;
    for (rank, &s) in order.iter().enumerate() {
        for &t in &order[rank + 1..] {
            if boxes[t].0.x > boxes[s].1.x {
                break;
            }
            let overlaps = boxes[s].0.cmple(boxes[t].1).all() && boxes[t].0.cmple(boxes[s].1).all();
            if !overlaps {
                continue;
            }
            let (first, second) = (s.min(t), s.max(t));
            if best.is_some_and(|b| (b.first, b.second) <= (first, second)) {
                continue;
            }
            if triangles_cross(
                triangles[first],
                triangles[second],
                positions,
                volume_tolerance,
                tolerance,
            ) {
                best = Some(Crossing { first, second });
            }
        }
    }
    best
}

/// Whether two triangles of the mesh cross: an edge of one passes through the
/// other's interior, or, sharing an edge, one is folded flat onto the other.
pub(crate) fn triangles_cross(
    first: [u32; 3],
    second: [u32; 3],
    positions: &[DVec3],
    volume_tolerance: f64,
    tolerance: f64,
) -> bool {
    let shared = first.iter().filter(|i| second.contains(i)).count();
    let p = first.map(|i| positions[i as usize]);
    let q = second.map(|i| positions[i as usize]);
    match shared {
        // The same triangle twice is a non-manifold edge, caught before.
        3 => false,
        2 => {
            // Folded flat: the vertex opposite the shared edge lies in the other
            // triangle's plane and inside it.
            let apex_of = |tri: [u32; 3], other: [u32; 3]| {
                tri.iter().position(|i| !other.contains(i)).unwrap_or(0)
            };
            let (a, b) = (apex_of(first, second), apex_of(second, first));
            lies_inside(q[b], p, tolerance) || lies_inside(p[a], q, tolerance)
        }
        // Proper crossings of an edge through the other triangle. Edges through a
        // shared vertex touch the other triangle there, which is not a crossing.
        // Each corner's side of the other triangle's plane is computed once
        // (it was twice, once per edge): most pairs the checks ask about
        // have no edge between corners strictly on opposite sides.
        _ => {
            let p_sides = p.map(|corner| orient(q[0], q[1], q[2], corner));
            let q_sides = q.map(|corner| orient(p[0], p[1], p[2], corner));
            (0..3).any(|k| {
                let l = (k + 1) % 3;
                segment_crosses((p[k], p[l]), (p_sides[k], p_sides[l]), q, volume_tolerance)
                    || segment_crosses((q[k], q[l]), (q_sides[k], q_sides[l]), p, volume_tolerance)
            })
        }
    }
}

/// Six times the signed volume of the tetrahedron (a, b, c, d).
fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    (b - a).cross(c - a).dot(d - a)
}

/// The open segment (p, q) passes through the interior of `triangle`: its ends
/// are strictly on opposite sides of the plane (`sp` and `sq`, their
/// `orient` against the triangle) and it passes strictly inside all three
/// edges.
fn segment_crosses(
    (p, q): (DVec3, DVec3),
    (sp, sq): (f64, f64),
    [a, b, c]: [DVec3; 3],
    tolerance: f64,
) -> bool {
    if !((sp > tolerance && sq < -tolerance) || (sp < -tolerance && sq > tolerance)) {
        return false;
    }
    let sides = [orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a)];
    sides.iter().all(|&s| s > tolerance) || sides.iter().all(|&s| s < -tolerance)
}

/// `point` is within `tolerance` of the plane of `triangle` and strictly inside it.
fn lies_inside(point: DVec3, [a, b, c]: [DVec3; 3], tolerance: f64) -> bool {
    let normal = (b - a).cross(c - a);
    let area = normal.length();
    if area == 0.0 || (point - a).dot(normal).abs() / area > tolerance {
        return false;
    }
    let inside_edge = |u: DVec3, v: DVec3| (v - u).cross(point - u).dot(normal) > tolerance * area;
    inside_edge(a, b) && inside_edge(b, c) && inside_edge(c, a)
}

/// A shell (connected component) that is not where its orientation says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShellProblem {
    /// The shell of triangle `inner` lies inside the shell of triangle `outer`,
    /// and both face outward: the space inside both would count twice.
    Nested { inner: usize, outer: usize },
    /// The shell of triangle `shell` faces inward but is inside no other shell,
    /// so it is not a cavity.
    InwardAlone { shell: usize },
}

/// Check that every shell of an outward-oriented mesh is either a solid (facing
/// outward, inside no other shell) or a cavity (facing inward, inside exactly
/// one). Returns the first shell that is neither, by its first triangle.
pub fn check_shells(positions: &[DVec3], triangles: &[[u32; 3]]) -> Option<ShellProblem> {
    let shells = shells(positions.len(), triangles);
    if shells.len() < 2 {
        return None;
    }
    let volume = |shell: &[usize]| -> f64 {
        let shell_triangles: Vec<[u32; 3]> = shell.iter().map(|&t| triangles[t]).collect();
        super::cage::signed_volume(positions, &shell_triangles)
    };
    for (s, shell) in shells.iter().enumerate() {
        let probe = positions[triangles[shell[0]][0] as usize];
        let mut depth = 0.0;
        let mut container = None;
        for (t, other) in shells.iter().enumerate() {
            if s == t {
                continue;
            }
            let w = winding_number(positions, triangles, other, probe);
            if w.abs() > 0.5 {
                container.get_or_insert(other[0]);
            }
            depth += w;
        }
        let outward = volume(shell) > 0.0;
        match (outward, depth.round() as i64, container) {
            (true, 0, _) | (false, 1, _) => {}
            (true, _, Some(outer)) => {
                return Some(ShellProblem::Nested {
                    inner: shell[0],
                    outer,
                })
            }
            _ => return Some(ShellProblem::InwardAlone { shell: shell[0] }),
        }
    }
    None
}

/// Triangles grouped by connected component (through shared vertices), each
/// group ascending, groups in order of their first triangle.
fn shells(vertex_count: usize, triangles: &[[u32; 3]]) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..vertex_count).collect();
    fn root(parent: &mut [usize], mut v: usize) -> usize {
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }
    for triangle in triangles {
        let a = root(&mut parent, triangle[0] as usize);
        for &corner in &triangle[1..] {
            let b = root(&mut parent, corner as usize);
            parent[b] = a;
        }
    }
    let mut groups: Vec<(usize, Vec<usize>)> = Vec::new();
    for (t, triangle) in triangles.iter().enumerate() {
        let r = root(&mut parent, triangle[0] as usize);
        match groups.iter_mut().find(|(root, _)| *root == r) {
            Some((_, group)) => group.push(t),
            None => groups.push((r, vec![t])),
        }
    }
    groups.into_iter().map(|(_, group)| group).collect()
}

/// Generalised winding number of the triangles `subset` at `x` (Van Oosterom and
/// Strackee's solid angle, over 4π).
fn winding_number(positions: &[DVec3], triangles: &[[u32; 3]], subset: &[usize], x: DVec3) -> f64 {
    let total: f64 = subset
        .iter()
        .map(|&t| {
            let [a, b, c] = triangles[t].map(|i| positions[i as usize] - x);
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let numerator = a.dot(b.cross(c));
            let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            2.0 * numerator.atan2(denominator)
        })
        .sum();
    total / (4.0 * std::f64::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        (
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
    }

    #[test]
    fn a_tetrahedron_does_not_cross_itself() {
        let (positions, triangles) = tetra();
        assert_eq!(find_crossing(&positions, &triangles, 2.0), None);
    }

    /// The cube of side 1 around the origin with corner 7 = (½, ½, ½) moved to
    /// `corner`.
    fn cube_with_corner(corner: DVec3) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let cube = crate::geometry::procedural::cube_cage(0.5);
        let mut positions = cube.positions().to_vec();
        positions[7] = corner;
        (positions, cube.triangles().to_vec())
    }

    #[test]
    fn a_corner_pushed_through_the_opposite_faces_crosses_them() {
        let (positions, triangles) = cube_with_corner(DVec3::splat(0.5));
        assert_eq!(find_crossing(&positions, &triangles, 2.0), None);
        let (positions, triangles) = cube_with_corner(DVec3::new(-1.0, 0.0, 0.0));
        let crossing = find_crossing(&positions, &triangles, 2.0).expect("crossing");
        // One of the two is on the face x = −½ the corner went through.
        let on_x0 = |t: usize| {
            triangles[t]
                .iter()
                .all(|&i| positions[i as usize].x == -0.5)
        };
        assert!(
            on_x0(crossing.first) || on_x0(crossing.second),
            "{crossing:?}"
        );
    }

    #[test]
    fn two_separate_tetrahedra_do_not_cross_but_overlapping_ones_do() {
        let (positions, triangles) = tetra();
        let shifted = |offset: DVec3| {
            let mut all = positions.clone();
            all.extend(positions.iter().map(|&p| p + offset));
            let mut tris = triangles.clone();
            tris.extend(triangles.iter().map(|t| t.map(|i| i + 4)));
            (all, tris)
        };
        let (apart, tris) = shifted(DVec3::new(3.0, 0.0, 0.0));
        assert_eq!(find_crossing(&apart, &tris, 5.0), None);
        let (overlapping, tris) = shifted(DVec3::new(0.2, 0.2, 0.2));
        assert!(find_crossing(&overlapping, &tris, 2.0).is_some());
    }

    /// A big tetrahedron around a small one (scaled about an inside point).
    fn nested(inner_reversed: bool) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let (positions, triangles) = tetra();
        let centre = DVec3::splat(0.25);
        let mut all: Vec<DVec3> = positions
            .iter()
            .map(|&p| centre + (p - centre) * 4.0)
            .collect();
        all.extend(positions.iter().map(|&p| centre + (p - centre) * 0.5));
        let mut tris = triangles.clone();
        tris.extend(triangles.iter().map(|t| {
            let mut t = t.map(|i| i + 4);
            if inner_reversed {
                t.reverse();
            }
            t
        }));
        (all, tris)
    }

    #[test]
    fn a_cavity_is_a_shell_but_a_solid_inside_a_solid_is_not() {
        let (positions, triangles) = nested(true);
        assert_eq!(find_crossing(&positions, &triangles, 8.0), None);
        assert_eq!(check_shells(&positions, &triangles), None);
        let (positions, triangles) = nested(false);
        assert_eq!(
            check_shells(&positions, &triangles),
            Some(ShellProblem::Nested { inner: 4, outer: 0 })
        );
    }

    #[test]
    fn an_inward_shell_on_its_own_is_not_a_cavity() {
        let (positions, triangles) = tetra();
        let mut all = positions.clone();
        all.extend(positions.iter().map(|&p| p + DVec3::new(5.0, 0.0, 0.0)));
        let mut tris = triangles.clone();
        tris.extend(triangles.iter().map(|t| {
            let mut t = t.map(|i| i + 4);
            t.reverse();
            t
        }));
        assert_eq!(
            check_shells(&all, &tris),
            Some(ShellProblem::InwardAlone { shell: 4 })
        );
    }
}
