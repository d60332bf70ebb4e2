//! Quads of a cage as bilinear patches. A quad with corners q0 q1 q2 q3 (the
//! file's order) is `P(u, v) = (1−u)(1−v)q0 + u(1−v)q1 + uv·q2 + (1−u)v·q3`,
//! whose corner basis functions are [`bilinear_basis`]. It need not be planar,
//! and it does not depend on a diagonal: the families that take quads use the
//! patch, and only those that cannot (Green coordinates) use the two triangles
//! the cage also keeps.

use super::{triangulate_polygon, CageError, TriMesh};
use glam::DVec3;

/// A quad of a validated cage. Its corners run so that `∂P/∂u × ∂P/∂v` faces
/// outward, as the cage's triangles do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CageQuad {
    /// Cage vertices q0 q1 q2 q3: the file's order, reversed if the cage was flipped.
    pub corners: [u32; 4],
    /// The file's face it is (0-based).
    pub face: u32,
    /// The two triangles of [`super::Cage::triangles`] it was split into.
    pub triangles: [u32; 2],
}

/// How a cage's quads are split into triangles when a family is asked to bind
/// them as triangles (`--triangulate`), to reproduce results from before quads
/// were patches or to see how much the split matters.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum QuadSplit {
    /// Quads stay bilinear patches (no split).
    #[default]
    None,
    /// Along the shorter diagonal, as files were always triangulated.
    Shorter,
    /// Along the longer diagonal.
    Longer,
}

impl QuadSplit {
    pub const ALL: [QuadSplit; 3] = [QuadSplit::None, QuadSplit::Shorter, QuadSplit::Longer];

    pub fn id(self) -> &'static str {
        match self {
            QuadSplit::None => "none",
            QuadSplit::Shorter => "shorter",
            QuadSplit::Longer => "longer",
        }
    }

    pub fn from_id(id: &str) -> Option<QuadSplit> {
        Self::ALL.into_iter().find(|s| s.id() == id)
    }

    /// What a label says: "bilinear quads", "quads split along the shorter diagonal".
    pub fn describe(self) -> &'static str {
        match self {
            QuadSplit::None => "bilinear quads",
            QuadSplit::Shorter => "quads split along the shorter diagonal",
            QuadSplit::Longer => "quads split along the longer diagonal",
        }
    }
}

/// `[(1−u)(1−v), u(1−v), uv, (1−u)v]`: the weights of q0..q3 at (u, v).
#[inline]
pub fn bilinear_basis(u: f64, v: f64) -> [f64; 4] {
    [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v]
}

/// The patch's point at (u, v).
#[inline]
pub fn bilinear_point(q: &[DVec3; 4], u: f64, v: f64) -> DVec3 {
    let [a, b, c, d] = bilinear_basis(u, v);
    a * q[0] + b * q[1] + c * q[2] + d * q[3]
}

/// `∂P/∂u × ∂P/∂v` at (u, v): outward, with the patch's area element as length.
#[inline]
pub fn bilinear_normal(q: &[DVec3; 4], u: f64, v: f64) -> DVec3 {
    let along_u = (1.0 - v) * (q[1] - q[0]) + v * (q[2] - q[3]);
    let along_v = (1.0 - u) * (q[3] - q[0]) + u * (q[2] - q[1]);
    along_u.cross(along_v)
}

/// How far the patch bulges out of the surface of either split's two triangles:
/// at most this far, at its centre, where it is the normal component of
/// `(q0 − q1 + q2 − q3)/4`. Zero exactly when the four corners are coplanar.
#[inline]
pub fn out_of_plane(q: &[DVec3; 4]) -> f64 {
    let normal = (q[2] - q[0]).cross(q[3] - q[1]).normalize_or_zero();
    ((q[0] + q[2]) - (q[1] + q[3])).dot(normal).abs() * 0.25
}

/// The quads among `mesh`'s faces: every face of two triangles with four distinct
/// corners, in the file's corner order, with the triangles' indices. Also counts
/// faces of more than four corners (split into triangles, with a notice).
pub(crate) fn find_quads(mesh: &TriMesh) -> (Vec<CageQuad>, usize) {
    let mut quads = Vec::new();
    let mut polygons = 0;
    if mesh.triangle_faces.len() != mesh.triangles.len() {
        return (quads, polygons);
    }
    for run in super::polygons::face_runs(&mesh.triangle_faces) {
        let (start, face) = (run.start, mesh.triangle_faces[run.start]);
        match run.len() {
            1 => {}
            2 => {
                let [first, second] = [mesh.triangles[start], mesh.triangles[start + 1]];
                if let Some(corners) = quad_corners(first, second, &mesh.positions) {
                    quads.push(CageQuad {
                        corners,
                        face,
                        triangles: [start as u32, start as u32 + 1],
                    });
                }
            }
            _ => polygons += 1,
        }
    }
    (quads, polygons)
}

