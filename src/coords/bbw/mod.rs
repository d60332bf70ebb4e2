//! Bounded biharmonic weights (Jacobson, Baran, Popović, Sorkine 2011) for a
//! cage, on the harmonic solve's grid with no tetrahedral mesh. For every cage
//! vertex (a handle) i, wᵢ minimises the squared Laplacian energy ½∫(Δwᵢ)²
//! inside the cage subject to 0 ≤ wᵢ ≤ 1 and to the boundary data of harmonic
//! coordinates on the cage (hat functions on triangles, the bilinear basis on
//! quads); the handles are solved separately and each node's weights are then
//! divided by their sum, as the paper does (its partition of unity is not a
//! constraint of the solve: [`BbwStats::sum_deviation`] says how far the sums
//! were from one).
//!
//! Discretisation ([`operator`]): the grid, inside nodes and cut crossings of
//! [`super::harmonic`], with a consistent cut-cell Laplacian and a lumped mass.
//! Solver ([`admm`]): ADMM on the box constraints with one sparse Cholesky
//! factorisation shared by every handle and iteration; its size is predicted
//! from the symbolic analysis before any value is computed ([`plan`]). Mesh
//! vertices are sampled from the nodes as harmonic coordinates are
//! ([`super::harmonic::sample`]); vertices on the cage get their triangle's
//! barycentrics and vertices outside get MVC, as for the other families.

mod admm;
mod operator;

pub use admm::{AdmmSettings, BlockStats};

use super::harmonic::grid::{inside_nodes, Level};
use super::harmonic::{self, fill_boundary_and_outside, HarmonicError, RowsProgress};
use super::{BindProgress, Cancelled, Weights};
use crate::geometry::{Cage, PointClass};
use glam::DVec3;
use operator::Operator;
use rayon::prelude::*;

/// Grid cells along the cage's longest side when none is asked for. Smaller
/// than harmonic coordinates' because the factor of a biharmonic system grows
/// about as the grid's fourth power.
pub const DEFAULT_GRID: u32 = 32;
/// Handles solved together: one triangular solve serves them all.
const HANDLES_PER_BLOCK: usize = 8;
/// The family's name in messages.
const FAMILY: &str = "BBW";

/// What a bind at a grid size would use, found before any value is computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BbwPlan {
    pub grid: u32,
    /// Grid nodes along x, y and z.
    pub dims: [usize; 3],
    /// Cell size, in the cage's units.
    pub cell: f64,
    /// Nodes inside the cage: the unknowns of every handle.
    pub inside_nodes: usize,
    /// Entries of the Cholesky factor of the energy's Hessian.
    pub factor_entries: usize,
    /// Peak memory the bind is expected to use, output included.
    pub predicted_bytes: u64,
}

/// How the solve went.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BbwStats {
    pub inside_nodes: usize,
    pub factor_entries: usize,
    /// The most ADMM iterations a block of handles took, and all of them.
    pub max_iterations: usize,
    pub total_iterations: usize,
    /// Handles that stopped at the iteration cap before the tolerance.
    pub unconverged: usize,
    /// The largest primal (‖w − z‖∞) and dual residuals at the end.
    pub primal_residual: f64,
    pub dual_residual: f64,
    /// The largest |Σᵢ wᵢ − 1| at a node before the sums were divided out.
    pub sum_deviation: f64,
}

/// The weights at the grid's inside nodes: what the mesh vertices are sampled
/// from.
#[derive(Clone, Debug)]
pub struct NodeWeights {
    pub positions: Vec<DVec3>,
    pub cell: f64,
    /// One row per node, one column per cage vertex, after normalisation.
    pub values: Vec<f64>,
    /// The same before normalisation: each handle's own minimiser.
    pub raw: Vec<f64>,
}

/// The grid, its operator and the analysed Hessian of one bind.
struct Prepared {
    level: Level,
    system: System,
    plan: BbwPlan,
}

/// What the solve consumes.
struct System {
    operator: Operator,
    matrix: faer::sparse::SparseColMat<usize, f64>,
    analysis: admm::Analysis,
    plan: BbwPlan,
}

/// Bytes per inside node of the grid level, the operator and the Hessian's
/// assembly, before the factor: a bound checked before they are built.
const BYTES_PER_NODE_BEFORE_FACTOR: u64 = 80 + 130 + 29 * (24 + 16);

