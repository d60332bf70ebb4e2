//! Maximum entropy coordinates (Hormann and Sukumar 2008, "Maximum entropy
//! coordinates for arbitrary polytopes"): the weights of largest relative entropy
//! against a prior that reproduce the point,
//!
//! `wᵢ(x) = mᵢ(x) exp(−λ·(vᵢ − x)) / Z(λ)`, `Z(λ) = Σᵢ mᵢ(x) exp(−λ·(vᵢ − x))`,
//!
//! with `λ ∈ R³` the minimiser of `log Z`. Its gradient is `−Σ wᵢ (vᵢ − x)`, so at
//! the minimum the weights reproduce the point (linear precision); they sum to
//! one and are positive by construction. The prior is the face prior of
//! [`prior`], which makes them interpolate on the cage's faces.
//!
//! `log Z` is strictly convex wherever the point is strictly inside the convex
//! hull of the vertices its prior does not zero (its Hessian is the covariance of
//! `vᵢ − x` under `w`), and bounded below there, so a damped Newton method
//! (Armijo backtracking on `log Z`) converges from `λ = 0` at every point inside
//! the cage. Everything is computed from `vᵢ − x` in cage diagonals, in the log
//! domain with a log-sum-exp: the result does not depend on where the origin is,
//! on the cage's units, or on how many orders of magnitude the prior spans.
//!
//! Units: `ρ_f` is an area, and the prior of a vertex has as many factors as the
//! faces it misses, which differs between vertices. The prior is taken with
//! areas in units of the cage's area (the sum of its faces'), which makes the
//! coordinates invariant under rotating and scaling the scene (the definition
//! as written depends on the unit of length), and equals it for a cage of unit
//! area.

mod prior;

use crate::geometry::Cage;
use glam::{DMat3, DVec3};

/// Newton stops once the weights reproduce the point to this many cage diagonals.
pub const TOLERANCE: f64 = 1e-12;
/// A solve whose line search can no longer decrease `log Z` is still accepted
/// when its linear precision is within this many cage diagonals (the promise).
pub const ACCEPTED: f64 = 1e-10;
/// Newton iterations before giving up; convergence takes 5 to 30 inside the
/// test cages.
const MAX_ITERATIONS: u32 = 200;
/// Step halvings before a line search gives up.
const MAX_HALVINGS: u32 = 60;
/// Armijo's sufficient-decrease constant.
const ARMIJO: f64 = 1e-4;
/// The first longest step in `λ` (inverse cage diagonals): it changes a
/// weight's exponent by at most this much. Where the prior puts nearly all
/// weight on one or two vertices, the Hessian is nearly singular and the full
/// Newton step would be far beyond what halving can bring back. Each capped
/// step taken whole quadruples the cap, since a prior that spans hundreds of
/// orders of magnitude needs a `λ` of thousands.
const FIRST_MAX_STEP: f64 = 20.0;

/// Why a point has no maximum entropy coordinates.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum MecError {
    #[error("the point or the cage is not finite")]
    NotFinite,
    /// Only outside the convex hull of the cage (or numerically on it) can the
    /// minimiser fail to exist; callers then follow the outside policy.
    #[error(
        "Newton's method stopped after {iterations} iterations with the point reproduced to \
         {residual:e} cage diagonals: the point is not strictly inside the cage's convex hull"
    )]
    NotConverged { iterations: u32, residual: f64 },
}

/// How a solve went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MecSolve {
    pub iterations: u32,
    /// `|Σ wᵢ vᵢ − x|` in cage diagonals, as the solver measured it.
    pub residual: f64,
    /// The minimiser, in inverse cage diagonals.
    pub lambda: DVec3,
}

/// Reusable per-vertex buffers.
#[derive(Debug, Default)]
pub struct MecScratch {
    offsets: Vec<DVec3>,
    /// Per face, its `ρ`.
    rho: Vec<f64>,
    log_prior: Vec<f64>,
    weights: Vec<f64>,
}

/// `log Z` at one `λ`, with the weights (in the scratch) and their moments.
struct Evaluation {
    log_z: f64,
    /// `Σ wᵢ dᵢ`, the gradient's negative: the linear precision error.
    mean: DVec3,
}

/// Maximum entropy coordinates of `x`, strictly inside `cage`, into `out` (one
/// per cage vertex). On an error `out` is left as it was.
pub fn mec_weights_inside(
    x: DVec3,
    cage: &Cage,
    out: &mut [f64],
    scratch: &mut MecScratch,
) -> Result<MecSolve, MecError> {
    let diagonal = cage.diagonal();
    if !x.is_finite() || !diagonal.is_finite() || diagonal <= 0.0 {
        return Err(MecError::NotFinite);
    }
    let MecScratch {
        offsets,
        rho,
        log_prior,
        weights,
    } = scratch;
    offsets.clear();
    offsets.extend(cage.positions().iter().map(|&v| (v - x) / diagonal));
    prior::log_prior(cage, offsets, rho, log_prior);
    weights.resize(offsets.len(), 0.0);
    let solve = newton(offsets, log_prior, weights)?;
    for (out, &w) in out.iter_mut().zip(weights.iter()) {
        *out = w;
    }
    Ok(solve)
}