/// The quad whose split (see [`triangulate_polygon`]) gave these two triangles.
fn quad_corners(first: [u32; 3], second: [u32; 3], positions: &[DVec3]) -> Option<[u32; 4]> {
    // Along a-c: [a, b, c], [a, c, d]; along b-d: [a, b, d], [b, c, d].
    let candidates = [
        [first[0], first[1], first[2], second[2]],
        [first[0], first[1], second[1], second[2]],
    ];
    let mut cut = Vec::with_capacity(2);
    for corners in candidates {
        let distinct = (0..4).all(|i| (i + 1..4).all(|j| corners[i] != corners[j]));
        cut.clear();
        triangulate_polygon(&corners, positions, &mut cut);
        if distinct && cut == [first, second] {
            return Some(corners);
        }
    }
    None
}

/// A quad that folds over itself or is degenerate. The patch's normal is
/// bilinear in (u, v), so its component along the mean normal is smallest at a
/// corner: the quad folds exactly when a corner's normal points against the
/// mean, and is degenerate when a corner's two sides are collinear.
pub(crate) fn check_quad(
    q: &[DVec3; 4],
    corners: [u32; 4],
    face: usize,
    diagonal: f64,
) -> Result<(), CageError> {
    let corner_normals: [DVec3; 4] =
        std::array::from_fn(|k| (q[(k + 1) % 4] - q[k]).cross(q[(k + 3) % 4] - q[k]));
    let smallest = 1e-12 * diagonal * diagonal;
    for (k, normal) in corner_normals.iter().enumerate() {
        let side = |j: usize| (q[j] - q[k]).length();
        // Collinear sides: the cross product is small beside the sides' lengths.
        if normal.length() <= smallest.max(1e-9 * side((k + 1) % 4) * side((k + 3) % 4)) {
            return Err(CageError::DegenerateQuad {
                face,
                corners: [3, 0, 1].map(|j| corners[(k + j) % 4]),
            });
        }
    }
    let mean: DVec3 = corner_normals.iter().sum();
    if let Some(k) = corner_normals.iter().position(|n| n.dot(mean) <= 0.0) {
        return Err(CageError::FoldedQuad {
            face,
            corner: corners[k],
        });
    }
    Ok(())
}

/// The triangles that replace `quad` when quads are split along `split`'s diagonal.
pub fn split_quad(corners: [u32; 4], positions: &[DVec3], split: QuadSplit) -> [[u32; 3]; 2] {
    let [a, b, c, d] = corners;
    let p = |i: u32| positions[i as usize];
    let ac_shorter = p(a).distance_squared(p(c)) <= p(b).distance_squared(p(d));
    let along_ac = match split {
        QuadSplit::Longer => !ac_shorter,
        QuadSplit::None | QuadSplit::Shorter => ac_shorter,
    };
    if along_ac {
        [[a, b, c], [a, c, d]]
    } else {
        [[a, b, d], [b, c, d]]
    }
}

/// Grid points of a patch, `n + 1` per side, row v-major: for the checks that
/// need the patch itself (self-intersection, classification near the patch).
pub fn patch_grid(q: &[DVec3; 4], n: usize) -> Vec<DVec3> {
    let step = 1.0 / n as f64;
    (0..=n)
        .flat_map(|j| (0..=n).map(move |i| (i as f64 * step, j as f64 * step)))
        .map(|(u, v)| bilinear_point(q, u, v))
        .collect()
}

