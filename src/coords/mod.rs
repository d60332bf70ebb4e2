//! Barycentric coordinates of mesh vertices with respect to a cage: mean value
//! coordinates in closed form ([`mvc`]), the CPU reference for positive mean value
//! coordinates ([`pmvc`]), harmonic coordinates ([`harmonic`]), maximum entropy
//! coordinates ([`mec`]), maximum likelihood coordinates ([`mlc`]), bounded
//! biharmonic weights ([`bbw`]), local barycentric coordinates ([`lbc`]), and the
//! dense weights matrix they fill. Nothing here touches the GPU or the UI.
//!
//! Policy for vertices that are not strictly inside the cage:
//! - on the surface (within [`crate::geometry::classify::SURFACE_TOLERANCE`] of the
//!   cage diagonal), every family gives the barycentric coordinates of the
//!   touching triangle, which is the limit of each of them there (MEC's only on
//!   well-shaped triangles: near slivers and quads it tends elsewhere; MLC's
//!   only on hull triangles whose plane holds no other vertex; see
//!   docs/coordinates.md);
//! - outside, every family uses MVC. MVC is finite off the surface (its total weight
//!   is an alternating sum of decreasing `1/r` terms along every ray, so positive),
//!   reproduces the rest pose by linear precision, and meets every family
//!   continuously on the surface because all reduce to the triangle's barycentrics
//!   there. Beyond [`mvc::FAR_FIELD_DIAGONALS`] cage diagonals, where the closed
//!   form loses digits, MVC are extended affinely (see [`mvc`]), which keeps
//!   those properties exactly at every distance.
//!
//! Green coordinates are the exception: they have their own surface and exterior
//! policies ([`green`]), which keep the deformation continuous across the cage for
//! their extra triangle columns, so their rows ignore the point's class.

pub mod bbw;
mod bind_options;
mod column_moves;
pub mod cubemap;
pub mod dtype;
pub mod exact_pmvc;
pub mod family;
pub mod green;
pub mod harmonic;
pub mod lbc;
pub mod mec;
pub mod mlc;
pub mod mvc;
mod parameter;
pub mod parameter_values;
pub mod pmvc;
mod progress;
pub mod qmvc;
pub mod quality;
pub mod somigliana;
pub mod split_effect;
mod weights_id;

pub use crate::geometry::QuadSplit;
use crate::geometry::{Cage, PointClass};
pub use bind_options::BindOptions;
pub use column_moves::ColumnMoves;
pub use dtype::{Dtype, DtypeError, WeightValue, WeightsF64};
pub use family::{
    FamilySpec, Method, NamedValue, Parameter, ParameterError, ParameterSpec, QuadSupport,
    DEFAULT_RESOLUTION, EXACT_RESOLUTION,
};
use glam::DVec3;
pub use pmvc::PmvcIntegration;
pub use progress::{BindProgress, Cancelled};
pub use quality::WeightQuality;
use rayon::prelude::*;
pub use weights_id::{Twin, WeightsId};

/// How many of `total` points lie outside the cage, and the first few (0-based,
/// ascending `outside`): the warning of a bind with outside points, and the
/// error of a strict one (`--strict`, Python's `strict=True`).
pub fn outside_summary(outside: &[u32], total: usize) -> String {
    let first: Vec<String> = outside.iter().take(5).map(u32::to_string).collect();
    let more = if outside.len() > 5 { ", …" } else { "" };
    format!(
        "{} of {total} vertices ({:.2}%) lie outside the cage (first: {}{more})",
        outside.len(),
        100.0 * outside.len() as f64 / total.max(1) as f64,
        first.join(", ")
    )
}

/// Dense weights: one row per mesh vertex, one column per cage vertex (then, for
/// Green coordinates, per cage triangle), row-major f32.
#[derive(Clone, Debug, PartialEq)]
pub struct Weights {
    pub rows: usize,
    pub cols: usize,
    pub values: Vec<f32>,
}

impl Weights {
    pub fn zeros(rows: usize, cols: usize) -> Self {
        Self {
            rows,
            cols,
            values: vec![0.0; rows * cols],
        }
    }

    pub fn row(&self, row: usize) -> &[f32] {
        &self.values[row * self.cols..(row + 1) * self.cols]
    }

