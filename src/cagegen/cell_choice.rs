//! The voxel size of the first try: fine enough to keep the gaps between
//! parts of the mesh open, coarse enough for the target and the time.

use super::stats::voxels_merge_distance;

/// Vertices of the voxel surface that the first try starts from at most: the
/// simplification's time grows with it (the comb's 26,000 took about 4 s).
const MAX_SURFACE_VERTICES: f64 = 26_000.0;
/// Mean cage edge, in voxels, that the simplification reaches reliably (the
/// qmvc meshes): the first try's voxels are at least a cage's edge over this.
const EDGE_CELLS: f64 = 16.0;
/// The same two bounds where finer voxels keep gaps open: most of a finer
/// surface is flat patches and straight creases, merged before the
/// collapses at little cost ([`super::flat`]).
const MAX_SURFACE_VERTICES_FOR_GAPS: f64 = 80_000.0;
const EDGE_CELLS_FOR_GAPS: f64 = 24.0;
/// The least share of the points midway across gaps that the voxels chosen
/// for the gaps must keep open, where the others would not, to be chosen.
const MIN_SHARE_FOR_GAPS: f64 = 0.1;
/// The finest voxels chosen to keep a gap open, as a fraction of the
/// diagonal: gaps from four of them (1.6 %) wide.
pub const FINEST_CELL_SIZE_FOR_GAPS: f64 = 1.0 / 256.0;

/// What the first voxel surface, at voxel size `cell`, says.
pub(super) struct FirstSurface<'a> {
    pub cell: f64,
    pub vertices: usize,
    /// Widths of the gaps whose points midway these voxels cover.
    pub bridged_widths: &'a [f64],
    /// Widths of those whose points midway they leave outside.
    pub open_widths: &'a [f64],
}

/// What bounds the choice.
pub(super) struct Bounds {
    pub target: usize,
    pub clearance: f64,
    pub diagonal: f64,
    /// The coarsest voxel size chosen unasked.
    pub coarsest: f64,
}

/// The voxel sizes for the first try. A voxel surface has about one vertex
/// per cell² of area, so its vertex count goes as the inverse square of the
/// voxel size, and a cage of N vertices over it has a mean edge of about
/// √(1.15·V/N) voxels. The voxels are made coarser when the surface is over
/// [`MAX_SURFACE_VERTICES`] or that edge over [`EDGE_CELLS`], and finer when
/// they bridge a gap that finer ones would keep open, down to the coarsest
/// size that keeps the narrowest such gap, within the larger bounds for gaps;
/// gaps they keep open are kept from being bridged by coarser ones.
pub(super) fn first_try_cell(first: &FirstSurface, bounds: &Bounds) -> CellChoice {
    let vertices = first.vertices as f64;
    let within = |max_vertices: f64, edge_cells: f64| {
        let for_time = (vertices / max_vertices).sqrt();
        let for_target = (1.15 * vertices / bounds.target as f64).sqrt() / edge_cells;
        first.cell * for_time.max(for_target)
    };
    let wanted = within(MAX_SURFACE_VERTICES, EDGE_CELLS)
        .max(first.cell)
        .min(bounds.coarsest);
    let finest = FINEST_CELL_SIZE_FOR_GAPS * bounds.diagonal;
    // A bridged gap needs the voxels that keep it; one kept open here is
    // kept by these voxels, but may be bridged by coarser ones.
    let keeping = |widths: &[f64]| -> Vec<f64> {
        (widths.iter())
            .filter_map(|&w| keeping_cell(w, bounds.clearance))
            .filter(|&cell| cell >= finest)
            .collect()
    };
    let bridged = keeping(first.bridged_widths);
    let at_risk: Vec<f64> = (keeping(first.open_widths).into_iter())
        .filter(|&cell| cell < wanted)
        .map(|cell| cell.max(first.cell))
        .collect();
    let Some(narrowest) = bridged.iter().chain(&at_risk).copied().reduce(f64::min) else {
        return CellChoice {
            wanted,
            for_gaps: wanted,
        };
    };
    let for_gaps =
        wanted.min(narrowest.max(within(MAX_SURFACE_VERTICES_FOR_GAPS, EDGE_CELLS_FOR_GAPS)));
    // Worth a finer surface only when it keeps a share of the gaps open: a
    // gap these voxels bridge stays bridged by voxels no finer, and a few
    // points (a nozzle's rim) are rarely kept by the target anyway.
    let finer = for_gaps < first.cell / 1.05;
    let kept = at_risk.iter().filter(|&&cell| cell >= for_gaps).count()
        + if finer {
            bridged.iter().filter(|&&cell| cell >= for_gaps).count()
        } else {
            0
        };
    let points = first.bridged_widths.len() + first.open_widths.len();
    let for_gaps = if kept as f64 >= MIN_SHARE_FOR_GAPS * points as f64 {
        for_gaps
    } else {
        wanted
    };
    CellChoice { wanted, for_gaps }
}

/// The voxel size for the target and the time, and the one for the gaps
/// (no coarser).
pub(super) struct CellChoice {
    pub wanted: f64,
    pub for_gaps: f64,
}

/// The coarsest voxel size whose voxels, grown by `clearance`, keep a gap of
/// `width` open ([`voxels_merge_distance`]), if there is one.
fn keeping_cell(width: f64, clearance: f64) -> Option<f64> {
    // A quarter of the width when the clearance fits in one voxel, otherwise
    // the clearance in whole voxels.
    std::iter::once(0.25 * width)
        .chain((1..=8).map(|k| clearance / k as f64))
        .find(|&cell| voxels_merge_distance(cell, clearance) <= width)
}
