//! An independent reference for the tests: the defining integral
//! `wᵢ ∝ ∫ ψᵢ(p) (p − x)·n(p) / |p − x|⁴ dA` by brute force, sharing no code with
//! the closed-form terms or the adaptive quadrature. Every face is a patch over
//! the unit square, cut into `cells`² squares of `order`² Gauss–Legendre nodes
//! (computed here by Newton's method); a triangle is the patch that collapses
//! its last side, `P = (1 − u) t0 + u(1 − v) t1 + uv·t2`, whose basis is then
//! exactly its barycentrics.

use crate::geometry::Cage;
use glam::DVec3;

/// Gauss–Legendre nodes and weights on [−1, 1], by Newton's method on Pₙ.
pub fn legendre_nodes(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut derivative = 1.0;
            for _ in 0..100 {
                // P_n(z) and P_{n−1}(z) by the three-term recurrence.
                let (mut p0, mut p1) = (1.0, z);
                for k in 2..=n {
                    let k = k as f64;
                    (p0, p1) = (p1, ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k);
                }
                derivative = n as f64 * (z * p1 - p0) / (z * z - 1.0);
                let step = p1 / derivative;
                z -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            (z, 2.0 / ((1.0 - z * z) * derivative * derivative))
        })
        .collect()
}

/// A face as four corners and the cage vertices its basis functions weight.
fn faces(cage: &Cage) -> Vec<([DVec3; 4], [usize; 4])> {
    let at = |i: u32| cage.positions()[i as usize];
    let mut faces: Vec<([DVec3; 4], [usize; 4])> = cage
        .quads()
        .iter()
        .map(|quad| (quad.corners.map(at), quad.corners.map(|i| i as usize)))
        .collect();
    for (t, &[a, b, c]) in cage.triangles().iter().enumerate() {
        if cage.quad_of_triangle(t).is_none() {
            // Corner 3 coincides with corner 0, so its weight goes to vertex a.
            faces.push((
                [at(a), at(b), at(c), at(a)],
                [a, b, c, a].map(|i| i as usize),
            ));
        }
    }
    faces
}

/// The unnormalised weights of one face at `x`.
pub fn face_integral(x: DVec3, p: &[DVec3; 4], cells: usize, order: usize) -> [f64; 4] {
    let rule = legendre_nodes(order);
    let step = 1.0 / cells as f64;
    let mut sum = [0.0; 4];
    for ci in 0..cells {
        for cj in 0..cells {
            for &(s, ws) in &rule {
                for &(t, wt) in &rule {
                    let u = (ci as f64 + 0.5 * (s + 1.0)) * step;
                    let v = (cj as f64 + 0.5 * (t + 1.0)) * step;
                    let psi = [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v];
                    let point = psi[0] * p[0] + psi[1] * p[1] + psi[2] * p[2] + psi[3] * p[3];
                    let along_u = (1.0 - v) * (p[1] - p[0]) + v * (p[2] - p[3]);
                    let along_v = (1.0 - u) * (p[3] - p[0]) + u * (p[2] - p[1]);
                    let r = point - x;
                    let r2 = r.dot(r);
                    let f =
                        0.25 * step * step * ws * wt * r.dot(along_u.cross(along_v)) / (r2 * r2);
                    for k in 0..4 {
                        sum[k] += f * psi[k];
                    }
                }
            }
        }
    }
    sum
}

/// The normalised weights at `x`.
pub fn reference_weights(x: DVec3, cage: &Cage, cells: usize, order: usize) -> Vec<f64> {
    let mut w = vec![0.0; cage.vertex_count()];
    for (corners, vertices) in faces(cage) {
        let face = face_integral(x, &corners, cells, order);
        for k in 0..4 {
            w[vertices[k]] += face[k];
        }
    }
    let total: f64 = w.iter().sum();
    w.iter().map(|value| value / total).collect()
}
