//! Quality read-outs of a weights matrix: how many rows have negative weights, and
//! how far the rows are from partition of unity and linear precision.

use super::Weights;
use glam::DVec3;
use rayon::prelude::*;

/// A weight counts as negative below `-NEGATIVE_TOLERANCE`.
// A weight that is zero in theory can come out a few ulps below zero after f64
// cancellation and f32 storage (say -1e-9). 1e-7 is just under f32's epsilon, the
// rounding step of weights near 1, so that noise is not counted while any negative
// big enough to pull a vertex visibly is.
pub const NEGATIVE_TOLERANCE: f64 = 1e-7;

/// Quality of one set of weights against the points and cage they were bound for.
///
/// Negativity is measured over the vertices inside the cage (and on it), where a
/// family's promise holds; vertices outside follow the family's outside policy
/// (MVC weights, or Green coordinates' exterior extension), which promises no
/// sign, so their negative weights are reported apart.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WeightQuality {
    /// Inside vertices with any weight < -NEGATIVE_TOLERANCE, as a share of the
    /// inside vertices, in [0, 1].
    pub negative_share: f64,
    /// Inside vertices counted in negative_share.
    pub negative_vertices: usize,
    /// The most negative weight of an inside vertex (0 if none is negative) and
    /// where: (row, col).
    pub most_negative: f64,
    pub most_negative_at: Option<(usize, usize)>,
    /// Vertices outside the cage, and how many of them have a negative weight.
    pub outside_vertices: usize,
    pub outside_negative_vertices: usize,
    /// The most negative weight of an outside vertex (0 if none is negative).
    pub outside_most_negative: f64,
    /// max over rows of |Σ_j λ_ij − 1|.
    pub max_partition_error: f64,
    /// max over rows of |Σ_j λ_ij c_j − x_i| divided by the cage's bounding-box diagonal.
    pub max_linear_precision_error: f64,
}

impl WeightQuality {
    /// `points`: the rows' rest positions; `cage`: the rest cage positions (the
    /// columns); `outside`: the rows outside the cage, ascending. Every row is
    /// measured. `most_negative` is the true minimum even when it is within the
    /// tolerance, which only decides what is counted. A degenerate cage (zero
    /// diagonal) gives the linear precision error unscaled.
    pub fn measure(weights: &Weights, points: &[DVec3], cage: &[DVec3], outside: &[u32]) -> Self {
        Self::measure_columns(weights, points, cage, cage.len(), outside)
    }

    /// [`Self::measure`] for a family whose columns are not all cage vertices:
    /// `columns` holds each column's rest vector ([`super::Method::rest_columns`]),
    /// the first `vertex_columns` of them the cage positions. Partition of unity
    /// and negativity are measured over those; linear precision over all.
    pub fn measure_columns(
        weights: &Weights,
        points: &[DVec3],
        columns: &[DVec3],
        vertex_columns: usize,
        outside: &[u32],
    ) -> Self {
        Self::measure_with(weights, points, columns, vertex_columns, false, outside)
    }

    /// [`Self::measure_columns`] of weights of `method` bound to `bound` (the
    /// cage the family binds). For 3×3 blocks (Somigliana coordinates) the
    /// partition error is the largest entry of Σ Bᵥ − I.
    pub fn measure_family(
        weights: &Weights,
        points: &[DVec3],
        method: super::Method,
        bound: &crate::geometry::Cage,
        outside: &[u32],
    ) -> Self {
        let blocks =
            method.spec().columns == super::family::ColumnLayout::BlocksPerVertexThenTriangle;
        let columns = method.rest_columns(bound);
        let vertex_columns = method.vertex_columns(bound);
        Self::measure_with(weights, points, &columns, vertex_columns, blocks, outside)
    }

