//! Barycentric coordinates of mesh vertices with respect to a cage: mean value
//! coordinates in closed form ([`mvc`]), the CPU reference for positive mean value
//! coordinates ([`pmvc`]), and the dense weights matrix they fill. Nothing here
//! touches the GPU or the UI.
//!
//! Policy for vertices that are not strictly inside the cage:
//! - on the surface (within [`crate::geometry::classify::SURFACE_TOLERANCE`] of the
//!   cage diagonal), both methods give the barycentric coordinates of the touching
//!   triangle, which is the limit of both MVC and PMVC there;
//! - outside, both methods use MVC. MVC is finite off the surface (its total weight
//!   is an alternating sum of decreasing `1/r` terms along every ray, so positive),
//!   reproduces the rest pose by linear precision, and meets PMVC continuously on
//!   the surface because both reduce to the triangle's barycentrics there.

pub mod cubemap;
pub mod mvc;
pub mod pmvc;
pub mod quality;

use crate::geometry::{Cage, PointClass};
use glam::DVec3;
pub use quality::WeightQuality;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Which coordinates to compute.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Mean value coordinates (Ju, Schaefer, Warren 2005), closed form.
    Mvc,
    /// Positive mean value coordinates (Lipman et al. 2007), by cube-map integration.
    Pmvc,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Mvc => "MVC",
            Method::Pmvc => "PMVC",
        }
    }
}

/// Default cube-map resolution (texels along one face edge).
pub const DEFAULT_RESOLUTION: u32 = 32;

/// What to bind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BindOptions {
    pub method: Method,
    /// Cube-map resolution for PMVC; ignored by MVC.
    pub resolution: u32,
}

impl Default for BindOptions {
    fn default() -> Self {
        Self {
            method: Method::Pmvc,
            resolution: DEFAULT_RESOLUTION,
        }
    }
}

/// Dense weights: one row per mesh vertex, one column per cage vertex, row-major f32.
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

    /// Smallest weight in the matrix; infinity for an empty one.
    pub fn min(&self) -> f32 {
        self.values.iter().copied().fold(f32::INFINITY, f32::min)
    }
}

/// Progress and cancellation shared between a running bind and its observers.
#[derive(Debug, Default)]
pub struct BindProgress {
    done: AtomicUsize,
    cancel: AtomicBool,
}

impl BindProgress {
    /// Mesh vertices finished so far; never decreases.
    pub fn done(&self) -> usize {
        self.done.load(Ordering::Relaxed)
    }

    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    pub fn advance(&self, vertices: usize) {
        self.done.fetch_add(vertices, Ordering::Relaxed);
    }
}

/// The bind was cancelled; no weights were produced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("binding was cancelled")]
pub struct Cancelled;

/// Rows bound per parallel task: small enough to balance and to notice a cancel
/// quickly, large enough to amortise the scratch set-up.
const ROWS_PER_TASK: usize = 32;

/// Bind `points` to `cage` on the CPU, in parallel over points.
///
/// `classes` comes from [`crate::geometry::classify_points`] for the same points and
/// cage; it decides the inside/outside/surface policy described in the module doc.
pub fn bind_cpu(
    points: &[DVec3],
    classes: &[PointClass],
    cage: &Cage,
    options: BindOptions,
    progress: &BindProgress,
) -> Result<Weights, Cancelled> {
    assert_eq!(points.len(), classes.len(), "one class per point");
    let cols = cage.vertex_count();
    let mut weights = Weights::zeros(points.len(), cols);
    if cols == 0 || points.is_empty() {
        return Ok(weights);
    }
    let table = cubemap::TexelTable::new(options.resolution.max(1));
    weights
        .values
        .par_chunks_mut(cols * ROWS_PER_TASK)
        .enumerate()
        .try_for_each_init(
            || {
                (
                    vec![0.0f64; cols],
                    mvc::MvcScratch::default(),
                    pmvc::PmvcScratch::default(),
                )
            },
            |(row_f64, mvc_scratch, pmvc_scratch), (chunk, rows)| {
                if progress.is_cancelled() {
                    return Err(Cancelled);
                }
                let first = chunk * ROWS_PER_TASK;
                for (offset, row) in rows.chunks_mut(cols).enumerate() {
                    let i = first + offset;
                    weights_at(
                        points[i],
                        classes[i],
                        cage,
                        options.method,
                        &table,
                        row_f64,
                        mvc_scratch,
                        pmvc_scratch,
                    );
                    for (out, &value) in row.iter_mut().zip(row_f64.iter()) {
                        *out = value as f32;
                    }
                }
                progress.advance(rows.len() / cols);
                Ok(())
            },
        )?;
    Ok(weights)
}

/// Coordinates of one point, following the policy of the module doc.
#[allow(clippy::too_many_arguments)]
pub fn weights_at(
    x: DVec3,
    class: PointClass,
    cage: &Cage,
    method: Method,
    table: &cubemap::TexelTable,
    out: &mut [f64],
    mvc_scratch: &mut mvc::MvcScratch,
    pmvc_scratch: &mut pmvc::PmvcScratch,
) {
    match class {
        PointClass::OnSurface {
            triangle,
            barycentric,
        } => {
            out.fill(0.0);
            let corners = cage.triangles[triangle as usize];
            for (k, &corner) in corners.iter().enumerate() {
                out[corner as usize] += barycentric[k];
            }
        }
        PointClass::Outside => mvc::mvc_weights(x, cage, out, mvc_scratch),
        PointClass::Inside => match method {
            Method::Mvc => mvc::mvc_weights(x, cage, out, mvc_scratch),
            Method::Pmvc => {
                if !pmvc::pmvc_weights_inside(x, cage, table, out, pmvc_scratch) {
                    // A ray escaped: x is not enclosed after all (numerically on the
                    // surface or in a cage defect). Follow the outside policy.
                    mvc::mvc_weights(x, cage, out, mvc_scratch);
                }
            }
        },
    }
}
