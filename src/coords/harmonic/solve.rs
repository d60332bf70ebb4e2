//! Conjugate gradients preconditioned by a multigrid V-cycle, on blocks of
//! right-hand sides: every unknown holds one value per column of the block, so one
//! sweep over the stencil serves all the columns at once.
//!
//! The V-cycle is symmetric (as many damped-Jacobi sweeps after the coarse
//! correction as before, restriction the transpose of trilinear prolongation, each
//! level's own cut-cell operator), so it is a valid preconditioner for CG.

use super::grid::{Level, NONE};
use crate::coords::{BindProgress, Cancelled};
use rayon::prelude::*;

/// Damping of the Jacobi smoother (about optimal for the 7-point stencil).
const OMEGA: f32 = 0.8;
const SMOOTHING_SWEEPS: usize = 2;
/// Sweeps on the coarsest level, a few hundred unknowns at most.
const COARSEST_SWEEPS: usize = 60;
/// Unknowns per parallel task.
const ROWS_PER_TASK: usize = 256;

/// Trilinear prolongation from level `l + 1` to level `l`, and its transpose.
pub(super) struct Transfer {
    /// Per fine unknown: up to 8 (coarse unknown, weight), [`NONE`]-padded.
    fine_from_coarse: Vec<[(u32, f32); 8]>,
    /// Per coarse unknown, the fine unknowns it feeds: CSR offsets and entries.
    coarse_offsets: Vec<u32>,
    coarse_entries: Vec<(u32, f32)>,
}

impl Transfer {
    pub fn new(fine: &Level, coarse: &Level) -> Transfer {
        let fine_from_coarse: Vec<[(u32, f32); 8]> = fine
            .nodes
            .par_iter()
            .map(|&index| {
                let node = fine.frame.coordinates(index as usize);
                let spans = node.map(|x| {
                    if x % 2 == 0 {
                        [(x / 2, 1.0f32), (x / 2, 0.0)]
                    } else {
                        [(x / 2, 0.5), (x / 2 + 1, 0.5)]
                    }
                });
                let mut out = [(NONE, 0.0f32); 8];
                let mut n = 0;
                for &(z, wz) in &spans[2] {
                    for &(y, wy) in &spans[1] {
                        for &(x, wx) in &spans[0] {
                            let weight = wx * wy * wz;
                            if weight == 0.0 {
                                continue;
                            }
                            let unknown = coarse.unknown_of[coarse.frame.index([x, y, z])];
                            if unknown != NONE {
                                out[n] = (unknown, weight);
                                n += 1;
                            }
                        }
                    }
                }
                out
            })
            .collect();
        let mut counts = vec![0u32; coarse.unknowns() + 1];
        for entries in &fine_from_coarse {
            for &(coarse, _) in entries.iter().take_while(|(c, _)| *c != NONE) {
                counts[coarse as usize + 1] += 1;
            }
        }
        for k in 1..counts.len() {
            counts[k] += counts[k - 1];
        }
        let mut fill = counts.clone();
        let mut coarse_entries = vec![(0u32, 0.0f32); *counts.last().unwrap_or(&0) as usize];
        for (fine_unknown, entries) in fine_from_coarse.iter().enumerate() {
            for &(coarse, weight) in entries.iter().take_while(|(c, _)| *c != NONE) {
                let slot = &mut fill[coarse as usize];
                coarse_entries[*slot as usize] = (fine_unknown as u32, weight);
                *slot += 1;
            }
        }
        Transfer {
            fine_from_coarse,
            coarse_offsets: counts,
            coarse_entries,
        }
    }

    /// `fine += P coarse`.
    fn prolong_add(&self, coarse: &[f32], fine: &mut [f32], width: usize) {
        fine.par_chunks_mut(width)
            .zip(&self.fine_from_coarse)
            .for_each(|(row, entries)| {
                for &(c, weight) in entries.iter().take_while(|(c, _)| *c != NONE) {
                    let source = &coarse[c as usize * width..][..width];
                    for (value, &s) in row.iter_mut().zip(source) {
                        *value += weight * s;
                    }
                }
            });
    }

