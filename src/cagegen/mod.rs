//! The cage generator: a closed, outward-facing, self-intersection-free
//! triangle cage of about a requested number of vertices around any triangle
//! mesh. Imports `geometry` and `budget` only; reads and writes no file and
//! never touches wgpu or egui.
//!
//! The method (measured in `docs/cages.md`):
//! 1. voxelise the inside of the mesh by its generalised winding number, so that
//!    open scans with holes, several components and non-manifold edges still have
//!    an inside ([`winding`], [`voxels`]);
//! 2. dilate by the clearance, fill cavities and make the voxel set
//!    well-composed, so that its boundary is a manifold ([`voxels`]);
//! 3. take the boundary faces of the voxels as a closed quad surface
//!    ([`surface`]);
//! 4. simplify it with edge collapses that only move the surface outward
//!    (progressive hulls), refused when they would make the cage cross
//!    itself, swallow another part, fold or make a sliver ([`simplify`]),
//!    leave an envelope of the mesh (a few voxels, widened only when no
//!    collapse is left), or cover a point midway across a gap between parts
//!    that the voxels left outside ([`gaps`]);
//! 5. slide each vertex back inward as far as the same checks allow, keeping
//!    the clearance from a dense sample of the mesh's surface ([`shrink`]),
//!    whenever the collapses are stuck and at the end;
//! 6. polish: move vertices in any direction that lowers the enclosed
//!    volume, and flip edges that do, under the same checks ([`polish`]);
//! 7. for eight vertices, also tighten and polish the bounding box, and for
//!    targets up to 64, or where the cage bridges gaps, a prism along each
//!    axis (the mesh's convex or traced outline seen along it, extruded);
//!    keep a valid one that bridges no gap the simplification kept open and
//!    keeps more open or encloses less ([`starts`]).
//!
//! Step 4 keeps every surface around the previous one, so the cage contains
//! the voxels, which contain the mesh's surface; each change in steps 4 to 6
//! is refused when a surface sample would fall between the old and new faces.
//! The result is still checked independently (winding number of every mesh
//! vertex, and [`Cage::new`]'s validation, self-intersection included).

mod cell_choice;
mod checks;
mod chessboard;
mod cost;
mod error;
mod flat;
mod gaps;
mod guard;
mod measure;
mod pairing;
mod plan;
mod points;
mod polish;
mod shrink;
mod simplify;
mod starts;
mod stats;
mod surface;
mod voxels;
mod winding;

use crate::geometry::{Cage, TriMesh};
pub use cell_choice::FINEST_CELL_SIZE_FOR_GAPS;
pub use error::AutoCageError;
use error::{MAX_CELL_SIZE, MAX_CLEARANCE};
pub use gaps::GapReport;
use glam::DVec3;
pub use plan::{plan_cage, CagePlan, MAX_GRID_CELLS, MAX_SURFACE_SAMPLES};
pub use starts::{CageStart, StartReason};
pub use stats::{CageStats, GeneratedCage};
use std::time::Instant;
use winding::TriangleTree;

/// What to generate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CageOptions {
    /// About how many vertices the cage should have (at least 8).
    pub target_vertices: usize,
    /// Gap between the mesh and the cage, as a fraction of the mesh's
    /// bounding-box diagonal. `None` picks [`DEFAULT_CLEARANCE`].
    pub clearance: Option<f64>,
    /// Voxel size, as a fraction of the diagonal. `None` picks one from the
    /// mesh's size and the target. Parts closer than about three voxels merge.
    pub cell_size: Option<f64>,
    /// Pair triangles into near-planar, well-shaped quads (bilinear patches)
    /// where that keeps every guarantee.
    pub quads: bool,
}

impl CageOptions {
    pub fn new(target_vertices: usize) -> CageOptions {
        CageOptions {
            target_vertices,
            clearance: None,
            cell_size: None,
            quads: false,
        }
    }
}

/// The most vertices a generated cage may have: a cage is coarse by definition,
/// and binding cost grows with it.
pub const MAX_TARGET_VERTICES: usize = 20_000;
/// The fewest: a box.
pub const MIN_TARGET_VERTICES: usize = 8;

/// Finest voxel size, as a fraction of the diagonal: parts about 2.5 % of the
/// diagonal apart stay apart. Coarser voxels are chosen when the target is too
/// small for this much detail.
pub const DEFAULT_CELL_SIZE: f64 = 1.0 / 128.0;
/// Gap between the mesh and the cage when none is asked for, as a fraction of
/// the diagonal: half the finest voxel. At 1/128 no cage could come within 1.3
/// of a tube's volume (it is at least ((r + c) / r)², docs/cages.md).
pub const DEFAULT_CLEARANCE: f64 = 1.0 / 256.0;
/// The coarsest voxel size chosen unasked, as a fraction of the diagonal.
const MAX_CHOSEN_CELL_SIZE: f64 = 1.0 / 12.0;
/// How many coarser voxel sizes are tried when a cage misses its target.
const RETRIES: usize = 3;

