//! Where mesh vertices lie relative to the cage: inside, outside, or on its surface.
//!
//! Inside/outside is decided by the generalized winding number (the solid angle the
//! cage subtends, over 4π), which stays correct for points near the surface and for
//! cages with small defects, where ray-parity tests flip. A cage's bent quads are
//! bilinear patches, not their triangles: points between the two are corrected by
//! [`super::classify_patches`].

use super::Cage;
use glam::DVec3;
use rayon::prelude::*;

/// Points closer than this fraction of the cage diagonal count as on the surface.
pub const SURFACE_TOLERANCE: f64 = 1e-9;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PointClass {
    Inside,
    Outside,
    /// On triangle `triangle`, at these barycentric coordinates of its corners.
    OnSurface {
        triangle: u32,
        barycentric: DVec3,
    },
}

/// The classes of a point set, with the outside ones listed for reporting.
#[derive(Clone, Debug, Default)]
pub struct PointClasses {
    pub classes: Vec<PointClass>,
    /// Indices of the points outside the cage, ascending.
    pub outside: Vec<u32>,
}

/// Classify every point against the cage (in parallel).
pub fn classify_points(cage: &Cage, points: &[DVec3]) -> PointClasses {
    let tolerance = SURFACE_TOLERANCE * cage.diagonal();
    // Unit normal and a corner of each triangle's plane: a point farther than the
    // tolerance from the plane cannot be on the triangle, which spares most
    // closest-point computations. The distance is taken from the corner, not as
    // `n·x − n·a`, whose two terms far from the origin round by more than the
    // tolerance.
    let planes: Vec<(DVec3, DVec3)> = (0..cage.triangles().len())
        .map(|t| {
            let [a, b, c] = cage.triangle(t);
            ((b - a).cross(c - a).normalize_or_zero(), a)
        })
        .collect();
    let bent = super::classify_patches::bent_quads(cage, tolerance);
    let pillow = super::classify_patches::pillow_triangles();
    let classes: Vec<PointClass> = points
        .par_iter()
        .map_init(Vec::new, |corners, &x| {
            let class = classify_point(cage, &planes, x, tolerance, corners);
            if bent.is_empty() {
                class
            } else {
                super::classify_patches::correct_class(cage, &bent, &pillow, x, class, tolerance)
            }
        })
        .collect();
    let outside = classes
        .iter()
        .enumerate()
        .filter(|(_, c)| matches!(c, PointClass::Outside))
        .map(|(i, _)| i as u32)
        .collect();
    PointClasses { classes, outside }
}

fn classify_point(
    cage: &Cage,
    planes: &[(DVec3, DVec3)],
    x: DVec3,
    tolerance: f64,
    corners: &mut Vec<Corner>,
) -> PointClass {
    let tolerance_squared = tolerance * tolerance;
    for (t, &(normal, corner)) in planes.iter().enumerate() {
        if normal.dot(x - corner).abs() > tolerance && normal != DVec3::ZERO {
            continue;
        }
        let [a, b, c] = cage.triangle(t);
        let (offset, barycentric) = closest_offset_on_triangle(x, a, b, c);
        if offset.length_squared() <= tolerance_squared {
            return PointClass::OnSurface {
                triangle: t as u32,
                barycentric,
            };
        }
    }
    if is_enclosed(cage, x, corners) {
        PointClass::Inside
    } else {
        PointClass::Outside
    }
}

/// Σ over triangles of their signed solid angle seen from `x`, over 4π (Van Oosterom
/// and Strackee). 1 inside an outward cage, 0 outside.
pub fn generalized_winding_number(cage: &Cage, x: DVec3) -> f64 {
    let corners = &mut Vec::new();
    set_corners(cage, x, corners);
    winding_number_with(cage, corners, f64::atan2)
}

/// A cage vertex relative to the point, and its distance.
type Corner = (DVec3, f64);

/// Every cage vertex relative to `x`: each is shared by about six triangles, so this
/// spares most of the square roots.
fn set_corners(cage: &Cage, x: DVec3, corners: &mut Vec<Corner>) {
    corners.clear();
    corners.extend(cage.positions().iter().map(|&p| {
        let relative = p - x;
        (relative, relative.length())
    }));
}

/// `generalized_winding_number(cage, x) > 0.5`, decided first with a fast arctangent
/// (error below 2e-5 per triangle, so below 0.25 in total for fewer than 75,000
/// triangles) and redone exactly when that estimate is not clearly 0 or 1.
fn is_enclosed(cage: &Cage, x: DVec3, corners: &mut Vec<Corner>) -> bool {
    set_corners(cage, x, corners);
    let estimate = fast_winding_number(cage, corners);
    if (estimate - 0.5).abs() >= 0.25 {
        return estimate > 0.5;
    }
    winding_number_with(cage, corners, f64::atan2) > 0.5
}

