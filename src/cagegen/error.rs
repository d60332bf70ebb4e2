//! Why no cage was generated, with the sizes and the values that would fit.

use super::plan::MAX_GRID_CELLS;
use super::plan::MAX_SURFACE_SAMPLES;
use super::{MAX_TARGET_VERTICES, MIN_TARGET_VERTICES};
use crate::budget::human_bytes;
use crate::budget::TooLarge;
use crate::geometry::CageError;

/// Why no cage was generated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AutoCageError {
    #[error("the mesh has no triangles: a cage is built around a surface")]
    NoTriangles,
    #[error("the mesh is flat (all its points lie in one plane or on one line): it has no inside to enclose")]
    Flat,
    #[error("a cage needs at least {MIN_TARGET_VERTICES} vertices; {requested} were asked for")]
    TooFewVertices { requested: usize },
    #[error("{requested} cage vertices is more than the {MAX_TARGET_VERTICES} a cage may have (a cage is coarse; the mesh itself has {mesh_vertices})")]
    TooManyVertices {
        requested: usize,
        mesh_vertices: usize,
    },
    #[error("the clearance must be a positive fraction of the mesh's size below 0.5, not {value}")]
    BadClearance { value: f64 },
    #[error(
        "the voxel size must be a positive fraction of the mesh's size below 0.25, not {value}"
    )]
    BadCellSize { value: f64 },
    #[error("cancelled")]
    Cancelled,
    #[error("the generated cage failed its own check ({0}); please report this with the mesh")]
    Invalid(CageError),
    #[error("the generated cage leaves {outside} mesh vertices outside (first: vertex {}); please report this with the mesh", .first + 1)]
    NotEnclosing { outside: usize, first: usize },
    #[error(
        "a clearance of {clearance} of the diagonal needs {} surface samples ({}), more than the {} besides the mesh's vertices that a cage is built with; {}",
        count_text(*.points), human_bytes(*.bytes), MAX_SURFACE_SAMPLES,
        suggestion("clearance", *.suggested, MAX_CLEARANCE)
    )]
    TooManySamples {
        clearance: f64,
        points: u64,
        bytes: u64,
        /// The smallest clearance that fits (a fraction of the diagonal).
        suggested: f64,
    },
    #[error(
        "the voxel grid ({} × {} × {} cells) would need {}, more than the {} cells a cage is built in; {}",
        .dims[0], .dims[1], .dims[2], human_bytes(*.bytes), MAX_GRID_CELLS,
        suggestion("voxel size", *.suggested, MAX_CELL_SIZE)
    )]
    GridTooLarge {
        dims: [usize; 3],
        bytes: u64,
        /// A voxel size that fits (a fraction of the diagonal).
        suggested: f64,
    },
    #[error("{limit}; {advice}")]
    NotEnoughMemory { limit: TooLarge, advice: String },
}

/// Clearances and voxel sizes (fractions of the diagonal) must be below these.
pub(super) const MAX_CLEARANCE: f64 = 0.5;
pub(super) const MAX_CELL_SIZE: f64 = 0.25;

/// The advice after a refusal: the value that fits, or that none the generator
/// accepts does.
fn suggestion(what: &str, suggested: f64, below: f64) -> String {
    if suggested < below {
        format!("a {what} of {suggested} of the diagonal or more would fit")
    } else {
        format!("no {what} the generator accepts (below {below} of the diagonal) would fit; simplify the mesh first")
    }
}

/// A count that may have saturated: past a trillion, only its order.
fn count_text(count: u64) -> String {
    match count {
        u64::MAX => format!("over {:.1e}", u64::MAX as f64),
        n if n >= 1_000_000_000_000 => format!("{:.1e}", n as f64),
        n => n.to_string(),
    }
}
