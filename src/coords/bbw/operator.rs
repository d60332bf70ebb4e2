//! The discrete Laplacian of bounded biharmonic weights on the harmonic solve's
//! grid ([`crate::coords::harmonic::grid`]), and the energy's quadratic form.
//!
//! The harmonic solve's cut-cell stencil is the symmetric one (an arm cut at θh
//! has coefficient 1/θ), which is the right operator for Laplace's equation but
//! not the Laplacian's value at a cut node: there it is off by the factor
//! (θ₋ + θ₊)/2 per axis. The energy needs the value, so here each axis takes
//! the Shortley–Weller coefficients `2 / (θ_arm (θ₋ + θ₊))` (1 on an uncut
//! axis), which are consistent at every node and still reproduce linear
//! functions exactly (the two arms' terms cancel for any θ). With `D` that
//! h²-scaled (negative) Laplacian on the unknowns, `b` the boundary data it
//! reads across cut arms, and `m` each node's dual cell clipped at the
//! crossings (`Π_axes (θ₋ + θ₊)/2`, in cells), `½ Σᵢ mᵢ ((D w − b)ᵢ)²` is
//! `∫ (Δw)² dV` by the midpoint rule on the nodes' cells, up to a constant.
//!
//! Those rows alone are not enough: `D` is square and invertible, so their
//! minimiser is `D⁻¹ b`, the harmonic solution, whatever the bounds. The
//! paper's finite elements also sum the Laplacian's rows at the boundary
//! vertices, which hold the normal flux and, as the mesh is refined, clamp the
//! weights' normal derivative to zero on the cage (the clamped plate: wᵢ = the
//! boundary data and ∂wᵢ/∂n = 0). Here each cut arm adds that row: the
//! one-sided derivative along the arm, `s (g − wᵢ)/θ` in cells (s the arm's
//! direction), less the boundary data's surface gradient along the axis, which
//! is `nₐ ∂w/∂n` once the tangential part is taken away; weight 1 per arm.

use crate::coords::harmonic::grid::{Level, NONE};
use faer::sparse::{SparseColMat, Triplet};

/// `D`, `m` and the boundary terms of every handle, for one grid level.
pub(super) struct Operator {
    /// Inside nodes: the unknowns.
    unknowns: usize,
    /// Rows of `D`: CSR offsets into `entries`; one row per unknown (its
    /// Laplacian), then one per cut arm (its boundary flux).
    pub offsets: Vec<usize>,
    /// `(column, coefficient)`.
    pub entries: Vec<(u32, f64)>,
    /// Per row, its weight: a node's clipped cell volume, in cells, or 1.
    pub mass: Vec<f64>,
    /// Boundary terms `(row, cage vertex, value)`: handle `k`'s `b` is the
    /// sum of the values of the terms of vertex `k` in each row.
    pub boundary: Vec<(u32, u32, f64)>,
}

