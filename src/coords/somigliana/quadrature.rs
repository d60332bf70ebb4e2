//! Quadrature with error estimates for vector-valued integrands: adaptive
//! Gauss–Kronrod (7/15 points) on an interval, and an adaptive collapsed
//! Gauss–Legendre rule on a triangle, each with a bound on its pieces.

use std::sync::OnceLock;

/// Nodes of the 15-point Kronrod rule on [−1, 1], non-negative half, largest
/// first; the odd positions (1, 3, 5, 7) are the 7-point Gauss nodes.
const KRONROD_NODES: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
const KRONROD_WEIGHTS: [f64; 8] = [
    0.022_935_322_010_529_225,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_18,
    0.140_653_259_715_525_92,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_83,
];
/// Weights of the 7-point Gauss rule at `KRONROD_NODES[1]`, `[3]`, `[5]`, `[7]`.
const GAUSS_WEIGHTS: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// How many pieces an interval or a triangle may be cut into before the
/// estimate is taken as it is: the bound on the work per integral. The
/// integrands here are smooth on the domain, so this is reached only where
/// rounding keeps the error estimate above the tolerance.
const MAX_PIECES: usize = 256;

/// An error estimate within this many units of rounding of the integral of |f|
/// is rounding, not truncation: refining would not lower it.
const ROUNDOFF_ULPS: f64 = 64.0;

fn add_scaled<const N: usize>(sum: &mut [f64; N], values: &[f64; N], scale: f64) {
    for (s, v) in sum.iter_mut().zip(values) {
        *s += scale * v;
    }
}

/// One Gauss–Kronrod step on [a, b].
struct KronrodStep<const N: usize> {
    lo: f64,
    hi: f64,
    estimate: [f64; N],
    /// The largest component of the Kronrod estimate's difference from Gauss's.
    error: f64,
    /// The largest component of the integral of |f| (Kronrod's rule): the scale
    /// of the rounding in `estimate`.
    magnitude: f64,
}

fn kronrod_step<const N: usize>(
    f: &mut impl FnMut(f64) -> [f64; N],
    lo: f64,
    hi: f64,
) -> KronrodStep<N> {
    let (centre, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    let mut kronrod = [0.0; N];
    let mut gauss = [0.0; N];
    let mut absolute = [0.0; N];
    for (k, (&node, &weight)) in KRONROD_NODES.iter().zip(&KRONROD_WEIGHTS).enumerate() {
        let offsets: &[f64] = if node == 0.0 { &[0.0] } else { &[-node, node] };
        for &offset in offsets {
            let value = f(centre + half * offset);
            add_scaled(&mut kronrod, &value, weight * half);
            for (a, v) in absolute.iter_mut().zip(&value) {
                *a += (weight * half * v).abs();
            }
            if k % 2 == 1 {
                add_scaled(&mut gauss, &value, GAUSS_WEIGHTS[k / 2] * half);
            }
        }
    }
    let error = kronrod
        .iter()
        .zip(&gauss)
        .fold(0.0f64, |m, (k, g)| m.max((k - g).abs()));
    let magnitude = absolute.iter().fold(0.0f64, |m, a| m.max(*a));
    KronrodStep {
        lo,
        hi,
        estimate: kronrod,
        error,
        magnitude,
    }
}

/// ∫ₐᵇ f, every component within about `tolerance` (absolute), by globally
/// adaptive Gauss–Kronrod: the piece with the largest error estimate is halved
/// until the estimates sum to at most `tolerance`, or are rounding
/// ([`ROUNDOFF_ULPS`]), or there are [`MAX_PIECES`] pieces. Adds the integral to
/// `sum`.
pub(super) fn integrate_interval<const N: usize>(
    f: &mut impl FnMut(f64) -> [f64; N],
    a: f64,
    b: f64,
    tolerance: f64,
    sum: &mut [f64; N],
) {
    if a == b {
        return;
    }
    let mut pieces = vec![kronrod_step(f, a, b)];
    // Running sums over the pieces, updated as one is replaced by its halves.
    let (mut total_error, mut total_magnitude) = (pieces[0].error, pieces[0].magnitude);
    loop {
        let rounding = total_magnitude * (ROUNDOFF_ULPS * f64::EPSILON);
        if total_error <= tolerance.max(rounding) || pieces.len() >= MAX_PIECES {
            break;
        }
        let worst = (0..pieces.len())
            .max_by(|&i, &j| pieces[i].error.total_cmp(&pieces[j].error))
            .unwrap_or(0);
        let (lo, hi) = (pieces[worst].lo, pieces[worst].hi);
        let middle = 0.5 * (lo + hi);
        if middle <= lo.min(hi) || middle >= lo.max(hi) {
            break; // no room left between the floats
        }
        let halves = [kronrod_step(f, lo, middle), kronrod_step(f, middle, hi)];
        total_error += halves[0].error + halves[1].error - pieces[worst].error;
        total_magnitude += halves[0].magnitude + halves[1].magnitude - pieces[worst].magnitude;
        let [first, second] = halves;
        pieces[worst] = first;
        pieces.push(second);
    }
    for piece in &pieces {
        add_scaled(sum, &piece.estimate, 1.0);
    }
}

/// Gauss–Legendre nodes and weights on [0, 1] with `COLLAPSED_ORDER` points.
const COLLAPSED_ORDER: usize = 10;

fn gauss_legendre_unit() -> &'static ([f64; COLLAPSED_ORDER], [f64; COLLAPSED_ORDER]) {
    static RULE: OnceLock<([f64; COLLAPSED_ORDER], [f64; COLLAPSED_ORDER])> = OnceLock::new();
    RULE.get_or_init(|| {
        let (nodes, weights) = gauss_legendre(COLLAPSED_ORDER);
        let mut unit = ([0.0; COLLAPSED_ORDER], [0.0; COLLAPSED_ORDER]);
        for k in 0..COLLAPSED_ORDER {
            unit.0[k] = 0.5 * (nodes[k] + 1.0);
            unit.1[k] = 0.5 * weights[k];
        }
        unit
    })
}

