//! The paper's smoothing step, written here from its description only to
//! measure what docs/coordinates.md (MLC) says about it: each vertex's
//! direction is replaced by the normalised sum over its triangles of the
//! normalised mean unit vector of the triangle's spherical projection (taken
//! towards the triangle, whichever side it is seen from), written back as a
//! combination of the triangle's corner directions; the likelihood step runs on
//! the smoothed directions and its probabilities are mapped back. pmvc's MLC
//! leave the step out; nothing here is part of the product.

use crate::pointwise_family::linear_precision;
use glam::{DMat3, DVec3};
use pmvc::geometry::{classify_points, procedural, Cage, PointClass};

/// Per vertex, its smoothed direction as a combination of the projected
/// directions, `ũᵢ = Σⱼ T[i][j] uⱼ`, as `(j, T[i][j])` pairs.
type Combination = Vec<Vec<(usize, f64)>>;

/// The smoothed directions, their combinations and the distances `rᵢ`.
fn smoothed(cage: &Cage, x: DVec3) -> (Vec<DVec3>, Combination, Vec<f64>) {
    let offsets: Vec<DVec3> = cage.positions().iter().map(|&v| v - x).collect();
    let r: Vec<f64> = offsets.iter().map(|d| d.length()).collect();
    let u: Vec<DVec3> = offsets.iter().zip(&r).map(|(d, r)| *d / *r).collect();
    let mut sums = vec![DVec3::ZERO; u.len()];
    let mut combination: Combination = vec![Vec::new(); u.len()];
    for corners in cage.triangles() {
        let [a, b, c] = corners.map(|i| u[i as usize]);
        // The integral of the unit vector over the spherical triangle is half the
        // sum over its edges of the arc length times the edge plane's normal.
        let edge = |p: DVec3, q: DVec3| p.cross(q).normalize() * p.angle_between(q) * 0.5;
        let mut mean = edge(a, b) + edge(b, c) + edge(c, a);
        let frame = DMat3::from_cols(a, b, c);
        if frame.determinant() < 0.0 {
            mean = -mean;
        }
        let unit = mean.normalize();
        let t = frame.inverse() * unit;
        for &i in corners {
            sums[i as usize] += unit;
            for (k, &j) in corners.iter().enumerate() {
                combination[i as usize].push((j as usize, t[k]));
            }
        }
    }
    for (i, sum) in sums.iter_mut().enumerate() {
        let length = sum.length();
        *sum /= length;
        for entry in &mut combination[i] {
            entry.1 /= length;
        }
    }
    (sums, combination, r)
}

/// The weights of probabilities `p` on the smoothed directions:
/// `qⱼ = Σᵢ T[i][j] pᵢ`, then `wⱼ ∝ qⱼ / rⱼ`.
fn mapped_back(combination: &Combination, r: &[f64], p: &[f64]) -> Vec<f64> {
    let mut q = vec![0.0; r.len()];
    for (i, entries) in combination.iter().enumerate() {
        for &(j, t) in entries {
            q[j] += t * p[i];
        }
    }
    let total: f64 = q.iter().zip(r).map(|(q, r)| q / r).sum();
    q.iter().zip(r).map(|(q, r)| q / r / total).collect()
}

/// How the likelihood step on the smoothed directions ended.
enum Outcome {
    Maximum(Vec<f64>),
    /// Newton reached a `φ` with every `φ·ũᵢ > 0`: every slack grows along it
    /// without bound, so the dual has no maximum. The `pᵢ` there.
    Unbounded(Vec<f64>),
    /// Newton stopped short of 1e-13 (this test's solver, not the definition).
    Stalled,
}

