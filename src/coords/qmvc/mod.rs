//! Mean value coordinates of a bilinear quad (QMVC: Thiery, Memari, Boubekeur,
//! "Mean value coordinates for quad cages in 3D", ACM TOG 37(6), 2018): the
//! weights of its corners are `wᵢ(x) = ∫ ψᵢ(p) (p − x)·n(p) / |p − x|⁴ dA` over
//! the patch, `ψᵢ` its bilinear basis, as a triangle's are with barycentrics.
//!
//! Four unknowns per quad. Because the patch reproduces its points
//! (`Σ ψᵢ(p) qᵢ = p`), three equations are in closed form:
//! `Σ wᵢ (qᵢ − x) = m`, with `m` the integral of the unit direction over the
//! patch's spherical image, which depends on its four edges only
//! (`m = ½ Σₖ θₖ n̂ₖ`, as for a triangle in Ju, Schaefer, Warren 2005). They
//! fix the weights up to a multiple of the null vector `N` of the 3 × 4 matrix
//! `[qᵢ − x]`; the fourth equation, `N·w = ∫ (N·ψ) (p − x)·n / |p − x|⁴ dA`,
//! is the one integrated numerically ([`quadrature`]), as in the paper. Whatever
//! that integral's error, the three closed-form equations hold, and with them
//! linear precision: a cage's `m` sum to zero over a closed surface, so the
//! normalised weights reproduce `x`.
//!
//! The authors' implementation takes the `N` component from a 9 × 9 grid and
//! rescales it by a ratio of two of its integrals; here it is the integral's
//! projection on `N` itself, from a quadrature accurate to 1e-7 in the weights.

pub mod quadrature;

#[cfg(test)]
mod convergence;
#[cfg(test)]
pub(crate) mod reference;
#[cfg(test)]
mod tests;

use glam::DVec3;
pub use quadrature::{Integral, Rule, RULE};

/// What a quad adds to a point's unnormalised weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum QuadTerm {
    /// `x` lies on the patch: its row is these bilinear weights of the corners.
    OnPatch([f64; 4]),
    /// The quad is planar and `x` in its plane, off it: it subtends no solid angle.
    Coplanar,
    /// The corners' unnormalised weights.
    Weights([f64; 4]),
}

/// Below this, relative to the corners' distances, the null vector vanishes:
/// a planar quad seen edge-on.
const FLAT: f64 = 1e-12;

/// The QMVC term of the patch `q` at `x`, given the integral of
/// `ψ (p − x)·n / |p − x|⁴` over it ([`quadrature::integrate`]). `distances` and
/// `directions` are `|qᵢ − x|` and `(qᵢ − x)/|qᵢ − x|`, none of them zero (a
/// point on a corner is the caller's).
pub fn quad_term(
    x: DVec3,
    q: &[DVec3; 4],
    distances: [f64; 4],
    directions: [DVec3; 4],
    integral: Integral,
) -> QuadTerm {
    let integral = match integral {
        Integral::OnPatch(basis) => return QuadTerm::OnPatch(basis),
        Integral::Value(value) => value,
    };
    let a = q.map(|p| p - x);
    let null = null_vector(q, &a);
    // Each |Nₗ| is at most the product of the other three distances.
    let scale = (0..4)
        .map(|l| {
            (0..4)
                .filter(|&i| i != l)
                .map(|i| distances[i])
                .product::<f64>()
        })
        .fold(0.0, f64::max);
    let norm_squared = dot4(&null, &null);
    if norm_squared.sqrt() <= FLAT * scale {
        return QuadTerm::Coplanar;
    }
    let m = mean_vector(&directions);
    let particular = particular_solution(q, &a, &null, m);
    // Keep the particular solution's closed-form part, take the component along N
    // from the integral.
    let lambda = (dot4(&null, &integral) - dot4(&null, &particular)) / norm_squared;
    QuadTerm::Weights(std::array::from_fn(|i| particular[i] + lambda * null[i]))
}

/// `½ Σₖ θₖ n̂ₖ` over the four edges: the integral of the unit direction over the
/// patch's spherical image, signed as its solid angle (positive seen from behind
/// the outward normal). An edge seen end-on spans no arc and adds nothing.
pub fn mean_vector(directions: &[DVec3; 4]) -> DVec3 {
    let mut m = DVec3::ZERO;
    for k in 0..4 {
        let (e0, e1) = (directions[k], directions[(k + 1) % 4]);
        let half_chord = (0.5 * (e1 - e0).length()).min(1.0);
        let theta = 2.0 * half_chord.asin();
        let normal = e0.cross(e1);
        let length = normal.length();
        if length > 0.0 {
            m += (0.5 * theta / length) * normal;
        }
    }
    m
}

/// `N` with `Σ Nᵢ (qᵢ − x) = 0`: `Nᵢ = (−1)ⁱ det` of the other three `qⱼ − x`.
/// Each determinant is taken over the edges from its first vector, which stay
/// exact far from the patch. `Σ Nᵢ` is six times the signed volume of the four
/// corners, the same for every `x`, so `N` never vanishes on a bent quad.
pub fn null_vector(q: &[DVec3; 4], a: &[DVec3; 4]) -> [f64; 4] {
    let det = |i: usize, j: usize, k: usize| a[i].dot((q[j] - q[i]).cross(q[k] - q[i]));
    [det(1, 2, 3), -det(0, 2, 3), det(0, 1, 3), -det(0, 1, 2)]
}

/// Some `w` with `Σ wᵢ aᵢ = m`: the three columns other than the one with the
/// largest cofactor (the best-conditioned triple) solved by Cramer's rule, each
/// determinant with one far vector and edges, which stay exact far from the patch.
fn particular_solution(q: &[DVec3; 4], a: &[DVec3; 4], null: &[f64; 4], m: DVec3) -> [f64; 4] {
    let skip = (0..4)
        .max_by(|&i, &j| null[i].abs().total_cmp(&null[j].abs()))
        .unwrap_or(0);
    let [i, j, k] = match skip {
        0 => [1, 2, 3],
        1 => [0, 2, 3],
        2 => [0, 1, 3],
        _ => [0, 1, 2],
    };
    let det = a[i].dot((q[j] - q[i]).cross(q[k] - q[i]));
    let mut w = [0.0; 4];
    w[i] = m.dot(a[j].cross(q[k] - q[j])) / det;
    w[j] = m.dot(a[k].cross(q[i] - q[k])) / det;
    w[k] = m.dot(a[i].cross(q[j] - q[i])) / det;
    w
}

#[inline]
pub(crate) fn dot4(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}