/// The n-point Gauss–Legendre rule on [−1, 1], by Newton's method on Pₙ from
/// Chebyshev starting points.
pub(super) fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = Vec::with_capacity(n);
    let mut weights = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut derivative = 1.0;
        for _ in 0..100 {
            // Pₙ(x) and Pₙ'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let step = p1 / derivative;
            x -= step;
            if step.abs() < 1e-16 {
                break;
            }
        }
        nodes.push(x);
        weights.push(2.0 / ((1.0 - x * x) * derivative * derivative));
    }
    (nodes, weights)
}

/// A triangle of the parameter plane (ξ, η), ξ, η ≥ 0, ξ + η ≤ 1.
type ParameterTriangle = [[f64; 2]; 3];

/// ∫ over the reference triangle (ξ, η) of `f(ξ, η)` (area element dξ dη, so the
/// caller multiplies by twice the physical area). Triangles are split into four
/// until a rule on one agrees with the sum over its children within `tolerance`
/// times the share of its area. Adds the integral to `sum`.
pub(super) fn integrate_triangle<const N: usize>(
    f: &mut impl FnMut(f64, f64) -> [f64; N],
    tolerance: f64,
    sum: &mut [f64; N],
) {
    let root: ParameterTriangle = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
    let root_estimate = collapsed_rule(f, &root);
    let mut stack = vec![(root, root_estimate, 0u32)];
    let mut splits = 0;
    while let Some((triangle, estimate, depth)) = stack.pop() {
        let children = split_in_four(&triangle);
        let child_estimates = children.map(|child| collapsed_rule(f, &child));
        let mut refined = [0.0; N];
        for child in &child_estimates {
            add_scaled(&mut refined, child, 1.0);
        }
        let difference = refined
            .iter()
            .zip(&estimate)
            .fold(0.0f64, |m, (r, e)| m.max((r - e).abs()));
        let share = tolerance * 0.25f64.powi(depth as i32);
        let rounding =
            estimate.iter().fold(0.0f64, |m, e| m.max(e.abs())) * (ROUNDOFF_ULPS * f64::EPSILON);
        if difference <= share.max(rounding) || splits >= MAX_PIECES {
            add_scaled(sum, &refined, 1.0);
        } else {
            splits += 1;
            for (child, child_estimate) in children.into_iter().zip(child_estimates) {
                stack.push((child, child_estimate, depth + 1));
            }
        }
    }
}