/// How far past the clearance the envelope may widen on the first try, as a
/// fraction of the diagonal, however coarse the voxels; each retry adds half.
const MAX_REACH: f64 = 0.08;
/// Empty cells around the mesh's bounds: how far the cage may ever be from it.
pub(super) const MARGIN_CELLS: usize = 12;

/// Generate a cage around `mesh`. `progress` is called with the fraction done
/// (0 to 1) and returns `false` to cancel.
///
/// Without a voxel size, the first try uses [`DEFAULT_CELL_SIZE`], or coarser
/// voxels when a target-sized cage's mean edge would be over [`EDGE_CELLS`]
/// voxels or the voxel surface over [`MAX_SURFACE_VERTICES`] vertices. When that
/// cage has more than 15 % over the target, coarser voxels and a wider envelope
/// are tried (at most [`RETRIES`] times), which merge close parts; the cage
/// closest to the target is kept, and its voxel size is reported.
pub fn generate_cage(
    mesh: &TriMesh,
    options: &CageOptions,
    progress: &dyn Fn(f32) -> bool,
) -> Result<GeneratedCage, AutoCageError> {
    let started = Instant::now();
    let plan = plan_cage(mesh, options)?;
    // Everything is computed relative to the mesh's bounding-box centre, so a
    // mesh far from the origin keeps its precision; the cage moves back at the end.
    let centred = TriMesh {
        positions: mesh.positions.iter().map(|p| *p - plan.centre).collect(),
        triangles: mesh.triangles.clone(),
        triangle_faces: mesh.triangle_faces.clone(),
    };
    let mesh = &centred;
    let (diagonal, clearance) = (plan.diagonal, plan.clearance);
    let closed_volume = measure::closed_volume(mesh);
    let tree = TriangleTree::new(&mesh.positions, &mesh.triangles);
    let target = options.target_vertices;
    let mesh_points = points::PointTree::new(measure::surface_samples(mesh, 0.5 * clearance));
    // Gaps wider than the cage's two clearances can be kept open; those
    // narrower than twice the first try's reach (and its few voxels past the
    // clearance) could be bridged.
    let gap_widths = (
        2.0 * clearance,
        2.0 * (clearance + 1.25 * MAX_REACH * diagonal),
    );
    // Rays about two of the finest voxels apart: the voxels keep no gap
    // narrower than a few of them, so denser rays add points, not gaps.
    let ray_spacing = 2.0 * clearance.max(DEFAULT_CELL_SIZE * diagonal);
    let gap_points = gaps::gap_points(mesh, &tree, ray_spacing, gap_widths);
    let context = Context {
        mesh,
        tree: &tree,
        clearance,
        open: closed_volume.is_none(),
        gap_points: &gap_points,
    };

    let chosen = options.cell_size.is_none();
    let coarsest = MAX_CHOSEN_CELL_SIZE * diagonal;
    let (mut cell, surface, mut fallback) = if chosen {
        let bounds = cell_choice::Bounds {
            target,
            clearance,
            diagonal,
            coarsest,
        };
        context.first_surface(plan.cell_size, &bounds, progress)?
    } else {
        let surface = context.voxel_surface(plan.cell_size, &|f| progress(0.1 * f))?;
        (plan.cell_size, surface, None)
    };
    let attempts = if chosen {
        1 + RETRIES + usize::from(fallback.is_some())
    } else {
        1
    };
    let mut widened = 0;
    let mut best: Option<Attempt> = None;
    let mut next_surface = Some(surface);
    for attempt in 0..attempts {
        // The first try has most of the bar: retries are on smaller surfaces.
        let share = |k: usize| 0.1 + 0.85 * (1.0 - 0.4f32.powi(k as i32));
        let (from, to) = (share(attempt), share(attempt + 1));
        let span = move |f: f32| progress(from + (to - from) * f);
        let surface = match next_surface.take() {
            Some(surface) => surface,
            None => context.voxel_surface(cell, &|f| span(0.1 * f))?,
        };
        // Each retry may also stand further off the mesh.
        let reach = MAX_REACH * diagonal * 1.5f64.powi(widened);
        let cells = surface.clearance_cells;
        let goal = simplify::Goal {
            target_vertices: target,
            max_limit: (cells + MARGIN_CELLS).min(cells + 2 + (reach / cell).ceil() as usize)
                as u16,
            clearance,
            diagonal,
        };
        let result = simplify_surface(surface, &mesh_points, &goal, &|f| span(0.1 + 0.9 * f))?;
        let reached = result.simplified.positions.len();
        let closer = best
            .as_ref()
            .is_none_or(|b| reached < b.simplified.positions.len());
        if closer {
            best = Some(result);
        }
        if reached as f64 <= 1.15 * target as f64 || cell >= coarsest {
            break;
        }
        // Voxels made finer to keep gaps open missed the target: the size
        // chosen without the gaps is tried as it would have been first.
        if let Some(plain) = fallback.take() {
            cell = plain;
            continue;
        }
        // Larger steps when the target is far off.
        let factor = ((reached as f64 / target as f64).sqrt() / 2.0).clamp(1.5, 3.0);
        cell = (cell * factor).min(coarsest);
        widened += 1;
    }
    let Some(mut best) = best else {
        return Err(AutoCageError::Cancelled);
    };
    let goal = simplify::Goal {
        target_vertices: target,
        max_limit: 0,
        clearance,
        diagonal,
    };
    // The tries end at 0.95 of the bar; a cancel during the starts is answered after them.
    let step = |f: f32| progress(f).then_some(()).ok_or(AutoCageError::Cancelled);
    step(0.95)?;
    starts::replace_if_better(&mut best, (mesh, &mesh_points, &gap_points), &goal);
    step(0.97)?;
    let volume = closed_volume.map_or(MeshVolume::Winding(best.winding_volume), MeshVolume::Closed);
    let request = Request {
        target_vertices: target,
        clearance,
        quads: options.quads.then_some((&mesh_points, clearance)),
        cell_size_chosen: chosen,
        cell_size_asked: plan.cell_size_asked,
        centre: plan.centre,
        volume,
        gap_points: &gap_points,
        gap_range: gap_widths.1,
    };
    finish(mesh, best, &request, started, progress)
}

