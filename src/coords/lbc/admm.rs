//! The convex programme of local barycentric coordinates on the grid,
//! `min Σₖ TV(wₖ) subject to, at every node, w ≥ 0, Σ wₖ = 1, Σ wₖ vₖ = x`,
//! by the alternating direction method of multipliers with two splittings:
//! `Z = D W − B` (the energy's rows, whose proximal map is a shrinkage per
//! cell, [`Differences::shrink`]) and `Y = W` (each node's row of weights,
//! whose proximal map is the projection onto its barycentric set,
//! [`super::project`]). The handles are coupled only through the projection;
//! the W-step is one system `(DᵀD + I) wₖ = …` per handle, solved by
//! preconditioned conjugate gradients warm-started from the last iterate (its
//! spectrum is in [1, 13 + cut arms], so no factorisation is needed). The
//! weights returned are Y: exactly non-negative and barycentric at every node,
//! at any iteration.

use super::operator::Differences;
use super::project::{offsets, project, residual};
use crate::coords::Cancelled;
use glam::{DVec3, DVec4};
use rayon::prelude::*;

/// The step and stopping rule.
#[derive(Clone, Copy, Debug)]
pub struct LbcSettings {
    /// The penalty `ρ` of both splittings, in cells⁻¹ (the shrinkage's
    /// threshold is `1/ρ`).
    pub rho: f64,
    /// Over-relaxation (1.6, as OSQP).
    pub alpha: f64,
    /// Stop when the primal residuals `‖DW − B − Z‖∞`, `‖W − Y‖∞` and the
    /// dual residual `ρ(‖Dᵀ ΔZ‖∞ + ‖ΔY‖∞)` are all below this, in weights.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Iterations between two evaluations of the residuals.
    pub check_every: usize,
    /// Conjugate gradients stop at this residual relative to the right-hand side.
    pub cg_tolerance: f64,
}

impl Default for LbcSettings {
    fn default() -> Self {
        Self {
            rho: 64.0,
            alpha: 1.6,
            tolerance: 1e-5,
            max_iterations: 20_000,
            check_every: 10,
            cg_tolerance: 1e-9,
        }
    }
}

/// How the solve went.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LbcStats {
    pub inside_nodes: usize,
    /// Rows of the energy: cells' differences and cut arms.
    pub rows: usize,
    pub iterations: usize,
    /// False when the iteration cap came before the tolerance.
    pub converged: bool,
    pub primal_residual: f64,
    pub dual_residual: f64,
    /// Conjugate-gradient steps, over every handle and iteration.
    pub cg_steps: usize,
    /// The largest barycentric residual of the weights returned (|Σw − 1|,
    /// |Σ w (v − x)| / L with L the cage's diagonal) and the nodes whose
    /// projection did not reach [`super::project::TOLERANCE`].
    pub constraint_residual: f64,
    pub projection_failures: usize,
    /// The discrete energy Σₖ TV(wₖ) of the weights returned, in cells².
    pub energy: f64,
}

/// What the solve reads besides the settings.
pub(super) struct Problem<'a> {
    pub differences: &'a Differences,
    pub node_positions: &'a [DVec3],
    pub cage_positions: &'a [DVec3],
    /// The length the offsets `v − x` are divided by (the cage's diagonal).
    pub scale: f64,
}

/// Per thread, the vectors of one conjugate-gradient solve.
struct CgScratch {
    rows: Vec<f64>,
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
}

impl CgScratch {
    fn new(n: usize, rows: usize) -> CgScratch {
        CgScratch {
            rows: vec![0.0; rows],
            r: vec![0.0; n],
            z: vec![0.0; n],
            p: vec![0.0; n],
            q: vec![0.0; n],
        }
    }
}