    /// `coarse = scale · Pᵀ fine`.
    fn restrict(&self, fine: &[f32], coarse: &mut [f32], width: usize, scale: f32) {
        coarse
            .par_chunks_mut(width)
            .enumerate()
            .for_each(|(c, row)| {
                row.fill(0.0);
                let range = self.coarse_offsets[c] as usize..self.coarse_offsets[c + 1] as usize;
                for &(f, weight) in &self.coarse_entries[range] {
                    let source = &fine[f as usize * width..][..width];
                    for (value, &s) in row.iter_mut().zip(source) {
                        *value += scale * weight * s;
                    }
                }
            });
    }
}

/// `out = A x` on `level`, `width` columns per unknown.
fn apply(level: &Level, x: &[f32], out: &mut [f32], width: usize) {
    out.par_chunks_mut(width * ROWS_PER_TASK)
        .enumerate()
        .for_each(|(task, block)| {
            for (k, row) in block.chunks_mut(width).enumerate() {
                let unknown = task * ROWS_PER_TASK + k;
                let diagonal = level.diagonal[unknown];
                let own = &x[unknown * width..][..width];
                for (value, &v) in row.iter_mut().zip(own) {
                    *value = diagonal * v;
                }
                for &neighbour in &level.neighbours[unknown] {
                    if neighbour != NONE {
                        let other = &x[neighbour as usize * width..][..width];
                        for (value, &v) in row.iter_mut().zip(other) {
                            *value -= v;
                        }
                    }
                }
            }
        });
}

/// One damped Jacobi sweep for `A z = r`: `z += ω D⁻¹ (r − A z)`, using `scratch`.
fn jacobi(level: &Level, r: &[f32], z: &mut [f32], scratch: &mut [f32], width: usize) {
    apply(level, z, scratch, width);
    z.par_chunks_mut(width)
        .zip(scratch.par_chunks(width))
        .zip(r.par_chunks(width))
        .zip(&level.diagonal)
        .for_each(|(((z, az), r), &diagonal)| {
            let step = OMEGA / diagonal;
            for ((z, &az), &r) in z.iter_mut().zip(az).zip(r) {
                *z += step * (r - az);
            }
        });
}

/// The grid hierarchy and the work buffers of one V-cycle per level.
pub(super) struct Multigrid {
    pub levels: Vec<Level>,
    transfers: Vec<Transfer>,
}

impl Multigrid {
    pub fn new(levels: Vec<Level>) -> Multigrid {
        let transfers = levels
            .windows(2)
            .map(|pair| Transfer::new(&pair[0], &pair[1]))
            .collect();
        Multigrid { levels, transfers }
    }

    /// `z ≈ A⁻¹ r` on level `l` by one V-cycle from zero. Stops early, leaving `z`
    /// unfinished, once `progress` is cancelled (every sweep checks, so a cancel
    /// takes effect within one sweep of the finest level).
    fn vcycle(&self, l: usize, r: &[f32], z: &mut [f32], width: usize, progress: &BindProgress) {
        let level = &self.levels[l];
        let mut scratch = vec![0.0f32; r.len()];
        z.fill(0.0);
        let coarsest = l + 1 == self.levels.len() || self.levels[l + 1].unknowns() == 0;
        let sweeps = if coarsest {
            COARSEST_SWEEPS
        } else {
            SMOOTHING_SWEEPS
        };
        for _ in 0..sweeps {
            if progress.is_cancelled() {
                return;
            }
            jacobi(level, r, z, &mut scratch, width);
        }
        if coarsest {
            return;
        }
        // Residual, restricted; the factor 1/2 makes the coarse operator match the
        // Galerkin product of the h²-scaled operators.
        apply(level, z, &mut scratch, width);
        scratch
            .par_iter_mut()
            .zip(r.par_iter())
            .for_each(|(s, &r)| *s = r - *s);
        let coarse_len = self.levels[l + 1].unknowns() * width;
        let mut coarse_r = vec![0.0f32; coarse_len];
        self.transfers[l].restrict(&scratch, &mut coarse_r, width, 0.5);
        let mut coarse_z = vec![0.0f32; coarse_len];
        self.vcycle(l + 1, &coarse_r, &mut coarse_z, width, progress);
        self.transfers[l].prolong_add(&coarse_z, z, width);
        for _ in 0..sweeps {
            if progress.is_cancelled() {
                return;
            }
            jacobi(level, r, z, &mut scratch, width);
        }
    }
}