/// What every voxelisation of one generation shares.
struct Context<'a> {
    mesh: &'a TriMesh,
    tree: &'a TriangleTree,
    clearance: f64,
    /// The mesh has edges with other than two faces: its volume is measured
    /// by winding number.
    open: bool,
    gap_points: &'a [gaps::GapPoint],
}

/// The mesh's volume, for the volume ratio.
enum MeshVolume {
    Closed(f64),
    /// Of an open mesh: by winding number, inside its bounding box.
    Winding(f64),
}

/// What was asked, and what finishing needs besides the attempt.
struct Request<'a> {
    target_vertices: usize,
    clearance: f64,
    /// With quads: the mesh's surface samples and the clearance they keep.
    quads: Option<(&'a points::PointTree, f64)>,
    cell_size_chosen: bool,
    cell_size_asked: Option<f64>,
    /// Where the centred cage goes back to.
    centre: DVec3,
    volume: MeshVolume,
    /// Every gap point found, to report which the cage keeps outside.
    gap_points: &'a [gaps::GapPoint],
    /// The widest gap that gap points were sought across.
    gap_range: f64,
}

/// A closed voxel surface around the mesh, at least `clearance` from it.
struct VoxelSurface {
    surface: surface::Surface,
    envelope: voxels::Envelope,
    clearance_cells: usize,
    winding_volume: f64,
    /// The gap points outside the voxels, which the cage keeps outside.
    gaps: Vec<DVec3>,
    /// The widths of the gaps whose points midway the voxels cover, and leave outside.
    bridged_widths: Vec<f64>,
    open_widths: Vec<f64>,
}

/// The cage of one voxel size, before it is checked.
struct Attempt {
    simplified: simplify::Simplified,
    cell: f64,
    grid: [usize; 3],
    surface_vertices: usize,
    winding_volume: f64,
    start: CageStart,
    /// Why a start replaced the voxels' cage.
    start_reason: Option<StartReason>,
}