fn split_in_four(triangle: &ParameterTriangle) -> [ParameterTriangle; 4] {
    let mid = |a: [f64; 2], b: [f64; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let [a, b, c] = *triangle;
    let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
    [[a, ab, ca], [ab, b, bc], [ca, bc, c], [bc, ca, ab]]
}

/// The collapsed (Duffy) tensor Gauss rule on one parameter triangle: exact for
/// polynomials of degree 2·`COLLAPSED_ORDER` − 2.
fn collapsed_rule<const N: usize>(
    f: &mut impl FnMut(f64, f64) -> [f64; N],
    triangle: &ParameterTriangle,
) -> [f64; N] {
    let (nodes, weights) = gauss_legendre_unit();
    let [a, b, c] = *triangle;
    let jacobian = ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])).abs();
    let mut sum = [0.0; N];
    for (&s, &ws) in nodes.iter().zip(weights) {
        for (&t, &wt) in nodes.iter().zip(weights) {
            // (s, t) ↦ barycentric (1 − s, s(1 − t), s t) of the sub-triangle.
            let (l1, l2) = (s * (1.0 - t), s * t);
            let l0 = 1.0 - s;
            let xi = l0 * a[0] + l1 * b[0] + l2 * c[0];
            let eta = l0 * a[1] + l1 * b[1] + l2 * c[1];
            add_scaled(&mut sum, &f(xi, eta), ws * wt * s * jacobian);
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kronrod_integrates_polynomials_and_smooth_functions() {
        // Degree 21 is within the Kronrod rule's exactness (22), degree 13 within Gauss's.
        let mut f = |x: f64| [x.powi(21) + 3.0 * x.powi(12), (3.0 * x).exp()];
        let mut sum = [0.0; 2];
        integrate_interval(&mut f, -0.5, 1.5, 1e-13, &mut sum);
        let exact_poly = (1.5f64.powi(22) - 0.5f64.powi(22)) / 22.0
            + 3.0 * (1.5f64.powi(13) + 0.5f64.powi(13)) / 13.0;
        let exact_exp = ((4.5f64).exp() - (-1.5f64).exp()) / 3.0;
        assert!((sum[0] - exact_poly).abs() < 1e-10 * exact_poly, "{sum:?}");
        assert!((sum[1] - exact_exp).abs() < 1e-12 * exact_exp, "{sum:?}");
    }

    #[test]
    fn collapsed_rule_integrates_over_the_reference_triangle() {
        // ∫ ξ² η³ over the unit triangle is 2! 3! / 7!.
        let mut f = |xi: f64, eta: f64| [xi * xi * eta.powi(3), 1.0 / (2.0 + xi + eta)];
        let mut sum = [0.0; 2];
        integrate_triangle(&mut f, 1e-14, &mut sum);
        let exact_monomial = 2.0 * 6.0 / 5040.0;
        // ∫₀¹ u/(2 + u) du with u = ξ + η (the segment of length u has measure u du).
        let exact_rational = 1.0 - 2.0 * (1.5f64).ln();
        assert!((sum[0] - exact_monomial).abs() < 1e-15, "{sum:?}");
        assert!((sum[1] - exact_rational).abs() < 1e-14, "{sum:?}");
    }

    #[test]
    fn rounding_noise_stops_the_refinement() {
        // A smooth integrand plus noise of 1e-13 relative, asked for 1e-16:
        // refining cannot meet that, and the work stays bounded.
        let mut calls = 0usize;
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut noisy = |x: f64| {
            calls += 1;
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let noise = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            [x.cos() * (1.0 + 1e-13 * noise)]
        };
        let mut sum = [0.0];
        integrate_interval(&mut noisy, 0.0, 3.0, 1e-16, &mut sum);
        assert!((sum[0] - 3f64.sin()).abs() < 1e-12, "{sum:?}");
        assert!(calls <= 15 * (2 * MAX_PIECES), "{calls} evaluations");

        let mut triangle_calls = 0usize;
        let mut noisy_2d = |xi: f64, eta: f64| {
            triangle_calls += 1;
            let wobble = ((xi * 1e9).sin() * (eta * 1e9).cos()) * 1e-13;
            [1.0 + wobble]
        };
        let mut area = [0.0];
        integrate_triangle(&mut noisy_2d, 1e-18, &mut area);
        assert!((area[0] - 0.5).abs() < 1e-12, "{area:?}");
        let per_rule = COLLAPSED_ORDER * COLLAPSED_ORDER;
        assert!(
            triangle_calls <= per_rule * (1 + 4 * MAX_PIECES),
            "{triangle_calls} evaluations"
        );
    }
}
