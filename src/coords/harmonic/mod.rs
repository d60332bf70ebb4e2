//! Harmonic coordinates (Joshi, Meyer, DeRose, Green, Sanocki 2007), the paper's
//! third method. For every cage vertex i, hᵢ is harmonic inside the cage and equals
//! on the cage the piecewise-linear hat function of vertex i on triangles and its
//! bilinear basis function on quads, which are bilinear patches (see [`patches`]);
//! the weights are the hᵢ at the mesh vertices.
//!
//! Discretisation ([`grid`]): a regular grid over the cage's bounding box with
//! `grid` cells along its longest side, and the symmetric cut-cell stencil at the
//! exact places where grid lines cross the cage. It keeps the discrete maximum
//! principle (weights ≥ 0, summing to 1) and reproduces linear functions.
//! Solver ([`solve`]): conjugate gradients preconditioned by a multigrid V-cycle,
//! for blocks of cage vertices at once, in f32 with f64 dot products. Mesh
//! vertices take the trilinear interpolation of their cell's corners; a corner
//! outside the cage takes the boundary data at its closest point on the cage, so
//! every inside vertex gets non-negative weights summing to one.
//!
//! Vertices on the cage get the barycentrics of their triangle and vertices outside
//! get MVC, as for the other families (see [`super`]).

pub(super) mod grid;
mod patches;
pub(super) mod sample;
mod solve;

use super::{BindProgress, Cancelled, Weights};
use crate::geometry::{Cage, PointClass};
use glam::DVec3;
use grid::{inside_nodes, Frame, Level};
use rayon::prelude::*;
use solve::Multigrid;

/// Grid cells along the cage's longest side when none is asked for.
pub const DEFAULT_GRID: u32 = 64;
/// Fewer cells than this cannot resolve a cage.
pub const MIN_GRID: u32 = 4;
/// Relative residual every column is solved to.
const TOLERANCE: f64 = 2e-7;
const MAX_ITERATIONS: usize = 200;
/// Iterations a block usually takes, for progress.
const EXPECTED_ITERATIONS: usize = 12;
/// Cage vertices solved together: bounds memory while one sweep serves many.
const COLUMNS_PER_BLOCK: usize = 32;
/// Share of the available memory a bind may plan to use.
pub(super) const MEMORY_SHARE: f64 = 0.8;

/// Why a bind on the harmonic solve's grid (harmonic coordinates, and the
/// families that share the grid: [`super::bbw`]) could not be done.
#[derive(Debug, thiserror::Error)]
pub enum HarmonicError {
    #[error("the grid needs at least {MIN_GRID} cells along the cage's longest side, not {grid}")]
    GridTooSmall { grid: u32 },
    #[error("a grid of {grid} cells has {nodes} nodes, more than this tool supports; use a smaller --grid")]
    GridTooLarge { grid: u32, nodes: u128 },
    #[error(
        "a {family} bind at grid {grid} needs about {needed_mib} MiB, but only {available_mib} MiB of memory is available; use a smaller --grid (grid {suggested} needs about {suggested_mib} MiB)"
    )]
    NotEnoughMemory {
        /// The family's display name ("HC", "BBW").
        family: &'static str,
        grid: u32,
        needed_mib: u64,
        available_mib: u64,
        suggested: u32,
        suggested_mib: u64,
    },
    /// The sparse factorisation of a grid family's system failed (out of
    /// memory while factorising, or a matrix that is not positive definite).
    #[error("the {family} solve at grid {grid} failed: {reason}")]
    Solver {
        family: &'static str,
        grid: u32,
        reason: String,
    },
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
}

/// What a harmonic bind at a grid size would use, found before any solving.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HarmonicPlan {
    pub grid: u32,
    /// Grid nodes along x, y and z.
    pub dims: [usize; 3],
    /// Cell size, in the cage's units.
    pub cell: f64,
    /// Nodes inside the cage: the unknowns of the finest level.
    pub inside_nodes: usize,
    /// Multigrid levels.
    pub levels: usize,
    /// Peak memory the bind is expected to use, output included.
    pub predicted_bytes: u64,
}