impl Context<'_> {
    /// The voxel surface of the first try, at `cell` or a size chosen from
    /// the one made there ([`cell_choice`]). Voxels finer than `cell`, made
    /// to keep gaps open, are kept only when they leave more gap points
    /// outside: a gap point may lie in a pocket that any voxels fill.
    fn first_surface(
        &self,
        cell: f64,
        bounds: &cell_choice::Bounds,
        progress: &dyn Fn(f32) -> bool,
    ) -> Result<(f64, VoxelSurface, Option<f64>), AutoCageError> {
        let first = self.voxel_surface(cell, &|f| progress(0.05 * f))?;
        let choice = cell_choice::first_try_cell(
            &cell_choice::FirstSurface {
                cell,
                vertices: first.surface.positions.len(),
                bridged_widths: &first.bridged_widths,
                open_widths: &first.open_widths,
            },
            bounds,
        );
        let differs = |size: f64| size > 1.05 * cell || size < cell / 1.05;
        let mesh = self.mesh;
        let fits = |size: f64| {
            let grid = plan::grid_dims(mesh, size, self.clearance);
            size >= cell || plan::check_grid(mesh, grid, size, self.clearance, 0).is_ok()
        };
        // A second voxel surface takes the bar from 0.05 to 0.1; a third,
        // after finer voxels that opened nothing, its last part.
        let second = |size: f64| self.voxel_surface(size, &|f| progress(0.05 + 0.03 * f));
        let third = |size: f64| self.voxel_surface(size, &|f| progress(0.08 + 0.02 * f));
        if choice.for_gaps < choice.wanted {
            // Where these miss the target, the size chosen without the gaps.
            let plain = (choice.for_gaps < choice.wanted / 1.05).then_some(choice.wanted);
            if !differs(choice.for_gaps) {
                return Ok((cell, first, plain));
            }
            if choice.for_gaps > cell {
                return Ok((choice.for_gaps, second(choice.for_gaps)?, plain));
            }
            if fits(choice.for_gaps) {
                let first_open = first.gaps.len();
                drop(first);
                let finer = second(choice.for_gaps)?;
                if finer.gaps.len() > first_open {
                    return Ok((choice.for_gaps, finer, plain));
                }
                return Ok((choice.wanted, third(choice.wanted)?, None));
            }
        }
        if !differs(choice.wanted) {
            return Ok((cell, first, None));
        }
        Ok((choice.wanted, second(choice.wanted)?, None))
    }

    /// The voxel surface at voxel size `cell`, each allocation checked first.
    fn voxel_surface(
        &self,
        cell: f64,
        progress: &dyn Fn(f32) -> bool,
    ) -> Result<VoxelSurface, AutoCageError> {
        let mesh = self.mesh;
        let clearance_cells = plan::clearance_cells(cell, self.clearance);
        let dims = plan::grid_dims(mesh, cell, self.clearance);
        plan::check_grid(mesh, dims, cell, self.clearance, 0)?;
        let margin = clearance_cells + MARGIN_CELLS;
        let (mut voxels, winding_volume) =
            voxels::voxelise(mesh, self.tree, (cell, margin, dims), self.open, &|f| {
                progress(0.6 * f)
            })
            .ok_or(AutoCageError::Cancelled)?;
        // The grid-wide passes below each take a share of the bar: on a fine
        // grid each takes seconds.
        let step = |f: f32| progress(f).then_some(()).ok_or(AutoCageError::Cancelled);
        let envelope = voxels::Envelope {
            origin: voxels.origin,
            cell,
            dims: voxels.dims,
            distance: chessboard::distance_from_set(&voxels.inside, voxels.dims),
            limit: (clearance_cells + 2) as u16,
        };
        step(0.7)?;
        voxels::dilate(&mut voxels, clearance_cells);
        step(0.8)?;
        voxels::fill_cavities(&mut voxels);
        step(0.9)?;
        voxels::make_well_composed(&mut voxels);
        let (outside, covered): (Vec<&gaps::GapPoint>, Vec<_>) = self
            .gap_points
            .iter()
            .partition(|g| voxels.is_outside(g.position));
        let gaps = outside.iter().map(|g| g.position).collect();
        // The voxel size is chosen for the gaps between walls.
        let widths = |points: &[&gaps::GapPoint]| {
            (points.iter())
                .filter(|g| !g.opening)
                .map(|g| g.width)
                .collect()
        };
        let (bridged_widths, open_widths) = (widths(&covered), widths(&outside));
        step(1.0)?;
        let faces = surface::boundary_face_count(&voxels);
        plan::check_surface(faces as u64, cell, mesh.diagonal())?;
        Ok(VoxelSurface {
            surface: surface::boundary_surface(&voxels, faces),
            envelope,
            clearance_cells,
            winding_volume: winding_volume.unwrap_or(0.0),
            gaps,
            bridged_widths,
            open_widths,
        })
    }
}