/// Triangles of [`patch_grid`]'s `(n + 1)²` points, outward as the patch.
pub fn patch_grid_triangles(n: usize) -> Vec<[u32; 3]> {
    let index = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut triangles = Vec::with_capacity(2 * n * n);
    for j in 0..n {
        for i in 0..n {
            let [a, b, c, d] = [
                index(i, j),
                index(i + 1, j),
                index(i + 1, j + 1),
                index(i, j + 1),
            ];
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    triangles
}

/// Grid steps per side for the patches in the self-intersection check: a
/// patch's surface is then within `out_of_plane / 16` of its grid's triangles.
const CHECK_STEPS: usize = 4;

/// Two crossing faces of a cage whose quads are patches, as indices into
/// `triangles` (a quad is named by its first triangle), or `None`. A planar
/// quad is its two triangles; a bent one is a grid of [`CHECK_STEPS`]² cells
/// that follows the patch, whose edge points are shared with the neighbouring
/// patch, so the check sees the patches and not a split of them.
pub(crate) fn find_patch_crossing(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    quads: &[CageQuad],
    diagonal: f64,
) -> Option<[usize; 2]> {
    // Relative to the cage's box, so that the grids and the orientation tests
    // round the same wherever the cage is.
    let (low, high) = positions.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(low, high), &p| (low.min(p), high.max(p)),
    );
    let centre = 0.5 * (low + high);
    let local: Vec<DVec3> = positions.iter().map(|&p| p - centre).collect();
    let positions = local.as_slice();
    let flat = 1e-9 * diagonal;
    let bent: Vec<&CageQuad> = quads
        .iter()
        .filter(|quad| out_of_plane(&quad.corners.map(|i| positions[i as usize])) > flat)
        .collect();
    if bent.is_empty() {
        let crossing = super::find_crossing(positions, triangles, diagonal)?;
        return Some([crossing.first, crossing.second]);
    }
    let mut fine_positions = positions.to_vec();
    let mut fine_triangles =
        Vec::with_capacity(triangles.len() + bent.len() * 2 * CHECK_STEPS.pow(2));
    let mut parent = Vec::with_capacity(fine_triangles.capacity());
    let mut replaced = vec![false; triangles.len()];
    for quad in &bent {
        for &t in &quad.triangles {
            replaced[t as usize] = true;
        }
    }
    for (t, triangle) in triangles.iter().enumerate() {
        if !replaced[t] {
            fine_triangles.push(*triangle);
            parent.push(t);
        }
    }
    // Points on a cage edge, keyed by the edge's ends (smaller first) and the step
    // from the smaller end, so that both patches along an edge use the same ones.
    let mut edge_points: std::collections::HashMap<(u32, u32, usize), u32> =
        std::collections::HashMap::new();
    let n = CHECK_STEPS;
    let grid_triangles = patch_grid_triangles(n);
    for quad in &bent {
        let q = quad.corners.map(|i| positions[i as usize]);
        let grid = patch_grid(&q, n);
        let [c0, c1, c2, c3] = quad.corners;
        let mut index = Vec::with_capacity(grid.len());
        for (k, point) in grid.into_iter().enumerate() {
            let (i, j) = (k % (n + 1), k / (n + 1));
            // Which cage edge the grid point is on, as (from, to, step from `from`).
            let on_edge = match (i, j) {
                (0, 0) => Some((c0, c0, 0)),
                (i, 0) if i == n => Some((c1, c1, 0)),
                (i, j) if i == n && j == n => Some((c2, c2, 0)),
                (0, j) if j == n => Some((c3, c3, 0)),
                (i, 0) => Some((c0, c1, i)),
                (i, j) if i == n => Some((c1, c2, j)),
                (i, j) if j == n => Some((c3, c2, i)),
                (0, j) => Some((c0, c3, j)),
                _ => None,
            };
            let vertex = match on_edge {
                Some((from, to, _)) if from == to => from,
                Some((from, to, step)) => {
                    let key = if from < to {
                        (from, to, step)
                    } else {
                        (to, from, n - step)
                    };
                    *edge_points.entry(key).or_insert_with(|| {
                        fine_positions.push(point);
                        (fine_positions.len() - 1) as u32
                    })
                }
                None => {
                    fine_positions.push(point);
                    (fine_positions.len() - 1) as u32
                }
            };
            index.push(vertex);
        }
        for triangle in &grid_triangles {
            fine_triangles.push(triangle.map(|k| index[k as usize]));
            parent.push(quad.triangles[0] as usize);
        }
    }
    let crossing = super::find_crossing(&fine_positions, &fine_triangles, diagonal)?;
    let (first, second) = (parent[crossing.first], parent[crossing.second]);
    Some([first.min(second), first.max(second)])
}

/// The (u, v) on quad `quad` of `cage` nearest `x`, a point found on the
/// quad's triangle `triangle` at `barycentric`: the triangle's (u, v) as a
/// start, then Gauss–Newton steps on `|P(u, v) − x|²`, kept in the square.
pub fn patch_uv_from_triangle(
    cage: &super::Cage,
    quad: usize,
    triangle: usize,
    barycentric: DVec3,
    x: DVec3,
) -> [f64; 2] {
    const CORNER_UV: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let corners = cage.quads()[quad].corners;
    let mut uv = [0.0, 0.0];
    for (k, vertex) in cage.triangles()[triangle].iter().enumerate() {
        let at = corners.iter().position(|c| c == vertex).unwrap_or(0);
        uv[0] += barycentric[k] * CORNER_UV[at][0];
        uv[1] += barycentric[k] * CORNER_UV[at][1];
    }
    nearest_uv(&cage.quad(quad), x, uv)
}

/// Gauss–Newton for the patch point nearest `x`, from `start`, in `[0, 1]²`.
pub fn nearest_uv(q: &[DVec3; 4], x: DVec3, start: [f64; 2]) -> [f64; 2] {
    let [mut u, mut v] = start;
    for _ in 0..8 {
        let residual = bilinear_point(q, u, v) - x;
        let along_u = (1.0 - v) * (q[1] - q[0]) + v * (q[2] - q[3]);
        let along_v = (1.0 - u) * (q[3] - q[0]) + u * (q[2] - q[1]);
        let (a, b, c) = (
            along_u.dot(along_u),
            along_u.dot(along_v),
            along_v.dot(along_v),
        );
        let (r_u, r_v) = (along_u.dot(residual), along_v.dot(residual));
        let det = a * c - b * b;
        if det.abs() <= f64::MIN_POSITIVE {
            break;
        }
        let du = (c * r_u - b * r_v) / det;
        let dv = (a * r_v - b * r_u) / det;
        u = (u - du).clamp(0.0, 1.0);
        v = (v - dv).clamp(0.0, 1.0);
        if du.abs().max(dv.abs()) < 1e-15 {
            break;
        }
    }
    [u, v]
}