    /// Every mesh vertex moved to `Σ λᵢ · cageᵢ`, accumulated in f64.
    pub fn apply(&self, cage_positions: &[DVec3]) -> Vec<DVec3> {
        assert_eq!(
            cage_positions.len(),
            self.cols,
            "one cage position per weights column"
        );
        self.values
            .par_chunks(self.cols.max(1))
            .take(self.rows)
            .map(|row| {
                row.iter()
                    .zip(cage_positions)
                    .map(|(&w, &c)| f64::from(w) * c)
                    .sum()
            })
            .collect()
    }

    /// `rest` moved by `Σₖ wₖ dₖ` per row, with `moves` one displacement per
    /// column, accumulated in f64. The displacement form reproduces the rest pose
    /// exactly for any weights and keeps full precision far from the origin.
    pub fn apply_displacements(&self, rest: &[DVec3], moves: &[DVec3]) -> Vec<DVec3> {
        assert_eq!(
            moves.len(),
            self.cols,
            "one displacement per weights column"
        );
        assert_eq!(rest.len(), self.rows, "one rest position per weights row");
        dtype::displaced(&self.values, rest, moves)
    }

    /// `rest` moved by `moves` ([`ColumnMoves`]: linear or normalised), one per
    /// column, accumulated in f64.
    pub fn apply_moves(&self, rest: &[DVec3], moves: &ColumnMoves) -> Vec<DVec3> {
        assert_eq!(moves.len(), self.cols, "one move per weights column");
        assert_eq!(rest.len(), self.rows, "one rest position per weights row");
        moves.apply(&self.values, rest)
    }

    /// Smallest weight in the matrix; infinity for an empty one.
    pub fn min(&self) -> f32 {
        self.values.iter().copied().fold(f32::INFINITY, f32::min)
    }
}

/// Weights of either dtype: what a bind gives and a weights file holds.
#[derive(Clone, Debug, PartialEq)]
pub enum AnyWeights {
    F32(Weights),
    F64(WeightsF64),
}

impl AnyWeights {
    pub fn rows(&self) -> usize {
        match self {
            AnyWeights::F32(weights) => weights.rows,
            AnyWeights::F64(weights) => weights.rows,
        }
    }

    pub fn cols(&self) -> usize {
        match self {
            AnyWeights::F32(weights) => weights.cols,
            AnyWeights::F64(weights) => weights.cols,
        }
    }

    pub fn dtype(&self) -> Dtype {
        match self {
            AnyWeights::F32(_) => Dtype::Float32,
            AnyWeights::F64(_) => Dtype::Float64,
        }
    }

    /// [`Weights::apply_displacements`], whatever the dtype.
    pub fn apply_displacements(&self, rest: &[DVec3], moves: &[DVec3]) -> Vec<DVec3> {
        match self {
            AnyWeights::F32(weights) => weights.apply_displacements(rest, moves),
            AnyWeights::F64(weights) => weights.apply_displacements(rest, moves),
        }
    }

    /// [`Weights::apply_moves`], whatever the dtype.
    pub fn apply_moves(&self, rest: &[DVec3], moves: &ColumnMoves) -> Vec<DVec3> {
        match self {
            AnyWeights::F32(weights) => weights.apply_moves(rest, moves),
            AnyWeights::F64(weights) => weights.apply_moves(rest, moves),
        }
    }
}

