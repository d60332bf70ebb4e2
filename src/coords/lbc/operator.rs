//! The discrete total variation of local barycentric coordinates on the
//! harmonic solve's grid ([`crate::coords::harmonic::grid`]).
//!
//! Each inside node owns the grid cell ahead of it: its gradient there is the
//! forward differences to its +x, +y and +z neighbours, and the cell adds
//! `‖(Δx, Δy, Δz)‖` to the energy (isotropic within the cell, in cells: the
//! energy is `∫ |∇w| dV / h²`). An arm the cage cuts at θ (either direction)
//! is the slab between the node and the crossing, of volume θ with gradient
//! `(g − w)/θ` across it: it adds `|w − g|` with `g` the boundary data at the
//! crossing, which is how the boundary values enter (total variation allows a
//! jump there and charges it). So every row of the difference operator `D` has
//! entries ±1 only, and `DᵀD + I` has its spectrum in [1, 13 + cuts], whatever
//! the cut fractions: conjugate gradients solve it in a few tens of steps.

use crate::coords::harmonic::grid::{Level, NONE};

/// `D` and the boundary data of every handle, for one grid level. Rows: first
/// the interior differences `w[to] − w[from]`, grouped by the node owning the
/// cell, then one row `w[unknown] − g` per cut arm.
pub(super) struct Differences {
    unknowns: usize,
    /// `(from, to)` per interior row.
    pub pairs: Vec<(u32, u32)>,
    /// Per owning node, its rows: `pairs[groups[i]..groups[i + 1]]`.
    pub groups: Vec<u32>,
    /// The unknown of each cut row.
    pub cut_unknowns: Vec<u32>,
    /// The boundary data of each cut row: cage vertices and their values.
    pub cut_values: Vec<([u32; 4], [f64; 4])>,
}

impl Differences {
    pub fn new(level: &Level) -> Differences {
        let n = level.unknowns();
        let mut pairs = Vec::with_capacity(3 * n);
        let mut groups = Vec::with_capacity(n + 1);
        groups.push(0);
        for (from, neighbours) in level.neighbours.iter().enumerate() {
            for axis in 0..3 {
                let ahead = neighbours[2 * axis + 1];
                if ahead != NONE {
                    pairs.push((from as u32, ahead));
                }
            }
            groups.push(pairs.len() as u32);
        }
        let cut_unknowns = level.cut_arms.iter().map(|arm| arm.unknown).collect();
        let cut_values = level
            .cut_arms
            .iter()
            .map(|arm| (arm.corners, arm.values.map(f64::from)))
            .collect();
        Differences {
            unknowns: n,
            pairs,
            groups,
            cut_unknowns,
            cut_values,
        }
    }

    pub fn unknowns(&self) -> usize {
        self.unknowns
    }

    /// Rows of `D`.
    pub fn rows(&self) -> usize {
        self.pairs.len() + self.cut_unknowns.len()
    }

    /// Handle `vertex`'s boundary vector `b`: zero on interior rows, `g` on
    /// cut rows (a triangle's crossing repeats its last corner with value 0).
    pub fn boundary_of(&self, vertex: u32, out: &mut [f64]) {
        let (interior, cuts) = out.split_at_mut(self.pairs.len());
        interior.fill(0.0);
        for (out, (corners, values)) in cuts.iter_mut().zip(&self.cut_values) {
            *out = corners
                .iter()
                .zip(values)
                .filter(|(&corner, _)| corner == vertex)
                .map(|(_, &value)| value)
                .sum();
        }
    }

    /// `out = D x` for one handle.
    pub fn apply(&self, x: &[f64], out: &mut [f64]) {
        let (interior, cuts) = out.split_at_mut(self.pairs.len());
        for (out, &(from, to)) in interior.iter_mut().zip(&self.pairs) {
            *out = x[to as usize] - x[from as usize];
        }
        for (out, &unknown) in cuts.iter_mut().zip(&self.cut_unknowns) {
            *out = x[unknown as usize];
        }
    }

    /// `out = Dᵀ r` for one handle.
    pub fn apply_transpose(&self, r: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        let (interior, cuts) = r.split_at(self.pairs.len());
        for (&r, &(from, to)) in interior.iter().zip(&self.pairs) {
            out[to as usize] += r;
            out[from as usize] -= r;
        }
        for (&r, &unknown) in cuts.iter().zip(&self.cut_unknowns) {
            out[unknown as usize] += r;
        }
    }

    /// The diagonal of `DᵀD + I`: Jacobi's preconditioner.
    pub fn normal_diagonal(&self) -> Vec<f64> {
        let mut diagonal = vec![1.0; self.unknowns];
        for &(from, to) in &self.pairs {
            diagonal[from as usize] += 1.0;
            diagonal[to as usize] += 1.0;
        }
        for &unknown in &self.cut_unknowns {
            diagonal[unknown as usize] += 1.0;
        }
        diagonal
    }

    /// The proximal map of the energy with step `1/ρ` on one handle's rows
    /// `v` (in place): each cell's differences shrunk together towards zero by
    /// `1/ρ` in length, each cut row by `1/ρ` in magnitude.
    pub fn shrink(&self, v: &mut [f64], rho: f64) {
        let threshold = 1.0 / rho;
        let (interior, cuts) = v.split_at_mut(self.pairs.len());
        for range in self.groups.windows(2) {
            let cell = &mut interior[range[0] as usize..range[1] as usize];
            let length = cell.iter().map(|d| d * d).sum::<f64>().sqrt();
            let scale = if length > threshold {
                1.0 - threshold / length
            } else {
                0.0
            };
            cell.iter_mut().for_each(|d| *d *= scale);
        }
        for d in cuts {
            *d = d.signum() * (d.abs() - threshold).max(0.0);
        }
    }

    /// The energy of one handle's residual rows `r = Dw − b`.
    pub fn energy(&self, r: &[f64]) -> f64 {
        let (interior, cuts) = r.split_at(self.pairs.len());
        let cells: f64 = self
            .groups
            .windows(2)
            .map(|range| {
                interior[range[0] as usize..range[1] as usize]
                    .iter()
                    .map(|d| d * d)
                    .sum::<f64>()
                    .sqrt()
            })
            .sum();
        cells + cuts.iter().map(|d| d.abs()).sum::<f64>()
    }
}
