//! The bound-constrained quadratic programme of every handle,
//! `min ½ wᵀQw + qₖᵀw subject to 0 ≤ w ≤ 1`, by the alternating direction method
//! of multipliers as OSQP does it (Stellato et al. 2020: the splitting `w = z`
//! with `z` in the box, over-relaxation, and its residual-based stopping
//! rule), with one fixed step `ρ`. Every handle has the same `Q`, so one sparse
//! Cholesky factorisation of `Q + ρI` serves every handle and every iteration:
//! an iteration is two triangular solves, a clamp and a few vector updates,
//! for a block of handles at once.

use super::operator::Operator;
use crate::coords::Cancelled;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LltRef, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::SparseColMat;
use faer::{Conj, MatMut, Par, Side};

/// The step and stopping rule.
#[derive(Clone, Copy, Debug)]
pub struct AdmmSettings {
    /// The penalty `ρ` of `w = z`, in the units of `Q`'s entries.
    pub rho: f64,
    /// Over-relaxation (OSQP's default 1.6).
    pub alpha: f64,
    /// OSQP's absolute and relative tolerances on the primal residual
    /// `‖w − z‖∞` and the dual residual `‖Qw + q + ρu‖∞`.
    pub eps_abs: f64,
    pub eps_rel: f64,
    pub max_iterations: usize,
    /// Iterations between two evaluations of the residuals.
    pub check_every: usize,
}

impl Default for AdmmSettings {
    fn default() -> Self {
        Self {
            rho: 1.0,
            alpha: 1.6,
            eps_abs: 1e-7,
            eps_rel: 1e-6,
            max_iterations: 20_000,
            check_every: 10,
        }
    }
}

/// The symbolic analysis of `Q + ρI` (fill-reducing ordering and the factor's
/// structure), which tells the factor's size before any value is computed.
pub(super) struct Analysis {
    symbolic: SymbolicCholesky<usize>,
}

impl Analysis {
    pub fn new(matrix: &SparseColMat<usize, f64>) -> Result<Analysis, String> {
        let symbolic = factorize_symbolic_cholesky(
            matrix.symbolic(),
            Side::Lower,
            SymmetricOrdering::Amd,
            Default::default(),
        )
        .map_err(|error| format!("{error:?}"))?;
        Ok(Analysis { symbolic })
    }

    /// Entries of the Cholesky factor.
    pub fn factor_entries(&self) -> usize {
        self.symbolic.len_val()
    }

    fn numeric_scratch(&self) -> StackReq {
        self.symbolic
            .factorize_numeric_llt_scratch::<f64>(Par::rayon(0), Default::default())
    }

    /// Bytes the numerical factorisation needs: the factor and its workspace.
    pub fn factorisation_bytes(&self) -> u64 {
        8 * self.factor_entries() as u64 + self.numeric_scratch().size_bytes() as u64
    }

    /// Bytes one solve with `columns` right-hand sides needs besides them.
    pub fn solve_bytes(&self, columns: usize) -> u64 {
        self.symbolic
            .solve_in_place_scratch::<f64>(columns, Par::Seq)
            .size_bytes() as u64
    }

    /// The numerical factorisation of `matrix` (the one analysed).
    pub fn factorise(self, matrix: &SparseColMat<usize, f64>) -> Result<Factor, String> {
        let mut values = Vec::new();
        values
            .try_reserve_exact(self.factor_entries())
            .map_err(|_| "out of memory for the factor".to_owned())?;
        values.resize(self.factor_entries(), 0.0);
        let mut scratch = MemBuffer::try_new(self.numeric_scratch())
            .map_err(|_| "out of memory for the factorisation's workspace".to_owned())?;
        self.symbolic
            .factorize_numeric_llt(
                &mut values,
                matrix.as_ref(),
                Side::Lower,
                Default::default(),
                Par::rayon(0),
                MemStack::new(&mut scratch),
                Default::default(),
            )
            .map_err(|error| format!("{error:?}"))?;
        Ok(Factor {
            symbolic: self.symbolic,
            values,
        })
    }
}

/// The Cholesky factor of `Q + ρI`.
pub(super) struct Factor {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
}

impl Factor {
    /// Solve in place for `columns` right-hand sides stored column after column.
    fn solve(&self, rhs: &mut [f64], columns: usize, scratch: &mut MemBuffer) {
        let n = self.symbolic.nrows();
        let rhs = MatMut::from_column_major_slice_mut(rhs, n, columns);
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            Par::Seq,
            MemStack::new(scratch),
        );
    }

    fn scratch(&self, columns: usize) -> MemBuffer {
        MemBuffer::new(
            self.symbolic
                .solve_in_place_scratch::<f64>(columns, Par::Seq),
        )
    }
}