    fn measure_with(
        weights: &Weights,
        points: &[DVec3],
        columns: &[DVec3],
        vertex_columns: usize,
        blocks: bool,
        outside: &[u32],
    ) -> Self {
        assert_eq!(points.len(), weights.rows, "one point per weights row");
        assert_eq!(
            columns.len(),
            weights.cols,
            "one rest vector per weights column"
        );
        let cage = &columns[..vertex_columns.min(columns.len())];
        let diagonal = {
            // A block's columns (v, 0, b) hold (vᵥ)_b e_x.
            let positions: Vec<DVec3> = match blocks {
                true => (cage.chunks_exact(9))
                    .map(|c| DVec3::new(c[0].x, c[1].x, c[2].x))
                    .collect(),
                false => cage.to_vec(),
            };
            let (lo, hi) = crate::geometry::bounds_of(&positions);
            (hi - lo).length()
        };
        let scale = if diagonal > 0.0 { 1.0 / diagonal } else { 1.0 };
        let is_outside = |i: usize| outside.binary_search(&(i as u32)).is_ok();
        let (inside, beyond) = (0..weights.rows)
            .into_par_iter()
            .map(|i| {
                let row = if blocks {
                    RowQuality::of_blocks(i, weights.row(i), points[i], columns, cage.len())
                } else {
                    RowQuality::of(i, weights.row(i), points[i], columns, cage.len())
                };
                if is_outside(i) {
                    (RowQuality::default(), row)
                } else {
                    (row, RowQuality::default())
                }
            })
            .reduce(
                || (RowQuality::default(), RowQuality::default()),
                |a, b| (RowQuality::merge(a.0, b.0), RowQuality::merge(a.1, b.1)),
            );
        let inside_rows = weights.rows - outside.len().min(weights.rows);
        let most_negative_at = inside.min_at.filter(|_| inside.min < 0.0);
        Self {
            negative_share: if inside_rows == 0 {
                0.0
            } else {
                inside.negative_rows as f64 / inside_rows as f64
            },
            negative_vertices: inside.negative_rows,
            most_negative: if most_negative_at.is_some() {
                inside.min
            } else {
                0.0
            },
            most_negative_at,
            outside_vertices: weights.rows - inside_rows,
            outside_negative_vertices: beyond.negative_rows,
            outside_most_negative: beyond.min.min(0.0),
            max_partition_error: max_keeping_nan(inside.partition_error, beyond.partition_error),
            max_linear_precision_error: max_keeping_nan(inside.linear_error, beyond.linear_error)
                * scale,
        }
    }
}

/// What one row (or a merged range of rows) contributes; `Copy`, so no allocation per row.
#[derive(Clone, Copy, Debug)]
struct RowQuality {
    negative_rows: usize,
    min: f64,
    min_at: Option<(usize, usize)>,
    partition_error: f64,
    linear_error: f64,
}

impl Default for RowQuality {
    fn default() -> Self {
        Self {
            negative_rows: 0,
            min: f64::INFINITY,
            min_at: None,
            partition_error: 0.0,
            linear_error: 0.0,
        }
    }
}

impl RowQuality {
    fn of(i: usize, row: &[f32], x: DVec3, columns: &[DVec3], vertex_columns: usize) -> Self {
        let mut quality = Self::default();
        let mut sum = 0.0;
        // Σλ(c − x), not Σλc − x: the latter adds (Σλ − 1)·x, which grows with the
        // scene's distance from the origin (f32 rows far away would read as 1e-2
        // wrong) and is the partition error, measured on its own.
        let mut offset = DVec3::ZERO;
        for (j, (&w, &c)) in row.iter().zip(columns).enumerate() {
            let w = f64::from(w);
            if j >= vertex_columns {
                offset += w * c; // a rest vector, not a position
                continue;
            }
            offset += w * (c - x);
            sum += w;
            if w < quality.min {
                quality.min = w;
                quality.min_at = Some((i, j));
            }
        }
        quality.negative_rows = usize::from(quality.min < -NEGATIVE_TOLERANCE);
        quality.partition_error = (sum - 1.0).abs();
        quality.linear_error = offset.length();
        quality
    }

    /// [`Self::of`] for 3×3 blocks, 9 columns each, (a, b) at `3a + b`: column
    /// (v, a, b) holds (vᵥ)_b e_a, centred as (vᵥ − x)_b e_a, and partition of
    /// unity is Σ Bᵥ = I.
    fn of_blocks(
        i: usize,
        row: &[f32],
        x: DVec3,
        columns: &[DVec3],
        vertex_columns: usize,
    ) -> Self {
        let mut quality = Self::default();
        let mut sum = [[0.0f64; 3]; 3];
        let mut offset = DVec3::ZERO;
        for (j, (&w, &c)) in row.iter().zip(columns).enumerate() {
            let w = f64::from(w);
            if j >= vertex_columns {
                offset += w * c;
                continue;
            }
            let (a, b) = ((j % 9) / 3, j % 3);
            offset += w * (c - x[b] * DVec3::AXES[a]);
            sum[a][b] += w;
            // A vertex's weight, as the heatmap and the negativity view show
            // it: its block's x-from-x entry (the off-diagonal ones are signed
            // by design).
            if j % 9 == 0 && w < quality.min {
                quality.min = w;
                quality.min_at = Some((i, j));
            }
        }
        quality.negative_rows = usize::from(quality.min < -NEGATIVE_TOLERANCE);
        quality.partition_error = (0..9)
            .map(|k| (sum[k / 3][k % 3] - f64::from(u8::from(k / 3 == k % 3))).abs())
            .fold(0.0, max_keeping_nan);
        quality.linear_error = offset.length();
        quality
    }

