//! The Euclidean projection of a node's weights onto the barycentric set of
//! that node, `{y ≥ 0, Σ yᵢ = 1, Σ yᵢ (vᵢ − x) = 0}` (non-empty where x is
//! inside the cage, hence inside the hull of its vertices).
//!
//! With `aᵢ = (1, (vᵢ − x)/L)` and `c = (1, 0, 0, 0)`, the projection of `p`
//! is `yᵢ = max(0, pᵢ + aᵢ·μ)` for the `μ ∈ ℝ⁴` minimising the convex dual
//! `φ(μ) = ½ Σ max(0, pᵢ + aᵢ·μ)² − c·μ`, whose gradient is the constraints'
//! residual `Σ aᵢ yᵢ − c`. Semi-smooth Newton on φ (the Hessian over the
//! positive yᵢ, regularised) with a backtracking line search converges from
//! any start; warm-started from the node's previous μ, it takes one to three
//! steps once the ADMM iterations settle.

use glam::{DMat4, DVec3, DVec4};

/// Steps before giving up on one projection.
const MAX_STEPS: usize = 60;
/// The largest constraint residual accepted, in weights.
pub(super) const TOLERANCE: f64 = 1e-12;

/// The node's offsets `(vᵢ − x)/L` to every cage vertex.
pub(super) fn offsets(cage_positions: &[DVec3], x: DVec3, scale: f64, out: &mut Vec<DVec3>) {
    out.clear();
    out.extend(cage_positions.iter().map(|&v| (v - x) / scale));
}

fn row_of(offset: DVec3) -> DVec4 {
    DVec4::new(1.0, offset.x, offset.y, offset.z)
}

/// The dual's value, gradient and (generalised) Hessian at `mu`.
fn evaluate(p: &[f64], offsets: &[DVec3], mu: DVec4) -> (f64, DVec4, DMat4) {
    let mut value = -mu.x;
    let mut gradient = -DVec4::X;
    let mut hessian = DMat4::ZERO;
    for (&p, &o) in p.iter().zip(offsets) {
        let a = row_of(o);
        let y = p + a.dot(mu);
        if y > 0.0 {
            value += 0.5 * y * y;
            gradient += a * y;
            hessian += outer(a);
        }
    }
    (value, gradient, hessian)
}

/// Project `p` (one weight per cage vertex) into `out`, starting from and
/// updating the multipliers `mu`; false when the residual did not reach
/// [`TOLERANCE`] (then `out` is the last iterate, still non-negative).
pub(super) fn project(p: &[f64], offsets: &[DVec3], mu: &mut DVec4, out: &mut [f64]) -> bool {
    let (mut value, mut gradient, mut hessian) = evaluate(p, offsets, *mu);
    for _ in 0..MAX_STEPS {
        let size = gradient.abs().max_element();
        if size <= TOLERANCE {
            break;
        }
        // Fewer than four positive weights leave the Hessian singular; the
        // regularisation turns the step into a scaled gradient step there.
        let trace = hessian.x_axis.x + hessian.y_axis.y + hessian.z_axis.z + hessian.w_axis.w;
        let shift = 1e-10 * (1.0 + trace);
        let regularised = hessian + DMat4::from_diagonal(DVec4::splat(shift));
        let step = -(regularised.inverse() * gradient);
        if !step.is_finite() {
            break;
        }
        let slope = gradient.dot(step);
        let mut t = 1.0;
        // Near the solution the dual's decrease is below its rounding, so a
        // step that shrinks the residual is taken as well.
        loop {
            let candidate = *mu + t * step;
            let (next, next_gradient, next_hessian) = evaluate(p, offsets, candidate);
            let decreases = next <= value + 1e-4 * t * slope;
            let closer = next_gradient.abs().max_element() <= 0.9 * size;
            if decreases || closer || t < 1e-12 {
                *mu = candidate;
                (value, gradient, hessian) = (next, next_gradient, next_hessian);
                break;
            }
            t *= 0.5;
        }
    }
    for ((&p, &o), out) in p.iter().zip(offsets).zip(out.iter_mut()) {
        *out = (p + row_of(o).dot(*mu)).max(0.0);
    }
    residual(out, offsets) <= TOLERANCE
}

fn outer(a: DVec4) -> DMat4 {
    DMat4::from_cols(a * a.x, a * a.y, a * a.z, a * a.w)
}

/// The largest constraint residual of `y`: `|Σ y − 1|` and `|Σ y (v − x)/L|`.
pub(super) fn residual(y: &[f64], offsets: &[DVec3]) -> f64 {
    let total = y
        .iter()
        .zip(offsets)
        .fold(-DVec4::X, |sum, (&y, &o)| sum + row_of(o) * y);
    total.abs().max_element()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetrahedron() -> Vec<DVec3> {
        vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(1.0, 1.0, 1.0),
        ]
    }

    #[test]
    fn the_projection_is_feasible_and_no_feasible_point_is_closer() {
        let vertices = tetrahedron();
        let x = DVec3::new(0.3, 0.25, 0.2);
        let mut o = Vec::new();
        offsets(&vertices, x, 1.7, &mut o);
        let p = [0.9, -0.4, 0.3, 0.5, -0.2];
        let mut mu = DVec4::ZERO;
        let mut y = [0.0; 5];
        assert!(project(&p, &o, &mut mu, &mut y));
        assert!(residual(&y, &o) <= TOLERANCE);
        assert!(y.iter().all(|&w| w >= 0.0));
        // Five vertices in space leave a segment of feasible points,
        // y + t·d with d spanning the constraints' null space (Σd = 0,
        // Σ d v = 0, d₄ = 1); on it |y + t·d − p|² must be least at t = 0.
        let d = [2.0, -1.0, -1.0, -1.0, 1.0f64];
        assert!(
            (residual(&d, &o) - 1.0).abs() <= 1e-12,
            "d is not in the null space"
        );
        let (mut low, mut high) = (f64::NEG_INFINITY, f64::INFINITY);
        for (&y, &d) in y.iter().zip(&d) {
            if d > 0.0 {
                low = low.max(-y / d);
            } else if d < 0.0 {
                high = high.min(-y / d);
            }
        }
        let slope: f64 = y
            .iter()
            .zip(&p)
            .zip(&d)
            .map(|((y, p), d)| (y - p) * d)
            .sum();
        println!("segment [{low}, {high}], slope at the projection {slope:e}");
        if low < -1e-12 && high > 1e-12 {
            assert!(slope.abs() < 1e-12, "not least inside the segment: {slope}");
        } else if low >= -1e-12 {
            assert!(
                slope >= -1e-12,
                "decreases past the segment's start: {slope}"
            );
        } else {
            assert!(slope <= 1e-12, "decreases past the segment's end: {slope}");
        }
    }

    #[test]
    fn a_feasible_point_is_its_own_projection() {
        let vertices = tetrahedron();
        let p = [0.2, 0.2, 0.2, 0.2, 0.2];
        let x: DVec3 = vertices.iter().copied().sum::<DVec3>() * 0.2;
        let mut o = Vec::new();
        offsets(&vertices, x, 1.0, &mut o);
        let mut mu = DVec4::new(3.0, -2.0, 1.0, 0.5);
        let mut y = [0.0; 5];
        assert!(project(&p, &o, &mut mu, &mut y));
        for (a, b) in y.iter().zip(&p) {
            assert!((a - b).abs() < 1e-12);
        }
    }
}