impl Operator {
    pub fn new(level: &Level) -> Operator {
        let n = level.unknowns();
        // Per unknown, θ of each arm (1 where a neighbour is an unknown).
        let mut theta = vec![[1.0f64; 6]; n];
        for arm in &level.cut_arms {
            theta[arm.unknown as usize][arm.arm as usize] = 1.0 / f64::from(arm.coefficient);
        }
        let coefficients: Vec<[f64; 6]> = theta
            .iter()
            .map(|t| {
                std::array::from_fn(|arm| {
                    let axis = arm / 2;
                    2.0 / (t[arm] * (t[2 * axis] + t[2 * axis + 1]))
                })
            })
            .collect();
        let mass = theta
            .iter()
            .map(|t| (0..3).map(|a| 0.5 * (t[2 * a] + t[2 * a + 1])).product())
            .collect();
        let mut offsets = Vec::with_capacity(n + 1);
        let mut entries = Vec::with_capacity(7 * n);
        offsets.push(0);
        for (unknown, c) in coefficients.iter().enumerate() {
            entries.push((unknown as u32, c.iter().sum()));
            for (arm, &neighbour) in level.neighbours[unknown].iter().enumerate() {
                if neighbour != NONE {
                    entries.push((neighbour, -c[arm]));
                }
            }
            offsets.push(entries.len());
        }
        let mut mass: Vec<f64> = mass;
        let mut boundary = Vec::new();
        for arm in &level.cut_arms {
            let c = coefficients[arm.unknown as usize][arm.arm as usize];
            for (&corner, &value) in arm.corners.iter().zip(&arm.values) {
                if value != 0.0 {
                    boundary.push((arm.unknown, corner, c * f64::from(value)));
                }
            }
        }
        // The flux rows: r = s (g − wᵢ)/θ − ∂ₐg, that is D = −s/θ at the
        // unknown and b = −(s/θ) g + ∂ₐg.
        for arm in &level.cut_arms {
            let row = (offsets.len() - 1) as u32;
            let sign = if arm.arm % 2 == 1 { 1.0 } else { -1.0 };
            let scale = sign * f64::from(arm.coefficient);
            entries.push((arm.unknown, -scale));
            offsets.push(entries.len());
            mass.push(1.0);
            let mut seen = [u32::MAX; 4];
            for (k, (&corner, (&value, &slope))) in arm
                .corners
                .iter()
                .zip(arm.values.iter().zip(&arm.slopes))
                .enumerate()
            {
                // A triangle repeats its last corner with nothing.
                if seen[..k].contains(&corner) && value == 0.0 && slope == 0.0 {
                    continue;
                }
                seen[k] = corner;
                let term = -scale * f64::from(value) + f64::from(slope);
                if term != 0.0 {
                    boundary.push((row, corner, term));
                }
            }
        }
        Operator {
            unknowns: n,
            offsets,
            entries,
            mass,
            boundary,
        }
    }

    pub fn unknowns(&self) -> usize {
        self.unknowns
    }

    /// Rows of `D`: the unknowns' Laplacians and the cut arms' fluxes.
    pub fn rows(&self) -> usize {
        self.mass.len()
    }

    pub fn row(&self, unknown: usize) -> &[(u32, f64)] {
        &self.entries[self.offsets[unknown]..self.offsets[unknown + 1]]
    }

    /// Entries of the lower triangle of `Dᵀ diag(m) D` (the energy's Hessian),
    /// with `shift` added to the diagonal; duplicates are summed by the matrix.
    fn hessian_triplets(&self, shift: f64) -> Vec<Triplet<usize, usize, f64>> {
        let n = self.unknowns();
        let mut triplets = Vec::with_capacity(28 * n + self.rows());
        for r in 0..self.rows() {
            let row = self.row(r);
            let m = self.mass[r];
            for &(a, da) in row {
                for &(b, db) in row {
                    if a >= b {
                        triplets.push(Triplet::new(a as usize, b as usize, m * da * db));
                    }
                }
            }
        }
        triplets.extend((0..n).map(|k| Triplet::new(k, k, shift)));
        triplets
    }

    /// The lower triangle of `Dᵀ diag(m) D + shift·I`, compressed by column.
    pub fn shifted_hessian(&self, shift: f64) -> Result<SparseColMat<usize, f64>, String> {
        let n = self.unknowns();
        SparseColMat::try_new_from_triplets(n, n, &self.hessian_triplets(shift))
            .map_err(|error| format!("{error:?}"))
    }

    /// Handle `k`'s boundary vector `b` (one value per row).
    pub fn boundary_of(&self, vertex: u32, out: &mut [f64]) {
        out.fill(0.0);
        for &(unknown, corner, value) in &self.boundary {
            if corner == vertex {
                out[unknown as usize] += value;
            }
        }
    }

    /// `out = D x` for one column (`out` one value per row).
    pub fn apply(&self, x: &[f64], out: &mut [f64]) {
        for (r, value) in out.iter_mut().enumerate() {
            *value = self.row(r).iter().map(|&(j, d)| d * x[j as usize]).sum();
        }
    }

    /// `out = Dᵀ (m ⊙ r)` for one column (`r` one value per row).
    pub fn apply_transpose_weighted(&self, r: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for (row, &r) in r.iter().enumerate() {
            let scaled = self.mass[row] * r;
            for &(j, d) in self.row(row) {
                out[j as usize] += d * scaled;
            }
        }
    }
}