/// Column-wise dot products of two blocks, in f64. Partial sums are added in a
/// fixed order, so a bind gives the same weights on every run.
fn dots(a: &[f32], b: &[f32], width: usize) -> Vec<f64> {
    let partials: Vec<Vec<f64>> = a
        .par_chunks(width * ROWS_PER_TASK)
        .zip(b.par_chunks(width * ROWS_PER_TASK))
        .map(|(a, b)| {
            let mut sums = vec![0.0f64; width];
            for (a, b) in a.chunks(width).zip(b.chunks(width)) {
                for ((sum, &a), &b) in sums.iter_mut().zip(a).zip(b) {
                    *sum += f64::from(a) * f64::from(b);
                }
            }
            sums
        })
        .collect();
    let mut total = vec![0.0f64; width];
    for partial in partials {
        total.iter_mut().zip(partial).for_each(|(t, p)| *t += p);
    }
    total
}

/// How a block solve went.
#[derive(Clone, Copy, Debug, Default)]
pub struct BlockStats {
    pub iterations: usize,
    /// The largest relative residual ‖b − Ax‖/‖b‖ over the columns at the end.
    pub relative_residual: f64,
}

/// Solve `A x = b` on the finest level for a block of `width` columns, to relative
/// residual `tolerance` in every column, advancing `progress` once per iteration
/// (at most `max_iterations`).
pub(super) fn solve_block(
    multigrid: &Multigrid,
    b: &[f32],
    width: usize,
    tolerance: f64,
    max_iterations: usize,
    progress: &BindProgress,
) -> Result<(Vec<f32>, BlockStats), Cancelled> {
    let level = &multigrid.levels[0];
    let n = b.len();
    let mut x = vec![0.0f32; n];
    let mut r = b.to_vec();
    let mut p = vec![0.0f32; n];
    multigrid.vcycle(0, &r, &mut p, width, progress);
    let mut rz = dots(&r, &p, width);
    let b_norms: Vec<f64> = dots(b, b, width).into_iter().map(f64::sqrt).collect();
    let mut q = vec![0.0f32; n];
    let mut stats = BlockStats::default();
    for iteration in 1..=max_iterations {
        if progress.is_cancelled() {
            return Err(Cancelled);
        }
        apply(level, &p, &mut q, width);
        let pq = dots(&p, &q, width);
        let alpha: Vec<f32> = rz
            .iter()
            .zip(&pq)
            .map(|(&rz, &pq)| if pq > 0.0 { (rz / pq) as f32 } else { 0.0 })
            .collect();
        let axpy = |target: &mut [f32], source: &[f32], sign: f32| {
            target
                .par_chunks_mut(width)
                .zip(source.par_chunks(width))
                .for_each(|(t, s)| {
                    for ((t, &s), &a) in t.iter_mut().zip(s).zip(&alpha) {
                        *t += sign * a * s;
                    }
                });
        };
        axpy(&mut x, &p, 1.0);
        axpy(&mut r, &q, -1.0);
        progress.advance(1);
        stats.iterations = iteration;
        let r_norms = dots(&r, &r, width);
        stats.relative_residual = r_norms
            .iter()
            .zip(&b_norms)
            .map(|(&r, &b)| if b > 0.0 { r.sqrt() / b } else { 0.0 })
            .fold(0.0, f64::max);
        if stats.relative_residual <= tolerance {
            break;
        }
        // z = M r, into q (A p is no longer needed).
        multigrid.vcycle(0, &r, &mut q, width, progress);
        if progress.is_cancelled() {
            return Err(Cancelled);
        }
        let rz_next = dots(&r, &q, width);
        let beta: Vec<f32> = rz_next
            .iter()
            .zip(&rz)
            .map(|(&next, &previous)| {
                if previous > 0.0 {
                    (next / previous) as f32
                } else {
                    0.0
                }
            })
            .collect();
        p.par_chunks_mut(width)
            .zip(q.par_chunks(width))
            .for_each(|(p, z)| {
                for ((p, &z), &beta) in p.iter_mut().zip(z).zip(&beta) {
                    *p = z + beta * *p;
                }
            });
        rz = rz_next;
    }
    Ok((x, stats))
}