/// How one block of handles went.
#[derive(Clone, Copy, Debug, Default)]
pub struct BlockStats {
    /// Iterations until the slowest handle of the block stopped.
    pub iterations: usize,
    /// Handles that reached the tolerance (the others stopped at the cap).
    pub converged: usize,
    /// The largest primal and dual residuals at the end.
    pub primal: f64,
    pub dual: f64,
}

fn norm_inf(values: &[f64]) -> f64 {
    values.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// The weights of `handles` at every unknown, column after column, each in
/// [0, 1]; stops with [`Cancelled`] when `cancelled` says so between iterations.
pub(super) fn solve_block(
    operator: &Operator,
    factor: &Factor,
    handles: &[u32],
    settings: &AdmmSettings,
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Result<(Vec<f64>, BlockStats), Cancelled> {
    let n = operator.unknowns();
    let rows = operator.rows();
    let k = handles.len();
    let AdmmSettings {
        rho,
        alpha,
        eps_abs,
        eps_rel,
        ..
    } = *settings;
    // Per handle: b, and −q = Dᵀ m b.
    let mut b = vec![0.0; rows * k];
    let mut minus_q = vec![0.0; n * k];
    for (j, &handle) in handles.iter().enumerate() {
        operator.boundary_of(handle, &mut b[j * rows..][..rows]);
        operator.apply_transpose_weighted(&b[j * rows..][..rows], &mut minus_q[j * n..][..n]);
    }
    let q_norms: Vec<f64> = minus_q.chunks(n.max(1)).map(norm_inf).collect();
    let mut z = vec![0.0; n * k];
    let mut u = vec![0.0; n * k];
    let mut x = vec![0.0; n * k];
    let mut residual = vec![0.0; rows];
    let mut gradient = vec![0.0; n];
    let mut done = vec![false; k];
    let mut scratch = factor.scratch(k);
    let mut stats = BlockStats::default();
    for iteration in 1..=settings.max_iterations {
        if cancelled() {
            return Err(Cancelled);
        }
        for j in 0..k {
            let range = j * n..(j + 1) * n;
            for ((x, &z), (&u, &mq)) in x[range.clone()]
                .iter_mut()
                .zip(&z[range.clone()])
                .zip(u[range.clone()].iter().zip(&minus_q[range.clone()]))
            {
                *x = rho * (z - u) + mq;
            }
        }
        factor.solve(&mut x, k, &mut scratch);
        let check = iteration % settings.check_every == 0 || iteration == settings.max_iterations;
        if check {
            // The residuals reported are the last check's.
            stats.primal = 0.0;
            stats.dual = 0.0;
        }
        let mut all_done = true;
        for j in 0..k {
            if done[j] {
                continue;
            }
            let range = j * n..(j + 1) * n;
            let (x, z, u) = (
                &x[range.clone()],
                &mut z[range.clone()],
                &mut u[range.clone()],
            );
            let mut primal = 0.0f64;
            for ((&x, z), u) in x.iter().zip(z.iter_mut()).zip(u.iter_mut()) {
                let relaxed = alpha * x + (1.0 - alpha) * *z;
                let next = (relaxed + *u).clamp(0.0, 1.0);
                *u += relaxed - next;
                *z = next;
                primal = primal.max((x - next).abs());
            }
            if !check {
                all_done = false;
                continue;
            }
            // Dual residual: ∇E(x) + ρu = Dᵀm(Dx − b) + ρu.
            operator.apply(x, &mut residual);
            for (r, &b) in residual.iter_mut().zip(&b[j * rows..][..rows]) {
                *r -= b;
            }
            operator.apply_transpose_weighted(&residual, &mut gradient);
            let gradient_norm = norm_inf(&gradient);
            let mut dual = 0.0f64;
            let mut multiplier = 0.0f64;
            for (&g, &u) in gradient.iter().zip(u.iter()) {
                dual = dual.max((g + rho * u).abs());
                multiplier = multiplier.max((rho * u).abs());
            }
            let eps_primal = eps_abs + eps_rel * norm_inf(x).max(norm_inf(z));
            let eps_dual = eps_abs + eps_rel * gradient_norm.max(q_norms[j]).max(multiplier);
            stats.primal = stats.primal.max(primal);
            stats.dual = stats.dual.max(dual);
            if primal <= eps_primal && dual <= eps_dual {
                done[j] = true;
                stats.converged += 1;
            } else {
                all_done = false;
            }
        }
        stats.iterations = iteration;
        if all_done {
            break;
        }
    }
    Ok((z, stats))
}
