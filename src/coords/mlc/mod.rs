//! Maximum likelihood coordinates (Chang, Deng and Hormann 2023, "Maximum
//! likelihood coordinates", Computer Graphics Forum 42(5)): the vertices seen
//! from `x` are projected onto the unit sphere, `uᵢ = (vᵢ − x) / rᵢ`, and the
//! probabilities `pᵢ` of largest likelihood `Π pᵢ` whose mean `Σ pᵢ uᵢ` is the
//! centre (Owen's empirical likelihood) are taken back through the projection:
//!
//! `wᵢ(x) = (pᵢ / rᵢ) / Σₖ (pₖ / rₖ)`, `pᵢ = 1 / (n + φ·uᵢ)`,
//!
//! with `φ ∈ R³` the maximiser of the dual `Σᵢ log(n + φ·uᵢ)` over the
//! polytope where every `n + φ·uᵢ > 0`. Its gradient is `Σ pᵢ uᵢ`, so at the
//! maximum `Σ wᵢ (vᵢ − x) = 0` (linear precision); `Σ pᵢ = 1` there too, and
//! every weight is positive by construction.
//!
//! The paper smooths the projected vertices before the likelihood step (in 3D:
//! each vertex's direction replaced by the normalised sum of the mean unit
//! vectors of its faces' spherical triangles, decomposed back as mean value
//! coordinates decompose them); this module leaves that step out. Smoothed
//! directions need not surround the centre, and near the cage they often do
//! not (measured in docs/coordinates.md, MLC): there the dual is unbounded and
//! has no maximiser. Without the step the dual has a maximiser at every point
//! strictly inside the cage: `x` is then inside the hull of the vertices, so
//! the `uᵢ` surround the centre, the polytope is bounded and the concave dual
//! tends to −∞ on its boundary.
//!
//! The dual is minus a self-concordant barrier, so Newton's method with a
//! backtracking line search converges from `φ = 0` at every inside point. Near
//! a face `φ` grows like one over the distance while the slacks `n + φ·uᵢ` of
//! the face's corners stay of order one: the slacks are kept as the state and
//! updated by each step (never recomputed from `φ`, which would cancel), and
//! each Newton step is the least-squares solution of `(uᵢ / sᵢ)·Δ = 1` by a QR
//! factorisation, whose condition is the square root of the Hessian's. Only
//! `vᵢ − x` enter, so the result does not depend on the origin, the units or a
//! rotation.

#[cfg(test)]
mod tests;

use crate::geometry::Cage;
use glam::DVec3;

/// Newton stops once the weights reproduce the point to this many cage diagonals.
pub const TOLERANCE: f64 = 1e-12;
/// A solve whose line search can no longer improve is still accepted when its
/// linear precision is within this many cage diagonals (the promise).
pub const ACCEPTED: f64 = 1e-10;
/// Newton iterations before giving up; convergence takes 5 to 40 inside the
/// test cages, the most next to a face.
const MAX_ITERATIONS: u32 = 500;
/// Step halvings before a line search gives up.
const MAX_HALVINGS: u32 = 60;
/// Armijo's sufficient-increase constant.
const ARMIJO: f64 = 1e-4;

/// Why a point has no maximum likelihood coordinates.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum MlcError {
    #[error("the point or the cage is not finite")]
    NotFinite,
    /// The point is a cage vertex: its direction is undefined (its weight is one).
    #[error("the point is on cage vertex {vertex}")]
    OnVertex { vertex: usize },
    /// Only outside the convex hull of the cage (or numerically on it) can the
    /// maximiser fail to exist; callers then follow the outside policy.
    #[error(
        "Newton's method stopped after {iterations} iterations with the point reproduced to \
         {residual:e} cage diagonals: the point is not strictly inside the cage's convex hull"
    )]
    NotConverged { iterations: u32, residual: f64 },
}

/// How a solve went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MlcSolve {
    pub iterations: u32,
    /// `|Σ wᵢ (vᵢ − x)|` in cage diagonals, as the solver measured it.
    pub residual: f64,
    /// The maximiser `φ` (dimensionless: the `uᵢ` are unit vectors).
    pub phi: DVec3,
}