fn prepare(
    cage: &Cage,
    grid: u32,
    points: usize,
    settings: &AdmmSettings,
) -> Result<Prepared, HarmonicError> {
    let (frame, _) = harmonic::frame_for(cage, grid)?;
    let columns = cage.vertex_count() as u64;
    let output = points as u64 * columns * 4 + (64 << 20);
    // Classifying the nodes alone takes this much: refuse before it.
    check_memory(
        cage,
        grid,
        points,
        frame.node_count() as u64 * 8 + output,
        settings,
    )?;
    let (inside, _) = inside_nodes(cage, &frame);
    let inside = inside.iter().filter(|&&inside| inside).count() as u64;
    let before_factor =
        frame.node_count() as u64 * 8 + inside * BYTES_PER_NODE_BEFORE_FACTOR + output;
    check_memory(cage, grid, points, before_factor, settings)?;
    let level = Level::new(cage, frame, true);
    let operator = Operator::new(&level);
    let solver_error = |reason: String| HarmonicError::Solver {
        family: FAMILY,
        grid,
        reason,
    };
    let matrix = operator
        .shifted_hessian(settings.rho)
        .map_err(solver_error)?;
    let analysis = admm::Analysis::new(&matrix).map_err(solver_error)?;
    let n = level.unknowns() as u64;
    let threads = rayon::current_num_threads() as u64;
    let block = HANDLES_PER_BLOCK.min(cage.vertex_count()).max(1);
    let per_block = 7 * n * block as u64 * 8 + analysis.solve_bytes(block);
    let predicted_bytes = frame.node_count() as u64 * 8
        + n * BYTES_PER_NODE_BEFORE_FACTOR
        + analysis.factorisation_bytes()
        + threads * per_block
        + n * columns * 8
        + output;
    let plan = BbwPlan {
        grid,
        dims: frame.dims,
        cell: frame.h,
        inside_nodes: level.unknowns(),
        factor_entries: analysis.factor_entries(),
        predicted_bytes,
    };
    Ok(Prepared {
        level,
        system: System {
            operator,
            matrix,
            analysis,
            plan,
        },
        plan,
    })
}

/// Refuse `needed` bytes at `grid` if they would not fit, naming a grid that
/// would.
fn check_memory(
    cage: &Cage,
    grid: u32,
    points: usize,
    needed: u64,
    settings: &AdmmSettings,
) -> Result<(), HarmonicError> {
    harmonic::refuse_unless_it_fits(FAMILY, grid, needed, &|smaller| {
        Ok(prepare(cage, smaller, points, settings)?
            .plan
            .predicted_bytes)
    })
}

/// What a bind of `points` points at `grid` would use: the grid, and the
/// Hessian's symbolic factorisation (its values are not computed).
pub fn plan(cage: &Cage, grid: u32, points: usize) -> Result<BbwPlan, HarmonicError> {
    Ok(prepare(cage, grid, points, &AdmmSettings::default())?.plan)
}

/// Bounded biharmonic weights at the inside nodes of the grid at `grid`, with
/// the solver's `settings`; `progress` counts handles (plus one for the
/// factorisation).
pub fn node_weights(
    cage: &Cage,
    grid: u32,
    settings: &AdmmSettings,
    progress: &BindProgress,
) -> Result<(NodeWeights, BbwStats), HarmonicError> {
    let prepared = prepare(cage, grid, 0, settings)?;
    check_memory(cage, grid, 0, prepared.plan.predicted_bytes, settings)?;
    let level = prepared.level;
    let report = |done: usize| progress.advance(done);
    let (values, raw, stats) = solve(prepared.system, cage, settings, &report, progress)?;
    let frame = &level.frame;
    let positions = level
        .nodes
        .iter()
        .map(|&node| frame.position(frame.coordinates(node as usize)))
        .collect();
    Ok((
        NodeWeights {
            positions,
            cell: frame.h,
            values,
            raw,
        },
        stats,
    ))
}

