//! How every weights column's vector moved in a pose, and the one function
//! that applies such moves to weights rows on the CPU (the vertex shader's
//! twin is `blend_row` and `blend_matrix_row` in the mesh shader).
//!
//! Most families are linear: a point moves by `Σₖ wₖ dₖ`, one displacement per
//! column. Somigliana coordinates with a local blend are *normalised*: each
//! column also carries a 3×3 matrix Mₖ, and a point at rest position x goes to
//!
//! `x' = o + (I + Σₖ wₖ Mₖ)⁻¹ (x − o + Σₖ wₖ dₖ)`,
//!
//! o the origin the dₖ are taken about (moving it changes dₖ by `−Mₖ Δo`, not
//! the result). Every Mₖ is zero at rest, so both forms give the rest pose
//! exactly for any weights, as the displacement form always has.

use super::dtype::WeightValue;
use glam::{DMat3, DVec3};
use rayon::prelude::*;

/// Each weights column's move in one pose: linear (no matrices) or normalised.
#[derive(Clone, Debug, PartialEq)]
pub struct ColumnMoves {
    origin: DVec3,
    vectors: Vec<DVec3>,
    /// One per column up to the last column whose matrix is not zero (later
    /// columns carry none); empty for a linear move.
    matrices: Vec<DMat3>,
}

impl ColumnMoves {
    /// Displacements, one per column: `x' = x + Σ wₖ dₖ`.
    pub fn linear(displacements: Vec<DVec3>) -> Self {
        Self {
            origin: DVec3::ZERO,
            vectors: displacements,
            matrices: Vec::new(),
        }
    }

    /// The normalised form about `origin`, one vector and one matrix per
    /// column (equal lengths: the caller builds them together). Trailing zero
    /// matrices are dropped, so that neither the CPU nor the vertex shader
    /// blends them (Somigliana's face columns carry none).
    pub fn normalised(origin: DVec3, vectors: Vec<DVec3>, mut matrices: Vec<DMat3>) -> Self {
        debug_assert_eq!(vectors.len(), matrices.len());
        let carried = (matrices.iter())
            .rposition(|m| *m != DMat3::ZERO)
            .map_or(0, |last| last + 1);
        matrices.truncate(carried);
        Self {
            origin,
            vectors,
            matrices,
        }
    }

    /// Columns moved.
    pub fn len(&self) -> usize {
        self.vectors.len()
    }

    pub fn is_empty(&self) -> bool {
        self.vectors.is_empty()
    }

    /// Whether no column carries a matrix: `x' = x + Σ wₖ dₖ` (a normalised
    /// form whose matrices are all zero is that too).
    pub fn is_linear(&self) -> bool {
        self.matrices.is_empty()
    }

    /// The point the vectors are taken about (irrelevant when linear).
    pub fn origin(&self) -> DVec3 {
        self.origin
    }

    /// Each column's vector dₖ: its displacement when linear.
    pub fn vectors(&self) -> &[DVec3] {
        &self.vectors
    }

    /// Each column's matrix Mₖ, up to the last that is not zero (the rest are
    /// zero); empty when linear.
    pub fn matrices(&self) -> &[DMat3] {
        &self.matrices
    }

    /// The same moves with the vectors taken about `origin`: `dₖ − Mₖ (origin −
    /// o)`. A renderer whose positions are measured from its own origin asks
    /// for that one, so that nothing is lost to f32 far from the world's.
    pub fn about(&self, origin: DVec3) -> Self {
        if self.is_linear() {
            return self.clone();
        }
        let shift = origin - self.origin;
        let mut vectors = self.vectors.clone();
        // Columns past the matrices carry none, and their vectors stay.
        for (vector, &matrix) in vectors.iter_mut().zip(&self.matrices) {
            *vector -= matrix * shift;
        }
        Self {
            origin,
            vectors,
            matrices: self.matrices.clone(),
        }
    }

    /// `rest` moved by these moves through the row-major weights `values`
    /// (one row per rest position, one column per move), accumulated in f64:
    /// the one deformation of every weights matrix, whatever its dtype.
    pub(super) fn apply<T: WeightValue>(&self, values: &[T], rest: &[DVec3]) -> Vec<DVec3> {
        let cols = self.vectors.len();
        if self.is_linear() {
            return super::dtype::displaced(values, rest, &self.vectors);
        }
        values
            .par_chunks(cols.max(1))
            .take(rest.len())
            .zip(rest.par_iter())
            .map(|(row, &x)| {
                let mut matrix = DMat3::IDENTITY;
                for (&w, &m) in row.iter().zip(&self.matrices) {
                    matrix += m * w.to_f64();
                }
                let mut vector = x - self.origin;
                for (&w, &d) in row.iter().zip(&self.vectors) {
                    vector += w.to_f64() * d;
                }
                self.origin + solve(matrix, vector)
            })
            .collect()
    }
}

/// `matrix⁻¹ vector`, or `vector` itself where the matrix is singular (a point
/// whose blended frames cancel, which only a degenerate pose gives).
fn solve(matrix: DMat3, vector: DVec3) -> DVec3 {
    let determinant = matrix.determinant();
    if determinant.abs() > 1e-300 && determinant.is_finite() {
        matrix.inverse() * vector
    } else {
        vector
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_linear_move_is_the_displacement_form() {
        let moves = ColumnMoves::linear(vec![DVec3::X, DVec3::new(0.0, 2.0, 0.0)]);
        let moved = moves.apply(&[0.25f32, 0.75], &[DVec3::new(1.0, 1.0, 1.0)]);
        assert_eq!(moved, vec![DVec3::new(1.25, 2.5, 1.0)]);
        assert_eq!(moves.about(DVec3::splat(7.0)), moves);
    }

    #[test]
    fn a_normalised_move_solves_its_blended_matrix_whatever_its_origin() {
        // Two columns; the weights blend M to diag(1, 1, 1) + 0.5 diag(1, 0, 0).
        let vectors = vec![DVec3::new(0.5, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)];
        let matrices = vec![DMat3::from_diagonal(DVec3::new(1.0, 0.0, 0.0)), DMat3::ZERO];
        let moves = ColumnMoves::normalised(DVec3::ZERO, vectors, matrices);
        let rest = [DVec3::new(2.0, 1.0, 3.0)];
        let moved = moves.apply(&[0.5f64, 0.5], &rest)[0];
        // x − o + Σ w d = (2.25, 1.5, 3), divided by (1.5, 1, 1) on x.
        let want = DVec3::new(1.5, 1.5, 3.0);
        assert!((moved - want).length() < 1e-15, "{moved}");
        let far = moves.about(DVec3::new(1e7, -3e6, 2e5));
        let again = far.apply(&[0.5f64, 0.5], &rest)[0];
        assert!((again - want).length() < 1e-8, "{again}");
        // At rest (zero vectors and matrices) any weights give the rest point.
        let still = ColumnMoves::normalised(DVec3::ONE, vec![DVec3::ZERO; 2], vec![DMat3::ZERO; 2]);
        assert!(still.is_linear());
        assert_eq!(still.apply(&[0.3f32, -2.0], &rest), rest.to_vec());
    }
}