/// Reusable per-vertex buffers.
#[derive(Debug, Default)]
pub struct MlcScratch {
    /// `uᵢ`, the unit directions from the point to the vertices.
    directions: Vec<DVec3>,
    /// `rᵢ`, the distances in cage diagonals.
    distances: Vec<f64>,
    /// `sᵢ = n + φ·uᵢ`, the state.
    slacks: Vec<f64>,
    /// `sᵢ` at a trial step.
    trial: Vec<f64>,
    /// `Δ·uᵢ` for the current step.
    rates: Vec<f64>,
    /// The least-squares matrix's columns, overwritten by its QR factorisation.
    columns: [Vec<f64>; 3],
    /// The least-squares right-hand side.
    rhs: Vec<f64>,
}

/// The dual at one set of slacks: `Σ log sᵢ` and `Σ pᵢ uᵢ` (its gradient).
struct Evaluation {
    objective: f64,
    gradient: DVec3,
    /// `Σ pᵢ / rᵢ`, which turns the gradient into the linear precision error.
    total: f64,
}

impl Evaluation {
    /// `|Σ wᵢ (vᵢ − x)|` in cage diagonals.
    fn residual(&self) -> f64 {
        self.gradient.length() / self.total
    }
}

/// Maximum likelihood coordinates of `x`, strictly inside `cage`, into `out`
/// (one per cage vertex). On an error `out` is left as it was.
pub fn mlc_weights_inside(
    x: DVec3,
    cage: &Cage,
    out: &mut [f64],
    scratch: &mut MlcScratch,
) -> Result<MlcSolve, MlcError> {
    let diagonal = cage.diagonal();
    if !x.is_finite() || !diagonal.is_finite() || diagonal <= 0.0 {
        return Err(MlcError::NotFinite);
    }
    scratch.directions.clear();
    scratch.distances.clear();
    for (vertex, &v) in cage.positions().iter().enumerate() {
        let offset = (v - x) / diagonal;
        let r = offset.length();
        if !r.is_finite() {
            return Err(MlcError::NotFinite);
        }
        if r == 0.0 {
            return Err(MlcError::OnVertex { vertex });
        }
        scratch.directions.push(offset / r);
        scratch.distances.push(r);
    }
    let solve = newton(scratch)?;
    let MlcScratch {
        distances, slacks, ..
    } = scratch;
    let total: f64 = slacks
        .iter()
        .zip(distances.iter())
        .map(|(s, r)| 1.0 / (s * r))
        .sum();
    for ((out, s), r) in out.iter_mut().zip(slacks.iter()).zip(distances.iter()) {
        *out = 1.0 / (s * r) / total;
    }
    Ok(solve)
}

/// Maximise `Σ log sᵢ` from `φ = 0`; the slacks of the maximiser are left in
/// the scratch.
fn newton(scratch: &mut MlcScratch) -> Result<MlcSolve, MlcError> {
    let MlcScratch {
        directions: u,
        distances: r,
        slacks,
        trial,
        rates,
        columns,
        rhs,
    } = scratch;
    let n = u.len() as f64;
    slacks.clear();
    slacks.resize(u.len(), n);
    let mut phi = DVec3::ZERO;
    let mut current = evaluate(slacks, u, r);
    let mut iterations = 0;
    loop {
        let residual = current.residual();
        if residual <= TOLERANCE {
            return Ok(MlcSolve {
                iterations,
                residual,
                phi,
            });
        }
        if iterations == MAX_ITERATIONS || !residual.is_finite() {
            return stalled(iterations, residual, phi);
        }
        iterations += 1;
        let Some(step) = newton_step(u, slacks, columns, rhs) else {
            return stalled(iterations, residual, phi);
        };
        rates.clear();
        rates.extend(u.iter().map(|ui| step.dot(*ui)));
        let slope = current.gradient.dot(step);
        let mut t = 1.0;
        let mut accepted = None;
        for _ in 0..MAX_HALVINGS {
            trial.clear();
            trial.extend(slacks.iter().zip(rates.iter()).map(|(s, a)| s + t * a));
            // Outside the polytope the dual is undefined: a shorter step.
            if trial.iter().all(|&s| s > 0.0) {
                let next = evaluate(trial, u, r);
                let increased = next.objective >= current.objective + ARMIJO * t * slope;
                // Near the maximum the objective changes by less than its
                // rounding; a step that does not lower it beyond that and
                // halves the residual is taken.
                let flat = next.objective
                    >= current.objective - 1e-13 * current.objective.abs().max(1.0)
                    && next.residual() <= 0.5 * residual;
                if next.objective.is_finite() && (increased || flat) {
                    accepted = Some(next);
                    break;
                }
            }
            t *= 0.5;
        }
        let Some(next) = accepted else {
            return stalled(iterations, residual, phi);
        };
        std::mem::swap(slacks, trial);
        phi += t * step;
        current = next;
    }
}

