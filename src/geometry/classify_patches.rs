//! Classification against a cage's bent quads. The winding number of the cage's
//! triangles decides every point except those between a bent patch and its two
//! triangles: there the patch and the split disagree. The patch with its two
//! triangles reversed is a closed "pillow", whose winding number is ±1 exactly
//! for those points and 0 elsewhere; it is taken on a grid of
//! [`PILLOW_STEPS`]² cells that follows the patch to `out_of_plane / 1024`.
//! Only points inside the hull of the quad's four corners, which holds the
//! whole pillow, are tested. Points on a patch (within the surface tolerance)
//! are on the surface; points on a bent quad's triangle but off its patch take
//! the side of the patch they are on.

use super::quads::{
    bilinear_normal, bilinear_point, nearest_uv, out_of_plane, patch_grid, patch_grid_triangles,
};
use super::{closest_offset_on_triangle, Cage, PointClass};
use glam::DVec3;

/// Grid steps per side of the pillow's patch.
const PILLOW_STEPS: usize = 32;

/// A bent quad, prepared once per classification.
pub(super) struct BentQuad {
    quad: usize,
    /// Outward planes of the corners' tetrahedron, as (point on it, normal).
    hull: [(DVec3, DVec3); 4],
    /// The patch's grid, relative to the quad's centre.
    grid: Vec<DVec3>,
    /// Points closer than this to the patch take the side of the patch they
    /// are on: ten times how far the pillow's grid strays from the patch.
    near: f64,
}

/// The cage's quads that are not planar within `tolerance`.
pub(super) fn bent_quads(cage: &Cage, tolerance: f64) -> Vec<BentQuad> {
    (0..cage.quads().len())
        .filter_map(|k| {
            let q = cage.quad(k);
            let bend = out_of_plane(&q);
            (bend > tolerance).then(|| BentQuad {
                quad: k,
                hull: tetrahedron_planes(&q),
                grid: {
                    let centre = (q[0] + q[1] + q[2] + q[3]) * 0.25;
                    patch_grid(&q.map(|p| p - centre), PILLOW_STEPS)
                },
                near: 10.0 * bend / (PILLOW_STEPS * PILLOW_STEPS) as f64,
            })
        })
        .collect()
}

fn tetrahedron_planes(q: &[DVec3; 4]) -> [(DVec3, DVec3); 4] {
    let centre = (q[0] + q[1] + q[2] + q[3]) * 0.25;
    std::array::from_fn(|k| {
        let [a, b, c] = [q[k], q[(k + 1) % 4], q[(k + 2) % 4]];
        let normal = (b - a).cross(c - a);
        let normal = if normal.dot(centre - a) > 0.0 {
            -normal
        } else {
            normal
        };
        (a, normal.normalize_or_zero())
    })
}

/// The class of `x` given its class against the triangles, `first`.
pub(super) fn correct_class(
    cage: &Cage,
    bent: &[BentQuad],
    grid_triangles: &[[u32; 3]],
    x: DVec3,
    first: PointClass,
    tolerance: f64,
) -> PointClass {
    for quad in bent {
        if quad.hull.iter().any(|&(a, n)| n.dot(x - a) > tolerance) {
            continue;
        }
        // Relative to the quad's centre, so that the class does not depend on
        // where the scene is (tests/coords/origin_offsets.rs).
        let corners = cage.quad(quad.quad);
        let centre = (corners[0] + corners[1] + corners[2] + corners[3]) * 0.25;
        let q = corners.map(|p| p - centre);
        let local = x - centre;
        let halves = cage.quads()[quad.quad].triangles;
        let uv = nearest_uv(&q, local, [0.5, 0.5]);
        let offset = local - bilinear_point(&q, uv[0], uv[1]);
        if offset.length_squared() <= tolerance * tolerance {
            let t = halves[0] as usize;
            let [a, b, c] = cage.triangle(t);
            let (_, barycentric) = closest_offset_on_triangle(x - offset, a, b, c);
            return PointClass::OnSurface {
                triangle: halves[0],
                barycentric,
            };
        }
        let on_a_half =
            matches!(first, PointClass::OnSurface { triangle, .. } if halves.contains(&triangle));
        // Near the patch, closer than the pillow grid follows it, the side of
        // the patch decides; farther, the pillow's winding number.
        if on_a_half || offset.length() < quad.near {
            let inner = offset.dot(bilinear_normal(&q, uv[0], uv[1])) < 0.0;
            return if inner {
                PointClass::Inside
            } else {
                PointClass::Outside
            };
        }
        let winding = pillow_winding(cage, quad, grid_triangles, halves, centre, local);
        if winding > 0.5 {
            return PointClass::Inside;
        }
        if winding < -0.5 {
            return PointClass::Outside;
        }
    }
    first
}

/// Winding number at `x` of the patch's grid with the quad's two triangles reversed.
fn pillow_winding(
    cage: &Cage,
    quad: &BentQuad,
    grid_triangles: &[[u32; 3]],
    halves: [u32; 2],
    centre: DVec3,
    x: DVec3,
) -> f64 {
    let solid = |[a, b, c]: [DVec3; 3]| {
        let (a, b, c) = (a - x, b - x, c - x);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let numerator = a.dot(b.cross(c));
        let denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        2.0 * numerator.atan2(denominator)
    };
    let patch: f64 = grid_triangles
        .iter()
        .map(|t| solid(t.map(|i| quad.grid[i as usize])))
        .sum();
    let split: f64 = halves
        .iter()
        .map(|&t| solid(cage.triangle(t as usize).map(|p| p - centre)))
        .sum();
    (patch - split) / (4.0 * std::f64::consts::PI)
}

/// The grid's triangles, shared by every bent quad.
pub(super) fn pillow_triangles() -> Vec<[u32; 3]> {
    patch_grid_triangles(PILLOW_STEPS)
}