fn simplify_surface(
    voxel_surface: VoxelSurface,
    mesh_points: &points::PointTree,
    goal: &simplify::Goal,
    progress: &dyn Fn(f32) -> bool,
) -> Result<Attempt, AutoCageError> {
    let VoxelSurface {
        surface,
        envelope,
        winding_volume,
        gaps,
        ..
    } = voxel_surface;
    let gap_tree = points::PointTree::new(gaps);
    let (cell, grid) = (envelope.cell, envelope.dims);
    let surface_vertices = surface.positions.len();
    let simplified = simplify::simplify(
        (mesh_points, &gap_tree),
        surface.positions,
        surface.triangles,
        envelope,
        goal,
        progress,
    )
    .ok_or(AutoCageError::Cancelled)?;
    Ok(Attempt {
        simplified,
        cell,
        grid,
        surface_vertices,
        winding_volume,
        start: CageStart::Voxels,
        start_reason: None,
    })
}

/// Check the chosen cage independently, measure it and move it back from the
/// mesh's centre.
fn finish(
    mesh: &TriMesh,
    attempt: Attempt,
    request: &Request,
    started: Instant,
    progress: &dyn Fn(f32) -> bool,
) -> Result<GeneratedCage, AutoCageError> {
    let Attempt {
        simplified,
        cell,
        grid,
        surface_vertices,
        start,
        start_reason,
        ..
    } = attempt;
    let reach = f64::from(simplified.envelope_limit) * cell;
    let (cage, report) = match request.quads {
        Some((samples, clearance)) => {
            let triangles = &simplified.triangles;
            let gaps =
                points::PointTree::new(request.gap_points.iter().map(|g| g.position).collect());
            pairing::quad_cage(simplified.positions, triangles, (samples, &gaps), clearance)
        }
        None => Cage::new(TriMesh {
            triangle_faces: (0..simplified.triangles.len() as u32).collect(),
            positions: simplified.positions,
            triangles: simplified.triangles,
        }),
    }
    .map_err(AutoCageError::Invalid)?;
    let enclosure = if cage.has_quads() {
        pairing::enclosure_on_patches(&cage, mesh)
    } else {
        measure::enclosure(&cage, mesh)
    };
    if let Some(first) = enclosure.first_outside {
        return Err(AutoCageError::NotEnclosing {
            outside: enclosure.outside,
            first,
        });
    }
    let mut gaps = gaps::report(request.gap_points, request.gap_range, &cage);
    for point in &mut gaps.bridged {
        *point += request.centre;
    }
    let (mesh_volume, mesh_volume_from_voxels) = match request.volume {
        MeshVolume::Closed(volume) => (volume, false),
        MeshVolume::Winding(volume) => (volume, true),
    };
    if !progress(1.0) {
        return Err(AutoCageError::Cancelled);
    }
    let stats = CageStats {
        vertices: cage.vertex_count(),
        triangles: cage.triangle_count(),
        quads: cage.quads().len(),
        target_vertices: request.target_vertices,
        shells: measure::shell_count(&cage),
        min_clearance: enclosure.min_clearance,
        mesh_diagonal: mesh.diagonal(),
        outside_vertices: 0,
        cage_volume: report.volume,
        mesh_volume,
        mesh_volume_from_voxels,
        min_angle_degrees: measure::min_angle_degrees(&cage),
        clearance: request.clearance,
        cell_size: cell,
        cell_size_chosen: request.cell_size_chosen,
        cell_size_asked: request.cell_size_asked,
        reach,
        grid,
        surface_vertices,
        gaps,
        start,
        start_reason,
        seconds: started.elapsed().as_secs_f64(),
    };
    // Validated where it was built; a translation changes neither its
    // topology, its orientation nor whether it crosses itself.
    let moved = cage
        .positions()
        .iter()
        .map(|p| *p + request.centre)
        .collect();
    Ok(GeneratedCage {
        cage: cage.with_positions(moved),
        stats,
    })
}

pub(super) fn check_options(mesh: &TriMesh, options: &CageOptions) -> Result<(), AutoCageError> {
    let requested = options.target_vertices;
    if requested < MIN_TARGET_VERTICES {
        return Err(AutoCageError::TooFewVertices { requested });
    }
    if requested > MAX_TARGET_VERTICES {
        return Err(AutoCageError::TooManyVertices {
            requested,
            mesh_vertices: mesh.positions.len(),
        });
    }
    if let Some(value) = options.clearance {
        if !(value > 0.0 && value < MAX_CLEARANCE) {
            return Err(AutoCageError::BadClearance { value });
        }
    }
    if let Some(value) = options.cell_size {
        if !(value > 0.0 && value < MAX_CELL_SIZE) {
            return Err(AutoCageError::BadCellSize { value });
        }
    }
    if mesh.triangles.is_empty() {
        return Err(AutoCageError::NoTriangles);
    }
    if measure::is_flat(mesh) {
        return Err(AutoCageError::Flat);
    }
    Ok(())
}
