//! Local barycentric coordinates (Zhang, Deng, Hormann and Zheng 2014) for a
//! cage, on the harmonic solve's grid with no tetrahedral mesh: the weights of
//! all cage vertices together minimise their total variation `Σₖ ∫|∇wₖ|`
//! inside the cage, subject at every point to `wₖ ≥ 0`, `Σ wₖ = 1` and
//! `Σ wₖ vₖ = x`, with the cage's boundary data (hat functions on triangles,
//! the bilinear basis on quads) as the values the weights take on the cage.
//! Total variation favours weights that are constant over regions and change
//! across thin bands, which is what makes them local: a point far from a cage
//! vertex gets exactly zero from it.
//!
//! Discretisation ([`operator`]): the grid, inside nodes and cut crossings of
//! [`super::harmonic`]; each node owns the cell ahead of it, and each cut arm
//! charges the jump from the node to the boundary data at the crossing.
//! Solver ([`admm`]): ADMM with the total variation and the per-node
//! barycentric constraints split apart; every iterate it returns is exactly
//! non-negative and barycentric at every node ([`project`]). Mesh vertices are
//! sampled from the nodes as harmonic coordinates are
//! ([`super::harmonic::sample`]): trilinear interpolation keeps linear
//! precision inside cells whose corners are all inside the cage; in a cell
//! the cage cuts, outside corners take the boundary data of their closest cage
//! point, as for the other grid families. Vertices on the cage get their
//! triangle's barycentrics and vertices outside get MVC.

mod admm;
mod operator;
mod project;

pub use admm::{LbcSettings, LbcStats};

use super::harmonic::grid::{inside_nodes, Level};
use super::harmonic::{self, fill_boundary_and_outside, HarmonicError, RowsProgress};
use super::{BindProgress, Cancelled, Weights};
use crate::geometry::{Cage, PointClass};
use glam::DVec3;
use operator::Differences;

/// Grid cells along the cage's longest side when none is asked for.
pub const DEFAULT_GRID: u32 = 32;
/// The family's name in messages.
const FAMILY: &str = "LBC";

/// What a bind at a grid size would use, found before the solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LbcPlan {
    pub grid: u32,
    /// Grid nodes along x, y and z.
    pub dims: [usize; 3],
    /// Cell size, in the cage's units.
    pub cell: f64,
    /// Nodes inside the cage.
    pub inside_nodes: usize,
    /// Rows of the energy: cells' differences and cut arms.
    pub rows: usize,
    /// Peak memory the bind is expected to use, output included.
    pub predicted_bytes: u64,
}

/// The weights at the grid's inside nodes: what mesh vertices are sampled from.
#[derive(Clone, Debug)]
pub struct NodeWeights {
    pub positions: Vec<DVec3>,
    pub cell: f64,
    /// One row per node, one column per cage vertex.
    pub values: Vec<f64>,
}

/// Bytes per inside node of the grid level and the difference operator, with
/// room for six cut arms: a bound checked before they are built.
const BYTES_PER_NODE_BEFORE_SOLVE: u64 = 4 + 4 + 24 + 24 + 4 + 6 * (64 + 52);

struct Prepared {
    level: Level,
    differences: Differences,
    plan: LbcPlan,
}

fn prepare(cage: &Cage, grid: u32, points: usize) -> Result<Prepared, HarmonicError> {
    let (frame, _) = harmonic::frame_for(cage, grid)?;
    let columns = cage.vertex_count() as u64;
    let output = points as u64 * columns * 4 + (64 << 20);
    // Classifying the nodes alone takes this much: refuse before it.
    check_memory(cage, grid, points, frame.node_count() as u64 * 8 + output)?;
    let (inside, _) = inside_nodes(cage, &frame);
    let inside = inside.iter().filter(|&&inside| inside).count() as u64;
    let before_solve =
        frame.node_count() as u64 * 8 + inside * BYTES_PER_NODE_BEFORE_SOLVE + output;
    check_memory(cage, grid, points, before_solve)?;
    let level = Level::new(cage, frame, true);
    let differences = Differences::new(&level);
    let (n, rows) = (level.unknowns() as u64, differences.rows() as u64);
    let threads = rayon::current_num_threads() as u64;
    // The ADMM's arrays: B, Z, U per row and handle; W, Y, V, the next and
    // the previous Y per node and handle; per thread the conjugate gradients'
    // vectors; the node values handed to the sampler.
    let solve = 8 * columns * (3 * rows + 5 * n) + 32 * n + threads * 8 * (3 * rows + 6 * n);
    let predicted_bytes = frame.node_count() as u64 * 8
        + n * BYTES_PER_NODE_BEFORE_SOLVE
        + solve
        + n * columns * 4
        + output;
    let plan = LbcPlan {
        grid,
        dims: frame.dims,
        cell: frame.h,
        inside_nodes: level.unknowns(),
        rows: differences.rows(),
        predicted_bytes,
    };
    Ok(Prepared {
        level,
        differences,
        plan,
    })
}