/// How the solve went.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveStats {
    pub inside_nodes: usize,
    pub levels: usize,
    /// Blocks of cage vertices solved one after another.
    pub blocks: usize,
    /// The most iterations any block took.
    pub max_iterations: usize,
    pub total_iterations: usize,
    /// The largest final relative residual of any column.
    pub relative_residual: f64,
}

/// The finest frame for `grid` and the number of multigrid levels.
pub(super) fn frame_for(cage: &Cage, grid: u32) -> Result<(Frame, usize), HarmonicError> {
    if grid < MIN_GRID {
        return Err(HarmonicError::GridTooSmall { grid });
    }
    let (lo, hi) = crate::geometry::bounds_of(cage.positions());
    let extent = hi - lo;
    let h = extent.max_element() / f64::from(grid);
    // A margin of about 0.7 cells keeps the cage off the outermost nodes, and
    // unequal fractions per axis keep grid lines off the cage's vertices and edges.
    let margin = DVec3::new(0.7137, 0.7291, 0.7413);
    // Counted in u64 per axis and u128 in all: a grid of u32::MAX cells has about
    // 2³² nodes per side, whose product overflows 64 bits.
    let cells = (extent / h + 2.0 * margin)
        .ceil()
        .to_array()
        .map(|c| c as u64);
    let smallest = *cells.iter().min().unwrap_or(&1);
    let mut coarsenings = 0;
    while coarsenings < 7 && smallest >> (coarsenings + 1) >= 2 {
        coarsenings += 1;
    }
    let step = 1u64 << coarsenings;
    let dims = cells.map(|c| c.div_ceil(step) * step + 1);
    let nodes = dims.iter().map(|&n| u128::from(n)).product::<u128>();
    if nodes >= u128::from(u32::MAX / 2) {
        return Err(HarmonicError::GridTooLarge { grid, nodes });
    }
    let dims = dims.map(|n| n as usize);
    let frame = Frame {
        origin: lo - margin * h,
        h,
        dims,
    };
    Ok((frame, coarsenings + 1))
}

/// Bytes a bind is expected to need at its peak.
fn predicted_bytes(frame: &Frame, inside: usize, points: usize, columns: usize) -> u64 {
    let width = columns.min(COLUMNS_PER_BLOCK) as u64;
    let (inside, nodes) = (inside as u64, frame.node_count() as u64);
    // Levels add about a seventh; per grid node an index and crossings; per inside
    // node its stencil and transfers; per inside node and column the four CG
    // vectors and the V-cycle's three; and the output.
    let per_level = nodes * 6 + inside * (4 + 4 + 24 + 64 + 8) + inside * width * 4 * 7;
    per_level * 8 / 7 + (points as u64) * (columns as u64) * 4 + (64 << 20)
}

/// What a bind of `points` points at `grid` would use.
pub fn plan(cage: &Cage, grid: u32, points: usize) -> Result<HarmonicPlan, HarmonicError> {
    let (frame, levels) = frame_for(cage, grid)?;
    let (inside, _) = inside_nodes(cage, &frame);
    let inside_nodes = inside.iter().filter(|&&inside| inside).count();
    Ok(HarmonicPlan {
        grid,
        dims: frame.dims,
        cell: frame.h,
        inside_nodes,
        levels,
        predicted_bytes: predicted_bytes(&frame, inside_nodes, points, cage.vertex_count()),
    })
}