/// Why a CPU bind produced no weights.
#[derive(Debug, thiserror::Error)]
pub enum BindFailure {
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
    #[error(transparent)]
    Harmonic(harmonic::HarmonicError),
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    #[error(transparent)]
    TooLarge(#[from] crate::budget::TooLarge),
    #[error(transparent)]
    Somigliana(#[from] somigliana::SomiglianaError),
}

impl From<harmonic::HarmonicError> for BindFailure {
    fn from(error: harmonic::HarmonicError) -> Self {
        match error {
            harmonic::HarmonicError::Cancelled(cancelled) => BindFailure::Cancelled(cancelled),
            other => BindFailure::Harmonic(other),
        }
    }
}

/// Rows bound per parallel task: small enough to balance and to notice a cancel
/// quickly, large enough to amortise the scratch set-up.
const ROWS_PER_TASK: usize = 32;

/// Bind `points` to `cage` on the CPU, in parallel.
///
/// `classes` comes from [`BindOptions::classify`] for the same points, cage and
/// options; it decides the inside/outside/surface policy described in the module doc.
/// Families with a closed form or per-point integral go row by row
/// ([`bind_rows`]); the grid families (harmonic coordinates, BBW: those whose
/// rows are not independent) solve over the whole cage first.
pub fn bind_cpu(
    points: &[DVec3],
    classes: &[PointClass],
    cage: &Cage,
    options: BindOptions,
    progress: &BindProgress,
) -> Result<Weights, BindFailure> {
    options.validate()?;
    check_somigliana(options, cage)?;
    let cage = &*options.cage_to_bind(cage);
    if !options.method.spec().rows_independent {
        return bind_on_grid(points, classes, cage, options, progress);
    }
    let (cols, values) = every_row(points, classes, cage, options, progress)?;
    Ok(Weights {
        rows: points.len(),
        cols,
        values,
    })
}

/// The one check of Somigliana coordinates' Poisson ratio
/// ([`somigliana::validate_poisson_ratio`]), before any row is computed.
fn check_somigliana(options: BindOptions, cage: &Cage) -> Result<(), BindFailure> {
    if options.method == Method::Somigliana {
        somigliana::SomiglianaCage::new(cage, options.poisson_ratio())?;
    }
    Ok(())
}

/// A whole-scene solve on the harmonic solve's grid.
fn bind_on_grid(
    points: &[DVec3],
    classes: &[PointClass],
    cage: &Cage,
    options: BindOptions,
    progress: &BindProgress,
) -> Result<Weights, BindFailure> {
    if !classes
        .iter()
        .any(|class| matches!(class, PointClass::Inside))
    {
        // Nothing is sampled from the grid: every row is the boundary's or
        // the outside policy's. The grid is still checked, as a solve would.
        harmonic::frame_for(cage, options.grid)?;
        let mut weights = Weights::zeros(points.len(), cage.vertex_count());
        harmonic::fill_boundary_and_outside(points, classes, cage, &mut weights);
        progress.advance(points.len());
        return Ok(weights);
    }
    Ok(match options.method {
        Method::Bbw => bbw::bind_bbw(points, classes, cage, options.grid, progress)?.0,
        Method::Lbc => lbc::bind_lbc(points, classes, cage, options.grid, progress)?.0,
        _ => harmonic::bind_harmonic(points, classes, cage, options.grid, progress)?.0,
    })
}

/// Every row of `points`, bound by [`bind_rows`] into values of type `T`, after
/// the memory they take is checked; with the number of columns.
fn every_row<T: WeightValue>(
    points: &[DVec3],
    classes: &[PointClass],
    cage: &Cage,
    options: BindOptions,
    progress: &BindProgress,
) -> Result<(usize, Vec<T>), BindFailure> {
    let columns = options.method.columns(&options.cage_to_bind(cage));
    let value_bytes = std::mem::size_of::<T>();
    crate::budget::check_memory(
        || {
            format!(
                "the weights ({} rows × {columns} columns × {value_bytes} bytes)",
                points.len()
            )
        },
        crate::budget::bytes_for(points.len() as u64, (value_bytes * columns) as u64),
    )?;
    let mut values = vec![T::from_f64(0.0); points.len() * columns];
    let rows: Vec<usize> = (0..points.len()).collect();
    bind_rows(points, classes, cage, options, &rows, &mut values, progress)?;
    Ok((columns, values))
}

/// [`bind_cpu`] into float64 weights: every row as computed, without the
/// rounding to float32. The grid families (harmonic coordinates, BBW), sampled
/// in float32 from their grid, come widened (front ends refuse
/// `Dtype::Float64` for them: [`Dtype::check_family`]).
pub fn bind_cpu_f64(
    points: &[DVec3],
    classes: &[PointClass],
    cage: &Cage,
    options: BindOptions,
    progress: &BindProgress,
) -> Result<WeightsF64, BindFailure> {
    options.validate()?;
    check_somigliana(options, cage)?;
    if !options.method.spec().rows_independent {
        let columns = options.columns(cage) as u64;
        crate::budget::check_memory(
            || {
                format!(
                    "the weights ({} rows × {columns} columns × 8 bytes)",
                    points.len()
                )
            },
            crate::budget::bytes_for(points.len() as u64, 8 * columns),
        )?;
        let weights = bind_cpu(points, classes, cage, options, progress)?;
        return Ok(WeightsF64 {
            rows: weights.rows,
            cols: weights.cols,
            values: weights.values.iter().map(|&w| f64::from(w)).collect(),
        });
    }
    let (cols, values) = every_row(points, classes, cage, options, progress)?;
    Ok(WeightsF64 {
        rows: points.len(),
        cols,
        values,
    })
}

/// The one row loop of every CPU bind: fill `out` (`rows.len()` × the method's
/// columns, row-major, float32 or float64) with the weights of `points[rows[k]]`,
/// computed in f64, in parallel, advancing `progress` and stopping early when it
/// is cancelled.
pub fn bind_rows<T: WeightValue>(
    points: &[DVec3],
    classes: &[PointClass],
    cage: &Cage,
    options: BindOptions,
    rows: &[usize],
    out: &mut [T],
    progress: &BindProgress,
) -> Result<(), Cancelled> {
    assert_eq!(points.len(), classes.len(), "one class per point");
    let cage = &*options.cage_to_bind(cage);
    let cols = options.method.columns(cage);
    assert_eq!(
        out.len(),
        rows.len() * cols,
        "one output row per row asked for"
    );
    if cols == 0 || rows.is_empty() {
        return Ok(());
    }
    let integration = PmvcIntegration::of(options);
    let green_cage = (options.method == Method::Green).then(|| green::QgcCage::new(cage));
    // Checked by `check_somigliana` before any bind; a ν it refuses gives NaN rows.
    let somigliana_cage = (options.method == Method::Somigliana)
        .then(|| somigliana::SomiglianaCage::new(cage, options.poisson_ratio()).ok());
    out.par_chunks_mut(cols * ROWS_PER_TASK)
        .zip(rows.par_chunks(ROWS_PER_TASK))
        .try_for_each_init(
            || (vec![0.0f64; cols], RowScratch::default()),
            |(row_f64, scratch), (block, block_rows)| {
                if progress.is_cancelled() {
                    return Err(Cancelled);
                }
                for (row, &i) in block.chunks_mut(cols).zip(block_rows) {
                    if let Some(green_cage) = &green_cage {
                        green_row(green_cage, points[i], row_f64);
                    } else if let Some(prepared) = &somigliana_cage {
                        somigliana_row(
                            prepared.as_ref(),
                            points[i],
                            classes[i],
                            cage,
                            row_f64,
                            scratch,
                        );
                    } else {
                        weights_at(
                            points[i],
                            classes[i],
                            cage,
                            options.method,
                            &integration,
                            row_f64,
                            scratch,
                        );
                    }
                    for (out, &value) in row.iter_mut().zip(row_f64.iter()) {
                        *out = T::from_f64(value);
                    }
                }
                progress.advance(block_rows.len());
                Ok(())
            },
        )
}

/// Green coordinates (QGC on quads) of `x` into one row (φ, then ψ); NaN for a
/// point they cannot take (not finite), which the bind's validation rejects
/// beforehand.
fn green_row(green_cage: &green::QgcCage, x: DVec3, out: &mut [f64]) {
    let (phi, psi) = out.split_at_mut(green_cage.vertex_count());
    if green_cage.coordinates(x, phi, psi).is_err() {
        out.fill(f64::NAN);
    }
}

/// Somigliana coordinates of `x` into one row: its blocks inside; on the cage
/// or outside (or where Σ Bᵥ is not I), the row of the other families' policy as
/// identity blocks ([`somigliana::identity_blocks`]).
fn somigliana_row(
    prepared: Option<&somigliana::SomiglianaCage>,
    x: DVec3,
    class: PointClass,
    cage: &Cage,
    out: &mut [f64],
    scratch: &mut RowScratch,
) {
    let Some(prepared) = prepared else {
        return out.fill(f64::NAN);
    };
    if class == PointClass::Inside && prepared.row(x, out) {
        return;
    }
    let mut lambda = std::mem::take(&mut scratch.lambda);
    lambda.resize(cage.vertex_count(), 0.0);
    let integration = PmvcIntegration::of(BindOptions::for_method(Method::Mvc));
    let class = match class {
        PointClass::Inside => PointClass::Outside,
        other => other,
    };
    weights_at(
        x,
        class,
        cage,
        Method::Mvc,
        &integration,
        &mut lambda,
        scratch,
    );
    somigliana::identity_blocks(&lambda, out);
    scratch.lambda = lambda;
}

/// Per-thread buffers of the families computed row by row, reused across rows.
#[derive(Debug, Default)]
pub struct RowScratch {
    pub mvc: mvc::MvcScratch,
    pub pmvc: pmvc::PmvcScratch,
    pub mec: mec::MecScratch,
    pub mlc: mlc::MlcScratch,
    /// Scalar weights turned into Somigliana blocks.
    pub lambda: Vec<f64>,
}

/// Coordinates of one point, following the policy of the module doc. `out` holds
/// the method's columns ([`Method::columns`]).
pub fn weights_at(
    x: DVec3,
    class: PointClass,
    cage: &Cage,
    method: Method,
    integration: &PmvcIntegration,
    out: &mut [f64],
    scratch: &mut RowScratch,
) {
    let RowScratch {
        mvc: mvc_scratch,
        pmvc: pmvc_scratch,
        mec: mec_scratch,
        mlc: mlc_scratch,
        ..
    } = scratch;
    if method == Method::Somigliana {
        // As Green: prepared per call here, once per bind in `bind_rows`.
        let prepared = somigliana::SomiglianaCage::new(cage, somigliana::DEFAULT_POISSON_RATIO);
        return somigliana_row(prepared.ok().as_ref(), x, class, cage, out, scratch);
    }
    if method == Method::Green {
        // Its own policies for every class; prepared per call here, once per bind
        // in `bind_rows`.
        green_row(&green::QgcCage::new(cage), x, out);
        return;
    }
    match class {
        PointClass::OnSurface {
            triangle,
            barycentric,
        } => {
            out.fill(0.0);
            if let Some(quad) = cage.quad_of_triangle(triangle as usize) {
                // On a patch: its bilinear basis, the limit of every family there.
                let uv = crate::geometry::quads::patch_uv_from_triangle(
                    cage,
                    quad,
                    triangle as usize,
                    barycentric,
                    x,
                );
                let basis = crate::geometry::quads::bilinear_basis(uv[0], uv[1]);
                for (&corner, value) in cage.quads()[quad].corners.iter().zip(basis) {
                    out[corner as usize] += value;
                }
                return;
            }
            let corners = cage.triangles()[triangle as usize];
            for (k, &corner) in corners.iter().enumerate() {
                out[corner as usize] += barycentric[k];
            }
        }
        PointClass::Outside => mvc::mvc_weights(x, cage, out, mvc_scratch),
        PointClass::Inside => match method {
            // Grid families have no per-point form; bind_cpu solves them
            // whole. Asked for one row, MVC is the outside policy's answer.
            Method::Mvc
            | Method::Harmonic
            | Method::Bbw
            | Method::Lbc
            | Method::Green
            | Method::Somigliana => mvc::mvc_weights(x, cage, out, mvc_scratch),
            Method::Pmvc => {
                if !integration.weights_inside(x, cage, out, pmvc_scratch) {
                    // A ray escaped: x is not enclosed after all (numerically on the
                    // surface or in a cage defect). Follow the outside policy.
                    mvc::mvc_weights(x, cage, out, mvc_scratch);
                }
            }
            Method::Mec => {
                if mec::mec_weights_inside(x, cage, out, mec_scratch).is_err() {
                    // Only a point not strictly inside the hull has no solution
                    // (numerically on the surface): the outside policy, as PMVC.
                    mvc::mvc_weights(x, cage, out, mvc_scratch);
                }
            }
            Method::Mlc => {
                if mlc::mlc_weights_inside(x, cage, out, mlc_scratch).is_err() {
                    // As MEC: only a point numerically on the surface (or on a
                    // vertex) has no solution; the outside policy answers.
                    mvc::mvc_weights(x, cage, out, mvc_scratch);
                }
            }
        },
    }
}