/// The likelihood step on `directions`: Newton with a line search that keeps
/// every `n + φ·ũᵢ` positive.
fn likelihood(directions: &[DVec3]) -> Outcome {
    let n = directions.len() as f64;
    let mut phi = DVec3::ZERO;
    let objective = |phi: DVec3| -> f64 {
        directions
            .iter()
            .map(|u| n + phi.dot(*u))
            .map(|s| if s > 0.0 { s.ln() } else { f64::NEG_INFINITY })
            .sum()
    };
    for _ in 0..300 {
        let p: Vec<f64> = directions.iter().map(|u| 1.0 / (n + phi.dot(*u))).collect();
        let g: DVec3 = p.iter().zip(directions).map(|(p, u)| *p * *u).sum();
        // φ with every `φ·ũᵢ > 0` certifies that the directions leave the centre
        // outside their hull: the dual grows without bound along it.
        let total: f64 = p.iter().sum();
        if directions.iter().all(|u| phi.dot(*u) > 0.0) {
            return Outcome::Unbounded(p);
        }
        if g.length() <= 1e-13 && (total - 1.0).abs() <= 1e-9 {
            return Outcome::Maximum(p);
        }
        let h = p.iter().zip(directions).fold(DMat3::ZERO, |h, (p, u)| {
            h + DMat3::from_cols(*u * u.x, *u * u.y, *u * u.z) * (p * p)
        });
        let step = h.inverse() * g;
        let gradient = |phi: DVec3| -> f64 {
            let g: DVec3 = directions.iter().map(|u| *u / (n + phi.dot(*u))).sum();
            g.length()
        };
        let mut t = 1.0;
        let now = objective(phi);
        loop {
            let next = objective(phi + t * step);
            // Past the objective's rounding, a halved gradient decides.
            let flat =
                next >= now - 1e-13 * now.abs() && gradient(phi + t * step) < 0.5 * g.length();
            if next >= now + 1e-4 * t * g.dot(step) || (next.is_finite() && flat) {
                break;
            }
            t *= 0.5;
            if t < 1e-20 {
                return Outcome::Stalled;
            }
        }
        phi += t * step;
    }
    Outcome::Stalled
}

/// How often the paper's form, so computed, has no maximiser, its worst linear
/// precision and its smallest weight, at 5 points inside each triangle at
/// distances from 8 % to 1e-6 of the diagonal from it. `cargo test --release
/// --no-default-features --test coords mlc_smoothing -- --ignored --nocapture`.
#[test]
#[ignore = "measurement: prints the figures of the docs"]
fn mlc_smoothing_figures() {
    let cages = [
        ("icosphere", procedural::icosphere(1.0, 1)),
        (
            "comb",
            procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5),
        ),
        (
            "star",
            procedural::extrude(&procedural::star_outline(6, 0.4, 1.0), -0.3, 0.3),
        ),
    ];
    let mut rng = procedural::SplitMix64(11);
    for (name, cage) in cages {
        for h in [8e-2, 2e-2, 1e-3, 1e-6] {
            let (mut points, mut failed, mut stalled) = (0, 0, 0);
            let (mut precision, mut min, mut unbounded) = (0.0f64, f64::INFINITY, 0.0f64);
            for t in 0..cage.triangle_count() {
                let [a, b, c] = cage.triangle(t);
                let inward = -(b - a).cross(c - a).normalize();
                for _ in 0..5 {
                    let (mut s, mut v) = (rng.unit(), rng.unit());
                    if s + v > 1.0 {
                        (s, v) = (1.0 - s, 1.0 - v);
                    }
                    let x = a + s * (b - a) + v * (c - a) + h * cage.diagonal() * inward;
                    if classify_points(&cage, &[x]).classes[0] != PointClass::Inside {
                        continue;
                    }
                    points += 1;
                    let (directions, combination, r) = smoothed(&cage, x);
                    let p = match likelihood(&directions) {
                        Outcome::Maximum(p) => p,
                        Outcome::Unbounded(p) => {
                            failed += 1;
                            let w = mapped_back(&combination, &r, &p);
                            unbounded = unbounded.max(linear_precision(&cage, x, &w));
                            continue;
                        }
                        Outcome::Stalled => {
                            stalled += 1;
                            continue;
                        }
                    };
                    let w = mapped_back(&combination, &r, &p);
                    precision = precision.max(linear_precision(&cage, x, &w));
                    min = min.min(w.iter().copied().fold(f64::INFINITY, f64::min));
                }
            }
            println!(
                "{name}, {h} of the diagonal from a face: {failed} of {points} points without a maximiser \
                 (the weights where Newton proved it reproduce the point to {unbounded:.1e}), {stalled} stalled; \
                 the others: linear precision {precision:.1e}, smallest weight {min:.1e}"
            );
        }
    }
}