/// Minimise `log Z` from `λ = 0`; the weights of the minimiser are left in `w`.
fn newton(d: &[DVec3], log_prior: &[f64], w: &mut [f64]) -> Result<MecSolve, MecError> {
    let mut lambda = DVec3::ZERO;
    let mut current = evaluate(lambda, d, log_prior, w);
    let mut iterations = 0;
    let mut max_step = FIRST_MAX_STEP;
    loop {
        let residual = current.mean.length();
        if residual <= TOLERANCE {
            return Ok(MecSolve {
                iterations,
                residual,
                lambda,
            });
        }
        let gradient = -current.mean;
        if iterations == MAX_ITERATIONS || !current.log_z.is_finite() {
            // The weights in `w` are those of `current`.
            return stalled(iterations, residual, lambda);
        }
        iterations += 1;
        let mut step = newton_step(covariance(d, w, current.mean), gradient);
        let length = step.length();
        let capped = length > max_step;
        if capped {
            step *= max_step / length;
        }
        let slope = gradient.dot(step);
        let mut t = 1.0;
        let mut accepted = None;
        for _ in 0..MAX_HALVINGS {
            let trial = lambda + t * step;
            let next = evaluate(trial, d, log_prior, w);
            let decreased = next.log_z <= current.log_z + ARMIJO * t * slope;
            // Near the minimum `log Z` changes by less than its rounding; a step
            // that does not raise it beyond that and halves the gradient is taken.
            let flat = next.log_z <= current.log_z + 1e-13 * current.log_z.abs().max(1.0)
                && next.mean.length() <= 0.5 * residual;
            if next.log_z.is_finite() && (decreased || flat) {
                accepted = Some((trial, next));
                break;
            }
            t *= 0.5;
        }
        match accepted {
            Some((trial, next)) => {
                if capped && t == 1.0 {
                    max_step *= 4.0;
                }
                (lambda, current) = (trial, next);
            }
            None => {
                // Leave the weights of the last accepted λ in `w`.
                evaluate(lambda, d, log_prior, w);
                return stalled(iterations, residual, lambda);
            }
        }
    }
}

/// The end of a solve that cannot improve: accepted within [`ACCEPTED`].
fn stalled(iterations: u32, residual: f64, lambda: DVec3) -> Result<MecSolve, MecError> {
    if residual <= ACCEPTED {
        Ok(MecSolve {
            iterations,
            residual,
            lambda,
        })
    } else {
        Err(MecError::NotConverged {
            iterations,
            residual,
        })
    }
}

/// `log Z(λ)` and the weights into `w`, by a log-sum-exp.
fn evaluate(lambda: DVec3, d: &[DVec3], log_prior: &[f64], w: &mut [f64]) -> Evaluation {
    let mut top = f64::NEG_INFINITY;
    for ((wi, &di), &log_mi) in w.iter_mut().zip(d).zip(log_prior) {
        *wi = log_mi - lambda.dot(di);
        top = top.max(*wi);
    }
    if !top.is_finite() {
        return Evaluation {
            log_z: f64::NAN,
            mean: DVec3::splat(f64::NAN),
        };
    }
    let mut z = 0.0;
    for wi in w.iter_mut() {
        *wi = (*wi - top).exp();
        z += *wi;
    }
    let mut mean = DVec3::ZERO;
    for (wi, &di) in w.iter_mut().zip(d) {
        *wi /= z;
        mean += *wi * di;
    }
    Evaluation {
        log_z: top + z.ln(),
        mean,
    }
}

/// `Σ wᵢ (dᵢ − μ)(dᵢ − μ)ᵀ`: the Hessian of `log Z`, centred for accuracy.
fn covariance(d: &[DVec3], w: &[f64], mean: DVec3) -> DMat3 {
    let mut h = DMat3::ZERO;
    for (&wi, &di) in w.iter().zip(d) {
        let e = di - mean;
        h += DMat3::from_cols(e * (wi * e.x), e * (wi * e.y), e * (wi * e.z));
    }
    h
}

/// The Newton step `−H⁻¹ g` by a Cholesky factorisation; where `H` is not
/// numerically positive definite (a point almost on the hull, all weight on
/// one face), a growing multiple of the identity is added until it is.
fn newton_step(h: DMat3, gradient: DVec3) -> DVec3 {
    let scale = (h.x_axis.x + h.y_axis.y + h.z_axis.z).max(f64::MIN_POSITIVE);
    let mut shift = 0.0;
    for _ in 0..40 {
        if let Some(step) = cholesky_solve(h + DMat3::from_diagonal(DVec3::splat(shift)), -gradient)
        {
            return step;
        }
        shift = if shift == 0.0 {
            1e-14 * scale
        } else {
            shift * 10.0
        };
    }
    -gradient / scale
}

/// `A⁻¹ b` for a symmetric positive definite `A`; `None` when a pivot is not
/// positive.
fn cholesky_solve(a: DMat3, b: DVec3) -> Option<DVec3> {
    let at = |r: usize, c: usize| a.col(c)[r];
    // A pivot that is not positive (NaN included) ends the factorisation.
    let root = |pivot: f64| (pivot > 0.0).then(|| pivot.sqrt());
    let l00 = root(at(0, 0))?;
    let l10 = at(1, 0) / l00;
    let l20 = at(2, 0) / l00;
    let l11 = root(at(1, 1) - l10 * l10)?;
    let l21 = (at(2, 1) - l20 * l10) / l11;
    let l22 = root(at(2, 2) - l20 * l20 - l21 * l21)?;
    // L y = b, then Lᵀ x = y.
    let y0 = b.x / l00;
    let y1 = (b.y - l10 * y0) / l11;
    let y2 = (b.z - l20 * y0 - l21 * y1) / l22;
    let x2 = y2 / l22;
    let x1 = (y1 - l21 * x2) / l11;
    let x0 = (y0 - l10 * x1 - l20 * x2) / l00;
    let x = DVec3::new(x0, x1, x2);
    x.is_finite().then_some(x)
}

#[cfg(test)]
mod tests;