/// Refuse a plan that would not fit, naming a grid that would.
fn check_memory(cage: &Cage, plan: &HarmonicPlan, points: usize) -> Result<(), HarmonicError> {
    let Some(available) = crate::budget::available_memory() else {
        return Ok(());
    };
    let budget = (available as f64 * MEMORY_SHARE) as u64;
    if plan.predicted_bytes <= budget {
        return Ok(());
    }
    let mut suggested = plan.grid / 2;
    // Memory falls about eightfold per halving; halve until it fits.
    let mut suggested_bytes = plan.predicted_bytes / 8;
    while suggested >= MIN_GRID * 2 && suggested_bytes > budget {
        suggested /= 2;
        suggested_bytes /= 8;
    }
    if let Ok(smaller) = self::plan(cage, suggested.max(MIN_GRID), points) {
        suggested_bytes = smaller.predicted_bytes;
    }
    Err(HarmonicError::NotEnoughMemory {
        family: "HC",
        grid: plan.grid,
        needed_mib: plan.predicted_bytes >> 20,
        available_mib: available >> 20,
        suggested: suggested.max(MIN_GRID),
        suggested_mib: suggested_bytes >> 20,
    })
}

/// Refuse `needed` bytes for `family` at `grid` if they would not fit, naming
/// a grid that would: `predict` gives the bytes of a smaller grid (each
/// halving a quarter or less of the memory), tried until one fits.
pub(super) fn refuse_unless_it_fits(
    family: &'static str,
    grid: u32,
    needed: u64,
    predict: &dyn Fn(u32) -> Result<u64, HarmonicError>,
) -> Result<(), HarmonicError> {
    let Some(available) = crate::budget::available_memory() else {
        return Ok(());
    };
    let budget = (available as f64 * MEMORY_SHARE) as u64;
    if needed <= budget {
        return Ok(());
    }
    let mut suggested = grid / 2;
    let mut suggested_bytes = needed / 8;
    while suggested >= MIN_GRID {
        match predict(suggested) {
            Ok(bytes) if bytes <= budget => {
                suggested_bytes = bytes;
                break;
            }
            Ok(bytes) => suggested_bytes = bytes,
            Err(HarmonicError::NotEnoughMemory { needed_mib, .. }) => {
                suggested_bytes = needed_mib << 20
            }
            Err(other) => return Err(other),
        }
        suggested /= 2;
    }
    Err(HarmonicError::NotEnoughMemory {
        family,
        grid,
        needed_mib: needed >> 20,
        available_mib: available >> 20,
        suggested: suggested.max(MIN_GRID),
        suggested_mib: suggested_bytes >> 20,
    })
}