/// Refuse `needed` bytes at `grid` if they would not fit, naming a grid that
/// would.
fn check_memory(cage: &Cage, grid: u32, points: usize, needed: u64) -> Result<(), HarmonicError> {
    harmonic::refuse_unless_it_fits(FAMILY, grid, needed, &|smaller| {
        Ok(prepare(cage, smaller, points)?.plan.predicted_bytes)
    })
}

/// What a bind of `points` points at `grid` would use.
pub fn plan(cage: &Cage, grid: u32, points: usize) -> Result<LbcPlan, HarmonicError> {
    Ok(prepare(cage, grid, points)?.plan)
}

/// Solve on a prepared grid: node-major values and the stats.
fn solve(
    cage: &Cage,
    prepared: &Prepared,
    settings: &LbcSettings,
    progress: &BindProgress,
    report: &(dyn Fn(f64) + Sync),
) -> Result<(Vec<f64>, Vec<DVec3>, LbcStats), HarmonicError> {
    let level = &prepared.level;
    let frame = &level.frame;
    let positions: Vec<DVec3> = level
        .nodes
        .iter()
        .map(|&node| frame.position(frame.coordinates(node as usize)))
        .collect();
    let (lo, hi) = crate::geometry::bounds_of(cage.positions());
    let problem = admm::Problem {
        differences: &prepared.differences,
        node_positions: &positions,
        cage_positions: cage.positions(),
        scale: (hi - lo).length().max(f64::MIN_POSITIVE),
    };
    let cancelled = || progress.is_cancelled();
    let (values, stats) = admm::solve(&problem, settings, &cancelled, report)?;
    Ok((values, positions, stats))
}

/// Local barycentric coordinates at the inside nodes of the grid at `grid`,
/// with the solver's `settings`.
pub fn node_weights(
    cage: &Cage,
    grid: u32,
    settings: &LbcSettings,
    progress: &BindProgress,
) -> Result<(NodeWeights, LbcStats), HarmonicError> {
    let prepared = prepare(cage, grid, 0)?;
    check_memory(cage, grid, 0, prepared.plan.predicted_bytes)?;
    let (values, positions, stats) = solve(cage, &prepared, settings, progress, &|_| ())?;
    Ok((
        NodeWeights {
            positions,
            cell: prepared.level.frame.h,
            values,
        },
        stats,
    ))
}

/// Local barycentric coordinates of `points` (classified by
/// [`crate::geometry::classify_points`]) at `grid` cells along the cage's
/// longest side. `progress` counts rows: it is advanced as the solve
/// converges.
pub fn bind_lbc(
    points: &[DVec3],
    classes: &[PointClass],
    cage: &Cage,
    grid: u32,
    progress: &BindProgress,
) -> Result<(Weights, LbcStats), HarmonicError> {
    bind_lbc_with(
        points,
        classes,
        cage,
        grid,
        &LbcSettings::default(),
        progress,
    )
}

/// [`bind_lbc`] with the solver's settings.
pub fn bind_lbc_with(
    points: &[DVec3],
    classes: &[PointClass],
    cage: &Cage,
    grid: u32,
    settings: &LbcSettings,
    progress: &BindProgress,
) -> Result<(Weights, LbcStats), HarmonicError> {
    let prepared = prepare(cage, grid, points.len())?;
    check_memory(cage, grid, points.len(), prepared.plan.predicted_bytes)?;
    // Units: the set-up, then a thousand shares of the solve.
    const UNITS: usize = 1000;
    let rows_progress = RowsProgress::new(progress, points.len(), UNITS + 1);
    rows_progress.reach(1);
    let report =
        |share: f64| rows_progress.reach(1 + (share.clamp(0.0, 1.0) * UNITS as f64) as usize);
    let (values, _, stats) = solve(cage, &prepared, settings, progress, &report)?;
    if progress.is_cancelled() {
        return Err(Cancelled.into());
    }
    let columns = cage.vertex_count();
    let mut weights = Weights::zeros(points.len(), columns);
    let sampler = harmonic::sample::Sampler::new(cage, &prepared.level, points, classes);
    let values: Vec<f32> = values.iter().map(|&w| w as f32).collect();
    sampler.write_block(&values, 0, columns, &mut weights);
    fill_boundary_and_outside(points, classes, cage, &mut weights);
    rows_progress.finish();
    Ok((weights, stats))
}