/// Factorise, solve every handle and normalise: the node values (normalised,
/// then raw), node after node.
fn solve(
    system: System,
    cage: &Cage,
    settings: &AdmmSettings,
    report: &(dyn Fn(usize) + Sync),
    progress: &BindProgress,
) -> Result<(Vec<f64>, Vec<f64>, BbwStats), HarmonicError> {
    let System {
        operator,
        matrix,
        analysis,
        plan,
    } = system;
    let grid = plan.grid;
    if progress.is_cancelled() {
        return Err(Cancelled.into());
    }
    // The Hessian is dropped once factorised: only the factor is solved with.
    let factor = analysis
        .factorise(&matrix)
        .map_err(|reason| HarmonicError::Solver {
            family: FAMILY,
            grid,
            reason,
        })?;
    drop(matrix);
    report(1);
    let operator = &operator;
    let n = operator.unknowns();
    let columns = cage.vertex_count();
    let handles: Vec<u32> = (0..columns as u32).collect();
    let cancelled = || progress.is_cancelled();
    let blocks: Vec<(Vec<f64>, BlockStats)> = handles
        .par_chunks(HANDLES_PER_BLOCK)
        .map(|block| {
            let solved = admm::solve_block(operator, &factor, block, settings, &cancelled)?;
            report(block.len());
            Ok(solved)
        })
        .collect::<Result<_, Cancelled>>()?;
    let mut stats = BbwStats {
        inside_nodes: n,
        factor_entries: plan.factor_entries,
        ..BbwStats::default()
    };
    let mut raw = vec![0.0; n * columns];
    for (b, (values, block)) in blocks.iter().enumerate() {
        stats.max_iterations = stats.max_iterations.max(block.iterations);
        stats.total_iterations += block.iterations;
        stats.unconverged += values.len() / n.max(1) - block.converged;
        stats.primal_residual = stats.primal_residual.max(block.primal);
        stats.dual_residual = stats.dual_residual.max(block.dual);
        for (j, column) in values.chunks(n.max(1)).enumerate() {
            let handle = b * HANDLES_PER_BLOCK + j;
            for (node, &value) in column.iter().enumerate() {
                raw[node * columns + handle] = value;
            }
        }
    }
    let mut values = raw.clone();
    for row in values.chunks_mut(columns.max(1)) {
        let sum: f64 = row.iter().sum();
        stats.sum_deviation = stats.sum_deviation.max((sum - 1.0).abs());
        if sum > 0.0 {
            row.iter_mut().for_each(|w| *w /= sum);
        }
    }
    Ok((values, raw, stats))
}

/// Bounded biharmonic weights of `points` (classified by
/// [`crate::geometry::classify_points`]) at `grid` cells along the cage's
/// longest side. `progress` counts rows: it is advanced as handles are solved.
pub fn bind_bbw(
    points: &[DVec3],
    classes: &[PointClass],
    cage: &Cage,
    grid: u32,
    progress: &BindProgress,
) -> Result<(Weights, BbwStats), HarmonicError> {
    bind_bbw_with(
        points,
        classes,
        cage,
        grid,
        &AdmmSettings::default(),
        progress,
    )
}

/// [`bind_bbw`] with the solver's settings.
pub fn bind_bbw_with(
    points: &[DVec3],
    classes: &[PointClass],
    cage: &Cage,
    grid: u32,
    settings: &AdmmSettings,
    progress: &BindProgress,
) -> Result<(Weights, BbwStats), HarmonicError> {
    let prepared = prepare(cage, grid, points.len(), settings)?;
    check_memory(
        cage,
        grid,
        points.len(),
        prepared.plan.predicted_bytes,
        settings,
    )?;
    let columns = cage.vertex_count();
    // Units: the set-up, the factorisation, then one per handle.
    let rows_progress = RowsProgress::new(progress, points.len(), columns + 2);
    let done = std::sync::atomic::AtomicUsize::new(1);
    rows_progress.reach(1);
    let report = |units: usize| {
        let now = done.fetch_add(units, std::sync::atomic::Ordering::Relaxed) + units;
        rows_progress.reach(now);
    };
    let (values, _, stats) = solve(prepared.system, cage, settings, &report, progress)?;
    let mut weights = Weights::zeros(points.len(), columns);
    let sampler = harmonic::sample::Sampler::new(cage, &prepared.level, points, classes);
    let values: Vec<f32> = values.iter().map(|&w| w as f32).collect();
    sampler.write_block(&values, 0, columns, &mut weights);
    fill_boundary_and_outside(points, classes, cage, &mut weights);
    rows_progress.finish();
    Ok((weights, stats))
}