/// `out = (DᵀD + I) x`.
fn normal_apply(d: &Differences, x: &[f64], rows: &mut [f64], out: &mut [f64]) {
    d.apply(x, rows);
    d.apply_transpose(rows, out);
    out.iter_mut().zip(x).for_each(|(o, x)| *o += x);
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// Solve `(DᵀD + I) x = rhs` from the `x` given; the steps taken.
fn conjugate_gradients(
    d: &Differences,
    diagonal: &[f64],
    rhs: &[f64],
    x: &mut [f64],
    tolerance: f64,
    s: &mut CgScratch,
) -> usize {
    normal_apply(d, x, &mut s.rows, &mut s.q);
    for ((r, &b), &q) in s.r.iter_mut().zip(rhs).zip(&s.q) {
        *r = b - q;
    }
    let goal = (tolerance * dot(rhs, rhs).sqrt()).max(1e-14);
    for ((z, &r), &m) in s.z.iter_mut().zip(&s.r).zip(diagonal) {
        *z = r / m;
    }
    s.p.copy_from_slice(&s.z);
    let mut rz = dot(&s.r, &s.z);
    for step in 0..200 {
        if dot(&s.r, &s.r).sqrt() <= goal {
            return step;
        }
        normal_apply(d, &s.p, &mut s.rows, &mut s.q);
        let alpha = rz / dot(&s.p, &s.q);
        for ((x, r), (&p, &q)) in x.iter_mut().zip(s.r.iter_mut()).zip(s.p.iter().zip(&s.q)) {
            *x += alpha * p;
            *r -= alpha * q;
        }
        for ((z, &r), &m) in s.z.iter_mut().zip(&s.r).zip(diagonal) {
            *z = r / m;
        }
        let next = dot(&s.r, &s.z);
        let beta = next / rz;
        rz = next;
        for (p, &z) in s.p.iter_mut().zip(&s.z) {
            *p = z + beta * *p;
        }
    }
    200
}

fn norm_inf(values: &[f64]) -> f64 {
    values.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// Project every node's row of `source(node, handle)` into `y` (node-major),
/// updating the multipliers; the largest residual and the failures.
fn project_rows(
    problem: &Problem,
    k: usize,
    source: &(dyn Fn(usize, usize) -> f64 + Sync),
    y: &mut [f64],
    mu: &mut [DVec4],
) -> (f64, usize) {
    y.par_chunks_mut(k)
        .zip(mu.par_iter_mut())
        .enumerate()
        .map_init(
            || (Vec::new(), vec![0.0; k]),
            |(offset, p), (node, (y, mu))| {
                offsets(
                    problem.cage_positions,
                    problem.node_positions[node],
                    problem.scale,
                    offset,
                );
                for (handle, p) in p.iter_mut().enumerate() {
                    *p = source(node, handle);
                }
                let ok = project(p, offset, mu, y);
                (residual(y, offset), usize::from(!ok))
            },
        )
        .reduce(|| (0.0, 0), |a, b| (a.0.max(b.0), a.1 + b.1))
}

/// The weights at every unknown, node after node (one per cage vertex), and
/// how the solve went; `report` is given the share of the work done.
pub(super) fn solve(
    problem: &Problem,
    settings: &LbcSettings,
    cancelled: &(dyn Fn() -> bool + Sync),
    report: &(dyn Fn(f64) + Sync),
) -> Result<(Vec<f64>, LbcStats), Cancelled> {
    let d = problem.differences;
    let n = d.unknowns();
    let k = problem.cage_positions.len();
    let rows = d.rows();
    let LbcSettings { rho, alpha, .. } = *settings;
    let mut b = vec![0.0; rows * k];
    b.par_chunks_mut(rows.max(1))
        .enumerate()
        .for_each(|(handle, b)| d.boundary_of(handle as u32, b));
    let diagonal = d.normal_diagonal();
    // Start from the projection of equal weights.
    let mut mu = vec![DVec4::ZERO; n];
    let mut y = vec![0.0; n * k];
    let uniform = 1.0 / k.max(1) as f64;
    project_rows(problem, k, &|_, _| uniform, &mut y, &mut mu);
    let mut w = vec![0.0; n * k];
    transpose_into(&y, n, k, &mut w);
    let mut z = vec![0.0; rows * k];
    z.par_chunks_mut(rows.max(1))
        .zip(w.par_chunks(n.max(1)))
        .zip(b.par_chunks(rows.max(1)))
        .for_each(|((z, w), b)| {
            d.apply(w, z);
            z.iter_mut().zip(b).for_each(|(z, b)| *z -= b);
        });
    let mut u = vec![0.0; rows * k];
    let mut v = vec![0.0; n * k];
    let mut y_before = vec![0.0; n * k];
    let mut y_next = vec![0.0; n * k];
    let mut stats = LbcStats {
        inside_nodes: n,
        rows,
        ..LbcStats::default()
    };
    let mut first_residual: Option<f64> = None;
    for iteration in 1..=settings.max_iterations {
        if cancelled() {
            return Err(Cancelled);
        }
        let check = iteration % settings.check_every == 0 || iteration == settings.max_iterations;
        // The W-step, then the Z-step, handle by handle.
        let (cg_steps, primal_z, dual_z) = w
            .par_chunks_mut(n.max(1))
            .zip(z.par_chunks_mut(rows.max(1)))
            .zip(u.par_chunks_mut(rows.max(1)))
            .zip(b.par_chunks(rows.max(1)))
            .enumerate()
            .map_init(
                || {
                    let scratch = CgScratch::new(n, rows);
                    (scratch, vec![0.0; rows], vec![0.0; rows], vec![0.0; n])
                },
                |(scratch, a, old, rhs), (handle, (((w, z), u), b))| {
                    for ((a, &z), (&b, &u)) in
                        a.iter_mut().zip(z.iter()).zip(b.iter().zip(u.iter()))
                    {
                        *a = z + b - u;
                    }
                    d.apply_transpose(a, rhs);
                    for (node, rhs) in rhs.iter_mut().enumerate() {
                        *rhs += y[node * k + handle] - v[node * k + handle];
                    }
                    let steps =
                        conjugate_gradients(d, &diagonal, rhs, w, settings.cg_tolerance, scratch);
                    d.apply(w, a);
                    old.copy_from_slice(z);
                    for ((a, &b), (z, u)) in a.iter_mut().zip(b).zip(z.iter_mut().zip(u.iter_mut()))
                    {
                        *a -= b;
                        *u += alpha * *a + (1.0 - alpha) * *z;
                        *z = *u;
                    }
                    d.shrink(z, rho);
                    let mut primal = 0.0f64;
                    for ((&z, u), (&a, old)) in
                        z.iter().zip(u.iter_mut()).zip(a.iter().zip(old.iter_mut()))
                    {
                        *u -= z;
                        primal = primal.max((a - z).abs());
                        *old = z - *old;
                    }
                    let mut dual = 0.0;
                    if check {
                        d.apply_transpose(old, rhs);
                        dual = rho * norm_inf(rhs);
                    }
                    (steps, primal, dual)
                },
            )
            .reduce(
                || (0, 0.0, 0.0),
                |a, b| (a.0 + b.0, a.1.max(b.1), a.2.max(b.2)),
            );
        stats.cg_steps += cg_steps;
        // The Y-step, node by node.
        if check {
            y_before.copy_from_slice(&y);
        }
        let relaxed = |node: usize, handle: usize| {
            let at = node * k + handle;
            alpha * w[handle * n + node] + (1.0 - alpha) * y[at] + v[at]
        };
        let (constraint, failures) = project_rows(problem, k, &relaxed, &mut y_next, &mut mu);
        // v += relaxed − y_next, with relaxed = v_new + y_next.
        v.par_chunks_mut(k.max(1))
            .zip(y_next.par_chunks(k.max(1)))
            .zip(y.par_chunks(k.max(1)))
            .enumerate()
            .for_each(|(node, ((v, next), y))| {
                for (handle, ((v, &next), &y)) in v.iter_mut().zip(next).zip(y).enumerate() {
                    *v += alpha * w[handle * n + node] + (1.0 - alpha) * y - next;
                }
            });
        std::mem::swap(&mut y, &mut y_next);
        stats.iterations = iteration;
        stats.constraint_residual = constraint;
        stats.projection_failures = failures;
        if !check {
            continue;
        }
        let primal_y = w
            .par_chunks(n.max(1))
            .enumerate()
            .map(|(handle, w)| {
                w.iter().enumerate().fold(0.0f64, |m, (node, &w)| {
                    m.max((w - y[node * k + handle]).abs())
                })
            })
            .reduce(|| 0.0, f64::max);
        let dual_y = rho
            * y.iter()
                .zip(&y_before)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        stats.primal_residual = primal_z.max(primal_y);
        stats.dual_residual = dual_z + dual_y;
        let worst = stats.primal_residual.max(stats.dual_residual);
        let first = *first_residual.get_or_insert(worst.max(settings.tolerance));
        let by_residual = if worst <= settings.tolerance {
            1.0
        } else {
            (first / worst).ln().max(0.0) / (first / settings.tolerance).ln().max(1e-9)
        };
        report(by_residual.max(iteration as f64 / settings.max_iterations as f64));
        if worst <= settings.tolerance {
            stats.converged = true;
            break;
        }
    }
    stats.energy = energy(d, &y, &b, n, k);
    Ok((y, stats))
}

/// Σₖ TV(wₖ) of node-major weights `y`.
fn energy(d: &Differences, y: &[f64], b: &[f64], n: usize, k: usize) -> f64 {
    let rows = d.rows();
    (0..k)
        .into_par_iter()
        .map_init(
            || (vec![0.0; n], vec![0.0; rows]),
            |(column, r), handle| {
                for (node, c) in column.iter_mut().enumerate() {
                    *c = y[node * k + handle];
                }
                d.apply(column, r);
                r.iter_mut()
                    .zip(&b[handle * rows..][..rows])
                    .for_each(|(r, b)| *r -= b);
                d.energy(r)
            },
        )
        .sum()
}

/// `out[handle * n + node] = source[node * k + handle]`.
fn transpose_into(source: &[f64], n: usize, k: usize, out: &mut [f64]) {
    out.par_chunks_mut(n.max(1))
        .enumerate()
        .for_each(|(handle, column)| {
            for (node, out) in column.iter_mut().enumerate() {
                *out = source[node * k + handle];
            }
        });
}