/// Harmonic coordinates of `points` (classified by
/// [`crate::geometry::classify_points`]) at `grid` cells along the cage's longest
/// side. `progress` counts rows: it is advanced in proportion to the solve.
pub fn bind_harmonic(
    points: &[DVec3],
    classes: &[PointClass],
    cage: &Cage,
    grid: u32,
    progress: &BindProgress,
) -> Result<(Weights, SolveStats), HarmonicError> {
    let plan = plan(cage, grid, points.len())?;
    check_memory(cage, &plan, points.len())?;
    let multigrid = multigrid(cage, grid)?;
    let columns = cage.vertex_count();
    let mut weights = Weights::zeros(points.len(), columns);
    let blocks = columns.div_ceil(COLUMNS_PER_BLOCK).max(1);
    let mut stats = SolveStats {
        inside_nodes: multigrid.levels[0].unknowns(),
        levels: multigrid.levels.len(),
        blocks,
        ..SolveStats::default()
    };
    let rows_progress =
        RowsProgress::new(progress, points.len(), blocks * (EXPECTED_ITERATIONS + 1));
    let sampler = sample::Sampler::new(cage, &multigrid.levels[0], points, classes);
    for block in 0..blocks {
        let first = block * COLUMNS_PER_BLOCK;
        let width = COLUMNS_PER_BLOCK.min(columns - first);
        if width == 0 {
            break;
        }
        let b = right_hand_sides(&multigrid.levels[0], first, width);
        let counter = BindProgress::default();
        let (x, block_stats) = std::thread::scope(|scope| {
            let solving = scope.spawn(|| {
                solve::solve_block(&multigrid, &b, width, TOLERANCE, MAX_ITERATIONS, &counter)
            });
            // Pass cancels through and report iterations as rows while it runs.
            while !solving.is_finished() {
                if progress.is_cancelled() {
                    counter.cancel();
                }
                rows_progress.reach(
                    block * (EXPECTED_ITERATIONS + 1) + counter.done().min(EXPECTED_ITERATIONS),
                );
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
            solving.join().unwrap_or(Err(Cancelled))
        })?;
        stats.max_iterations = stats.max_iterations.max(block_stats.iterations);
        stats.total_iterations += block_stats.iterations;
        stats.relative_residual = stats.relative_residual.max(block_stats.relative_residual);
        sampler.write_block(&x, first, width, &mut weights);
        rows_progress.reach((block + 1) * (EXPECTED_ITERATIONS + 1));
    }
    fill_boundary_and_outside(points, classes, cage, &mut weights);
    rows_progress.finish();
    Ok((weights, stats))
}

/// The levels of a solve at `grid`, finest first, and their transfers.
fn multigrid(cage: &Cage, grid: u32) -> Result<Multigrid, HarmonicError> {
    let (frame, level_count) = frame_for(cage, grid)?;
    let mut levels = vec![Level::new(cage, frame, true)];
    for _ in 1..level_count {
        let coarser = levels.last().map(|level| level.frame.coarser());
        match coarser {
            Some(frame) if frame.dims.iter().all(|&n| n >= 3) => {
                levels.push(Level::new(cage, frame, false))
            }
            _ => break,
        }
    }
    Ok(Multigrid::new(levels))
}

/// Right-hand sides of columns `first..first + width`: each cut arm's coefficient
/// times the boundary data at its crossing.
fn right_hand_sides(level: &Level, first: usize, width: usize) -> Vec<f32> {
    let mut b = vec![0.0f32; level.unknowns() * width];
    for arm in &level.cut_arms {
        for (&corner, &value) in arm.corners.iter().zip(&arm.values) {
            let column = corner as usize;
            // A triangle's fourth value is zero: adding it would change nothing.
            if value == 0.0 {
                continue;
            }
            if (first..first + width).contains(&column) {
                b[arm.unknown as usize * width + column - first] += arm.coefficient * value;
            }
        }
    }
    b
}

/// Rows of points on the cage (their triangle's barycentrics) and outside it (MVC):
/// the policy every family shares, from [`super::weights_at`].
pub(super) fn fill_boundary_and_outside(
    points: &[DVec3],
    classes: &[PointClass],
    cage: &Cage,
    weights: &mut Weights,
) {
    let columns = weights.cols.max(1);
    // MVC reads no cube map; PMVC's integration is only there for the signature.
    let integration = super::PmvcIntegration::Exact;
    weights
        .values
        .par_chunks_mut(columns)
        .zip(points.par_iter().zip(classes))
        .filter(|(_, (_, class))| !matches!(class, PointClass::Inside))
        .for_each_init(
            || (vec![0.0f64; columns], super::RowScratch::default()),
            |(row_f64, scratch), (row, (&x, &class))| {
                super::weights_at(
                    x,
                    class,
                    cage,
                    super::Method::Mvc,
                    &integration,
                    row_f64,
                    scratch,
                );
                for (out, &value) in row.iter_mut().zip(row_f64.iter()) {
                    *out = value as f32;
                }
            },
        );
}

/// Maps the solve's work units onto the caller's rows, never going back.
pub(super) struct RowsProgress<'a> {
    progress: &'a BindProgress,
    rows: usize,
    units: usize,
    reported: std::sync::atomic::AtomicUsize,
}

impl<'a> RowsProgress<'a> {
    pub(super) fn new(progress: &'a BindProgress, rows: usize, units: usize) -> Self {
        Self {
            progress,
            rows,
            units: units.max(1),
            reported: Default::default(),
        }
    }

    /// `done` of the units are done.
    pub(super) fn reach(&self, done: usize) {
        let rows = (done.min(self.units) * self.rows) / self.units;
        let before = self
            .reported
            .fetch_max(rows, std::sync::atomic::Ordering::Relaxed);
        if rows > before {
            self.progress.advance(rows - before);
        }
    }

    pub(super) fn finish(&self) {
        self.reach(self.units);
    }
}

#[cfg(test)]
mod quad_tests;