/// The end of a solve that cannot improve: accepted within [`ACCEPTED`].
fn stalled(iterations: u32, residual: f64, phi: DVec3) -> Result<MlcSolve, MlcError> {
    if residual <= ACCEPTED {
        Ok(MlcSolve {
            iterations,
            residual,
            phi,
        })
    } else {
        Err(MlcError::NotConverged {
            iterations,
            residual,
        })
    }
}

/// `Σ log sᵢ`, `Σ uᵢ / sᵢ` and `Σ 1 / (sᵢ rᵢ)` at slacks `s`.
fn evaluate(s: &[f64], u: &[DVec3], r: &[f64]) -> Evaluation {
    let mut evaluation = Evaluation {
        objective: 0.0,
        gradient: DVec3::ZERO,
        total: 0.0,
    };
    for ((&si, &ui), &ri) in s.iter().zip(u).zip(r) {
        let p = 1.0 / si;
        evaluation.objective += si.ln();
        evaluation.gradient += p * ui;
        evaluation.total += p / ri;
    }
    evaluation
}

/// The Newton step `H⁻¹ g` with `H = Σ uᵢ uᵢᵀ / sᵢ²` and `g = Σ uᵢ / sᵢ`: the
/// least-squares solution of `A Δ ≈ 1`, `A`'s rows `uᵢ / sᵢ` (`Aᵀ A = H`,
/// `Aᵀ 1 = g`), by Householder reflections. `None` when `A` is numerically
/// rank-deficient (the directions span no volume).
fn newton_step(
    u: &[DVec3],
    s: &[f64],
    columns: &mut [Vec<f64>; 3],
    rhs: &mut Vec<f64>,
) -> Option<DVec3> {
    for (k, column) in columns.iter_mut().enumerate() {
        column.clear();
        column.extend(u.iter().zip(s).map(|(ui, si)| ui[k] / si));
    }
    rhs.clear();
    rhs.resize(u.len(), 1.0);
    let mut diagonal = [0.0; 3];
    for k in 0..3 {
        let (done, rest) = columns.split_at_mut(k + 1);
        let column = &mut done[k];
        let norm = column[k..].iter().map(|a| a * a).sum::<f64>().sqrt();
        if norm == 0.0 || !norm.is_finite() {
            return None;
        }
        // The reflection `I − 2vvᵀ/vᵀv`, `v = a − α e_k`, with the sign of `α`
        // chosen against cancellation.
        let alpha = if column[k] > 0.0 { -norm } else { norm };
        column[k] -= alpha;
        let vv = column[k..].iter().map(|a| a * a).sum::<f64>();
        let reflect = |target: &mut [f64], v: &[f64]| {
            let dot: f64 = target[k..].iter().zip(&v[k..]).map(|(t, v)| t * v).sum();
            let factor = 2.0 * dot / vv;
            for (t, v) in target[k..].iter_mut().zip(&v[k..]) {
                *t -= factor * v;
            }
        };
        for other in rest.iter_mut() {
            reflect(other, column);
        }
        reflect(rhs, column);
        diagonal[k] = alpha;
    }
    // Back substitution on the 3×3 triangle `R`.
    let r = |row: usize, col: usize| {
        if row == col {
            diagonal[row]
        } else {
            columns[col][row]
        }
    };
    let smallest = diagonal
        .iter()
        .map(|d| d.abs())
        .fold(f64::INFINITY, f64::min);
    let largest = diagonal.iter().map(|d| d.abs()).fold(0.0, f64::max);
    if smallest <= largest * 1e-15 {
        return None;
    }
    let z = rhs[2] / r(2, 2);
    let y = (rhs[1] - r(1, 2) * z) / r(1, 1);
    let x = (rhs[0] - r(0, 1) * y - r(0, 2) * z) / r(0, 0);
    let step = DVec3::new(x, y, z);
    step.is_finite().then_some(step)
}
