//! The paper's Algorithm 1 ("3D Green coordinates") with its `GCTriInt`, as
//! published and as corrected, kept as a cross-check of the closed form in
//! [`super::triangle`]. It divides by `N·v` per corner, so it is only used away
//! from the cage's faces.
//!
//! The erratum: the published `GCTriInt` returns −|I(π−α) − I(π−α−β)| / 4π; the
//! integral over the triangle (p, v₁, v₂) also has the term −√c β (the angle the
//! triangle subtends at p times the height), so the corrected return value is
//! −|I(π−α) − I(π−α−β) − √c β| / 4π. Without it ψ is wrong for every point off the
//! face's plane and the rest pose is not reproduced (tested below).

use glam::DVec3;
use std::f64::consts::PI;

#[derive(Clone, Copy, PartialEq)]
pub(super) enum Version {
    Published,
    Corrected,
}

fn angle_between(a: DVec3, b: DVec3) -> f64 {
    (a.dot(b) / (a.length() * b.length()))
        .clamp(-1.0, 1.0)
        .acos()
}

/// −∫ over the triangle (p, v1, v2) of 1/(4π|ξ − η|), for η above p (the paper's
/// `GCTriInt(p, v1, v2, η)`).
fn gc_tri_int(p: DVec3, v1: DVec3, v2: DVec3, eta: DVec3, version: Version) -> f64 {
    let alpha = angle_between(v2 - v1, p - v1);
    let beta = angle_between(v1 - p, v2 - p);
    let lambda = (p - v1).length_squared() * alpha.sin().powi(2);
    let c = (p - eta).length_squared();
    let integral = |theta: f64| {
        let (s, cos) = theta.sin_cos();
        if s == 0.0 {
            return 0.0;
        }
        let atan_term = 2.0 * c.sqrt() * (c.sqrt() * cos / (lambda + s * s * c).sqrt()).atan();
        let log_term = lambda.sqrt()
            * ((2.0 * lambda.sqrt() * s * s / (1.0 - cos).powi(2))
                * (1.0
                    - 2.0 * c * cos
                        / (c * (1.0 + cos)
                            + lambda
                            + (lambda * lambda + lambda * c * s * s).sqrt())))
            .ln();
        -s.signum() / 2.0 * (atan_term + log_term)
    };
    let difference = integral(PI - alpha) - integral(PI - alpha - beta);
    let total = match version {
        Version::Published => difference,
        Version::Corrected => difference - c.sqrt() * beta,
    };
    -0.25 / PI * total.abs()
}

/// Algorithm 1 for one point: φ one per cage vertex, ψ one per triangle.
pub(super) fn coordinates(
    eta: DVec3,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    version: Version,
) -> (Vec<f64>, Vec<f64>) {
    let mut phi = vec![0.0; positions.len()];
    let mut psi = vec![0.0; triangles.len()];
    for (j, corners) in triangles.iter().enumerate() {
        let v = corners.map(|i| positions[i as usize] - eta);
        let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
        let p = v[0].dot(n) * n;
        let mut signed_sum = 0.0;
        let mut side_integrals = [0.0; 3];
        let mut side_normals = [DVec3::ZERO; 3];
        for l in 0..3 {
            let next = (l + 1) % 3;
            let sign = ((v[l] - p).cross(v[next] - p)).dot(n).signum();
            signed_sum += sign * gc_tri_int(p, v[l], v[next], DVec3::ZERO, version);
            side_integrals[l] = gc_tri_int(DVec3::ZERO, v[next], v[l], DVec3::ZERO, version);
            side_normals[l] = v[next].cross(v[l]).normalize();
        }
        let face_integral = -signed_sum.abs();
        psi[j] = -face_integral;
        let w = n * face_integral
            + (0..3)
                .map(|l| side_normals[l] * side_integrals[l])
                .sum::<DVec3>();
        if w.length() > 1e-12 {
            for l in 0..3 {
                let normal = side_normals[(l + 1) % 3];
                phi[corners[l] as usize] += normal.dot(w) / normal.dot(v[l]);
            }
        }
    }
    (phi, psi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coords::green::green_coordinates;
    use crate::geometry::procedural;

    fn reproduction_error(cage: &crate::geometry::Cage, x: DVec3, version: Version) -> f64 {
        let (phi, psi) = coordinates(x, cage.positions(), cage.triangles(), version);
        let from_vertices: DVec3 = phi.iter().zip(cage.positions()).map(|(&w, &p)| w * p).sum();
        let from_faces: DVec3 = (0..cage.triangle_count())
            .map(|t| {
                let [a, b, c] = cage.triangle(t);
                psi[t] * (b - a).cross(c - a).normalize()
            })
            .sum();
        (from_vertices + from_faces - x).length()
    }

    #[test]
    fn corrected_algorithm_matches_the_closed_form() {
        let star = procedural::extrude(&procedural::star_outline(5, 0.5, 1.0), -0.3, 0.4);
        for cage in [procedural::cube_cage(1.0), star] {
            for x in procedural::points_inside(&cage, 8, 3, 0.05) {
                let (phi, psi) =
                    coordinates(x, cage.positions(), cage.triangles(), Version::Corrected);
                let mut closed_phi = vec![0.0; cage.vertex_count()];
                let mut closed_psi = vec![0.0; cage.triangle_count()];
                green_coordinates(x, &cage, &mut closed_phi, &mut closed_psi).unwrap();
                for (a, b) in phi
                    .iter()
                    .zip(&closed_phi)
                    .chain(psi.iter().zip(&closed_psi))
                {
                    assert!((a - b).abs() < 1e-9, "{a} {b} at {x}");
                }
                assert!(reproduction_error(&cage, x, Version::Corrected) < 1e-9);
            }
        }
    }

    #[test]
    fn published_gc_tri_int_does_not_reproduce_the_rest_pose() {
        let cage = procedural::cube_cage(1.0);
        let x = DVec3::new(0.2, -0.3, 0.1);
        let corrected = reproduction_error(&cage, x, Version::Corrected);
        let published = reproduction_error(&cage, x, Version::Published);
        eprintln!("rest error in the cube: corrected {corrected:.1e}, published {published:.1e}");
        assert!(corrected < 1e-9);
        assert!(published > 1e-2);
    }
}