    /// Associative and order-independent (ties go to the lower (row, col)), so the
    /// parallel reduction gives the same answer every run.
    fn merge(a: Self, b: Self) -> Self {
        let (min, min_at) = match (a.min_at, b.min_at) {
            (Some(at_a), Some(at_b)) if b.min < a.min || (b.min == a.min && at_b < at_a) => {
                (b.min, b.min_at)
            }
            (None, Some(_)) => (b.min, b.min_at),
            _ => (a.min, a.min_at),
        };
        Self {
            negative_rows: a.negative_rows + b.negative_rows,
            min,
            min_at,
            partition_error: max_keeping_nan(a.partition_error, b.partition_error),
            linear_error: max_keeping_nan(a.linear_error, b.linear_error),
        }
    }
}

/// A NaN weight makes the error NaN rather than being silently skipped by `f64::max`.
fn max_keeping_nan(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// The `k` largest weights of a row with their column index, largest first, ties by
/// lower index.
pub fn top_weights(row: &[f32], k: usize) -> Vec<(usize, f32)> {
    // `+ 0.0` turns -0.0 into 0.0 so the two tie instead of ordering by sign bit.
    let descending = |a: &(usize, f32), b: &(usize, f32)| {
        (b.1 + 0.0).total_cmp(&(a.1 + 0.0)).then(a.0.cmp(&b.0))
    };
    let mut all: Vec<(usize, f32)> = row.iter().copied().enumerate().collect();
    let k = k.min(all.len());
    if k == 0 {
        return Vec::new();
    }
    if k < all.len() {
        all.select_nth_unstable_by(k - 1, descending);
        all.truncate(k);
    }
    all.sort_unstable_by(descending);
    all
}

/// The smallest weight of a row and its column, if it is below zero (ties: lower index).
pub fn most_negative(row: &[f32]) -> Option<(usize, f32)> {
    let mut best: Option<(usize, f32)> = None;
    for (j, &w) in row.iter().enumerate() {
        if w < best.map_or(0.0, |(_, b)| b) {
            best = Some((j, w));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coords::mvc::{mvc_weights, MvcScratch};
    use crate::geometry::{procedural, Cage};

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12
    }

    fn mvc_matrix(cage: &Cage, points: &[DVec3]) -> Weights {
        let cols = cage.vertex_count();
        let mut weights = Weights::zeros(points.len(), cols);
        let mut row = vec![0.0; cols];
        let mut scratch = MvcScratch::default();
        for (&x, out) in points.iter().zip(weights.values.chunks_mut(cols)) {
            mvc_weights(x, cage, &mut row, &mut scratch);
            for (out, &w) in out.iter_mut().zip(&row) {
                *out = w as f32;
            }
        }
        weights
    }

    #[test]
    fn measures_a_hand_made_matrix_exactly() {
        // Bounding box 2 × 2 × 1: diagonal 3.
        let cage = [
            DVec3::ZERO,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
        ];
        let rows: [[f32; 4]; 5] = [
            [0.25, 0.25, 0.25, 0.25], // exact
            [1.5, -0.5, 0.0, 0.0],    // negative; off by 0.6 in z
            [0.5, 0.0, 0.0, 0.25],    // sums to 0.75; Σλc is its point, Σλ(c − x) is not
            [1.0, 0.0, -1e-8, 0.0],   // negative only within tolerance
            [0.5, 0.5, -0.5, 0.5],    // as negative as row 1, later: not the reported one
        ];
        let points = [
            DVec3::new(0.5, 0.5, 0.25),
            DVec3::new(-1.0, 0.0, 0.6),
            DVec3::new(0.0, 0.0, 0.25),
            DVec3::ZERO,
            DVec3::new(1.0, -1.0, 0.5),
        ];
        let weights = Weights {
            rows: 5,
            cols: 4,
            values: rows.concat(),
        };
        let quality = WeightQuality::measure(&weights, &points, &cage, &[]);
        assert_eq!(quality.negative_vertices, 2);
        assert!(close(quality.negative_share, 0.4));
        assert_eq!(quality.most_negative, -0.5);
        assert_eq!(quality.most_negative_at, Some((1, 1)));
        assert!(close(quality.max_partition_error, 0.25));
        assert!(close(quality.max_linear_precision_error, 0.6 / 3.0));

        // Row 1 outside the cage: its negative weight is reported apart, and the
        // inside share is of the four inside rows.
        let split = WeightQuality::measure(&weights, &points, &cage, &[1]);
        assert_eq!(split.negative_vertices, 1);
        assert!(close(split.negative_share, 0.25));
        assert_eq!(split.most_negative, -0.5);
        assert_eq!(split.most_negative_at, Some((4, 2)));
        assert_eq!(split.outside_vertices, 1);
        assert_eq!(split.outside_negative_vertices, 1);
        assert_eq!(split.outside_most_negative, -0.5);
        // Partition of unity and linear precision still cover every row.
        assert!(close(split.max_linear_precision_error, 0.6 / 3.0));
    }

    #[test]
    fn nothing_negative_reports_zero_and_no_location() {
        let weights = Weights {
            rows: 1,
            cols: 2,
            values: vec![0.5, 0.5],
        };
        let cage = [DVec3::ZERO, DVec3::X];
        let quality = WeightQuality::measure(&weights, &[DVec3::X * 0.5], &cage, &[]);
        assert_eq!(quality, WeightQuality::default());
        let empty = WeightQuality::measure(&Weights::zeros(0, 2), &[], &cage, &[]);
        assert_eq!(empty, WeightQuality::default());
    }

    #[test]
    fn linear_precision_reads_the_same_far_from_the_origin() {
        let cage = procedural::cube_cage(1.0);
        let points = procedural::points_inside(&cage, 300, 7, 1e-3);
        let weights = mvc_matrix(&cage, &points);
        let near = WeightQuality::measure(&weights, &points, cage.positions(), &[]);
        // The same f32 rows, the scene moved a million units away.
        let shift = DVec3::splat(1e6);
        let moved = |p: &[DVec3]| p.iter().map(|&p| p + shift).collect::<Vec<_>>();
        let far = WeightQuality::measure(&weights, &moved(&points), &moved(cage.positions()), &[]);
        assert!(near.max_linear_precision_error < 1e-6, "{near:?}");
        let change = (far.max_linear_precision_error - near.max_linear_precision_error).abs();
        assert!(change < 1e-9, "{near:?} against {far:?}");
    }

    #[test]
    fn mvc_inside_a_convex_cage_is_nonnegative_and_precise() {
        let cage = procedural::cube_cage(1.0);
        let points = procedural::points_inside(&cage, 300, 7, 1e-3);
        let quality =
            WeightQuality::measure(&mvc_matrix(&cage, &points), &points, cage.positions(), &[]);
        assert_eq!(quality.negative_vertices, 0, "{quality:?}");
        assert_eq!(quality.negative_share, 0.0);
        assert!(quality.max_partition_error < 1e-5, "{quality:?}");
        assert!(quality.max_linear_precision_error < 1e-5, "{quality:?}");
    }

    #[test]
    fn mvc_inside_a_comb_has_negative_rows() {
        let cage = procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5);
        let points = procedural::points_inside(&cage, 300, 5, 1e-3);
        let quality =
            WeightQuality::measure(&mvc_matrix(&cage, &points), &points, cage.positions(), &[]);
        assert!(quality.negative_share > 0.0, "{quality:?}");
        assert!(quality.most_negative < -NEGATIVE_TOLERANCE);
        let (row, col) = quality.most_negative_at.unwrap();
        let matrix = mvc_matrix(&cage, &points);
        assert_eq!(f64::from(matrix.row(row)[col]), quality.most_negative);
        // Still a partition of unity with linear precision: only positivity is lost.
        assert!(quality.max_partition_error < 1e-4, "{quality:?}");
        assert!(quality.max_linear_precision_error < 1e-4, "{quality:?}");
    }

    #[test]
    fn top_weights_orders_by_value_then_index() {
        let row = [0.1, 0.3, -0.2, 0.3, 0.0, -0.0, 0.5];
        assert_eq!(top_weights(&row, 3), vec![(6, 0.5), (1, 0.3), (3, 0.3)]);
        assert_eq!(top_weights(&row, 2), vec![(6, 0.5), (1, 0.3)]);
        assert_eq!(
            top_weights(&row, 6),
            vec![(6, 0.5), (1, 0.3), (3, 0.3), (0, 0.1), (4, 0.0), (5, -0.0)]
        );
        assert_eq!(top_weights(&row, 100).len(), row.len());
        assert!(top_weights(&row, 0).is_empty());
        assert!(top_weights(&[], 3).is_empty());
    }

    #[test]
    fn most_negative_finds_the_first_smallest_below_zero() {
        assert_eq!(
            most_negative(&[0.2, -0.1, -0.4, 0.9, -0.4]),
            Some((2, -0.4))
        );
        assert_eq!(most_negative(&[0.5, 0.0, -0.0, 0.5]), None);
        assert_eq!(most_negative(&[]), None);
    }
}
