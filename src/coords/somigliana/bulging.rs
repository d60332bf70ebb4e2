//! The tractions of the global variant with the paper's bulging term: how hard
//! each cage triangle pushes along its rotated normal in a pose.
//!
//! Each triangle is taken to stretch by s (the fitted similarity's scale) along
//! the surface and by `h_f = s exp(γ² V_f / V)` along its normal, where V_f is
//! the signed volume swept from the triangle as the similarity alone would
//! place it to where the pose puts it (positive where the pose pushes the
//! surface outward) and V the rest cage's volume; γ = 0 gives h = s, the plain
//! dilation. The traction of that stretch, per unit of the face blocks'
//! constant c(ν) μ (see the module doc), is
//! `t_f = (h_f (1 − ν) + 2 ν s) / (1 + ν)`, which is s at γ = 0. With γ > 0 the
//! tractions differ between triangles, so they are projected, least squares
//! weighted by area, onto those with zero net force `Σ A_f t_f n_f = 0` (a body
//! at rest under its boundary tractions); equal tractions already have it.

use super::fit::SimilarityFit;
use crate::geometry::Cage;
use glam::{DMat3, DVec3};

/// Each triangle's traction factor t_f ([`Cage::triangles`] order): its face
/// vector in the pose is `t_f R n_f`. `pose` has one finite position per cage
/// vertex (the caller checks).
pub(super) fn face_tractions(
    rest: &Cage,
    pose: &[DVec3],
    fit: &SimilarityFit,
    poisson_ratio: f64,
    bulging: f64,
) -> Vec<f64> {
    let scale = fit.scale;
    let triangles = rest.triangle_count();
    if bulging == 0.0 {
        return vec![scale; triangles];
    }
    let volume = rest.signed_volume().abs();
    if volume <= 0.0 || !volume.is_finite() {
        return vec![scale; triangles];
    }
    // Where the similarity alone puts each vertex, about the centroids (not
    // the origin, so a cage far from it loses no digits).
    let count = rest.vertex_count().max(1) as f64;
    let rest_centre = rest.positions().iter().sum::<DVec3>() / count;
    let posed_centre = pose.iter().sum::<DVec3>() / count;
    let fitted =
        |v: usize| posed_centre + scale * (fit.rotation * (rest.positions()[v] - rest_centre));
    let mut tractions: Vec<f64> = rest
        .triangles()
        .iter()
        .map(|&[a, b, c]| {
            let (a, b, c) = (a as usize, b as usize, c as usize);
            let swept = swept_volume(
                [pose[a], pose[b], pose[c]],
                [fitted(a), fitted(b), fitted(c)],
            );
            let normal_stretch = scale * (bulging * bulging * swept / volume).exp();
            (normal_stretch * (1.0 - poisson_ratio) + 2.0 * poisson_ratio * scale)
                / (1.0 + poisson_ratio)
        })
        .collect();
    without_net_force(rest, &mut tractions);
    tractions
}

/// The signed volume between triangle `from` and triangle `to` with straight
/// paths between corresponding corners: positive when `to` lies on the outer
/// side of `from` (the side its normal, by corner order, points to). The side
/// walls are bilinear patches, whose flux is the mean of their two
/// triangulations'; taken about `to`'s first corner, not the origin.
pub(super) fn swept_volume(to: [DVec3; 3], from: [DVec3; 3]) -> f64 {
    let origin = to[0];
    let tetra =
        |a: DVec3, b: DVec3, c: DVec3| (a - origin).dot((b - origin).cross(c - origin)) / 6.0;
    // A patch a, b, c, d (in order round its edge, outward).
    let patch = |a: DVec3, b: DVec3, c: DVec3, d: DVec3| {
        0.5 * (tetra(a, b, c) + tetra(a, c, d) + tetra(a, b, d) + tetra(b, c, d))
    };
    let mut total = tetra(to[0], to[1], to[2]) + tetra(from[2], from[1], from[0]);
    for i in 0..3 {
        let j = (i + 1) % 3;
        total += patch(to[j], to[i], from[i], from[j]);
    }
    total
}

/// Project `tractions` onto zero net force, least squares weighted by area:
/// `t_f ← t_f − n_f · z` with `(Σ A_f n_f n_fᵀ) z = Σ A_f t_f n_f` (rest
/// normals; the pose's common rotation drops out).
fn without_net_force(rest: &Cage, tractions: &mut [f64]) {
    let (areas, normals): (Vec<f64>, Vec<DVec3>) = (0..rest.triangle_count())
        .map(|t| {
            let [a, b, c] = rest.triangle(t);
            let area_normal = (b - a).cross(c - a) / 2.0;
            (area_normal.length(), area_normal.normalize_or_zero())
        })
        .unzip();
    without_net_force_along(&areas, &normals, tractions);
}

/// Project `tractions`, pushing along the unit `directions` over triangles of
/// `areas`, onto zero net force, least squares weighted by area: `t_f ← t_f −
/// d_f · z` with `(Σ A_f d_f d_fᵀ) z = Σ A_f t_f d_f`. Left as they are where
/// the system is singular (a flat cage).
pub(super) fn without_net_force_along(areas: &[f64], directions: &[DVec3], tractions: &mut [f64]) {
    let mut system = DMat3::ZERO;
    let mut force = DVec3::ZERO;
    for ((&area, &unit), &traction) in areas.iter().zip(directions).zip(tractions.iter()) {
        system += DMat3::from_cols(unit * unit.x, unit * unit.y, unit * unit.z) * area;
        force += unit * (area * traction);
    }
    let determinant = system.determinant();
    let size = system
        .to_cols_array()
        .iter()
        .fold(0.0f64, |m, e| m.max(e.abs()));
    let solvable = determinant.abs() > 1e-12 * size.powi(3);
    if !solvable {
        return;
    }
    let correction = system.inverse() * force;
    for (traction, direction) in tractions.iter_mut().zip(directions) {
        *traction -= direction.dot(correction);
    }
}