#[inline(always)]
fn winding_number_with(cage: &Cage, corners: &[Corner], atan2: impl Fn(f64, f64) -> f64) -> f64 {
    let mut total = 0.0;
    for triangle in cage.triangles() {
        total += 2.0 * half_solid_angle_with(triangle, corners, &atan2);
    }
    total / (4.0 * std::f64::consts::PI)
}

/// [`winding_number_with`] with [`fast_atan2`], summed in four lanes so that the loop
/// is vectorised (the order of the sum only moves the last bits of the estimate).
fn fast_winding_number(cage: &Cage, corners: &[Corner]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has just been checked to support AVX2.
        return unsafe { fast_winding_number_avx2(cage, corners) };
    }
    fast_winding_number_any_cpu(cage, corners)
}

/// The same code compiled for AVX2, four triangles at a time.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn fast_winding_number_avx2(cage: &Cage, corners: &[Corner]) -> f64 {
    fast_winding_number_any_cpu(cage, corners)
}

#[inline(always)]
fn fast_winding_number_any_cpu(cage: &Cage, corners: &[Corner]) -> f64 {
    let mut lanes = [0.0; 4];
    let chunks = cage.triangles().chunks_exact(4);
    let rest = chunks.remainder();
    for chunk in chunks {
        for (lane, triangle) in lanes.iter_mut().zip(chunk) {
            *lane += half_solid_angle_with(triangle, corners, fast_atan2);
        }
    }
    for (lane, triangle) in lanes.iter_mut().zip(rest) {
        *lane += half_solid_angle_with(triangle, corners, fast_atan2);
    }
    2.0 * lanes.iter().sum::<f64>() / (4.0 * std::f64::consts::PI)
}

/// Half the signed solid angle of one triangle seen from the point the corners are
/// relative to.
#[inline(always)]
fn half_solid_angle_with(
    triangle: &[u32; 3],
    corners: &[Corner],
    atan2: impl Fn(f64, f64) -> f64,
) -> f64 {
    let [(a, la), (b, lb), (c, lc)] = triangle.map(|i| corners[i as usize]);
    let numerator = a.dot(b.cross(c));
    let denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    atan2(numerator, denominator)
}

/// `y.atan2(x)` within 2e-5 (Abramowitz and Stegun 4.4.49 on the octant), with the
/// same quadrants and signed zeros; 0 at the origin.
#[inline(always)]
fn fast_atan2(y: f64, x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    // Selects rather than branches, so that loops over triangles vectorise.
    let (ax, ay) = (x.abs(), y.abs());
    let (low, high) = if ax < ay { (ax, ay) } else { (ay, ax) };
    let a = if high == 0.0 { 0.0 } else { low / high };
    let s = a * a;
    let angle =
        a * (0.999_866 + s * (-0.330_299_5 + s * (0.180_141 + s * (-0.085_133 + s * 0.020_835_1))));
    let angle = if ay > ax { FRAC_PI_2 - angle } else { angle };
    let angle = if x.is_sign_negative() {
        PI - angle
    } else {
        angle
    };
    if high == 0.0 {
        0.0
    } else {
        angle.copysign(y)
    }
}

/// The closest point to `p` on triangle `abc` as an offset from `p`, and its
/// barycentric coordinates. Built from the corners relative to `p`, so the
/// distance keeps its precision far from the origin, where the absolute closest
/// point of [`closest_point_on_triangle`] is rounded to the coordinates' spacing.
pub fn closest_offset_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (DVec3, DVec3) {
    let (_, barycentric) = closest_point_on_triangle(p, a, b, c);
    let offset = (a - p) * barycentric.x + (b - p) * barycentric.y + (c - p) * barycentric.z;
    (offset, barycentric)
}

/// Closest point to `p` on triangle `abc` and its barycentric coordinates
/// (Ericson, Real-Time Collision Detection, 5.1.5).
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (DVec3, DVec3) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, DVec3::X);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, DVec3::Y);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, DVec3::new(1.0 - v, v, 0.0));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, DVec3::Z);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, DVec3::new(1.0 - w, 0.0, w));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), DVec3::new(0.0, 1.0 - w, w));
    }
    let denominator = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denominator, vc * denominator);
    (a + ab * v + ac * w, DVec3::new(1.0 - v - w, v, w))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_atan2_is_within_its_bound_in_every_quadrant() {
        let mut worst = 0.0f64;
        for i in 0..3600 {
            let angle = (f64::from(i) + 0.5) * std::f64::consts::PI / 1800.0 - std::f64::consts::PI;
            for radius in [1e-300, 1e-3, 1.0, 1e12] {
                let (y, x) = (radius * angle.sin(), radius * angle.cos());
                worst = worst.max((fast_atan2(y, x) - y.atan2(x)).abs());
            }
        }
        assert!(worst < 2e-5, "{worst}");
        for (y, x) in [
            (0.0, 1.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
        ] {
            assert!(
                (fast_atan2(y, x) - f64::atan2(y, x)).abs() < 1e-12,
                "({y}, {x})"
            );
        }
    }
}
