//! Automatic cages: a closed, outward-facing, self-intersection-free triangle
//! cage of about a requested number of vertices around any triangle mesh.
//!
//! The method (measured in `docs/cages.md`):
//! 1. voxelise the inside of the mesh by its generalised winding number, so that
//!    open scans with holes, several components and non-manifold edges still have
//!    an inside ([`winding`], [`voxels`]);
//! 2. dilate by the clearance, fill cavities and make the voxel set
//!    well-composed, so that its boundary is a manifold ([`voxels`]);
//! 3. take the boundary faces of the voxels as a closed quad surface
//!    ([`surface`]);
//! 4. simplify it with edge collapses that only ever move the surface outward
//!    (progressive hulls: the new vertex lies on or outside the plane of every
//!    face around the collapsed edge), and that are refused when they would make
//!    the cage cross itself, swallow another part, fold or make a sliver
//!    ([`simplify`]), and that stay within an envelope of the mesh (cells at
//!    most a few voxels away, widened step by step only when no collapse is
//!    left), so that parts a few voxels apart are not bridged;
//! 5. slide each vertex back inward as far as the same checks allow, keeping
//!    the clearance from a dense sample of the mesh's surface ([`shrink`]).
//!
//! Step 4 keeps every surface it makes around the previous one, so the cage
//! contains the voxels, which contain every point of the mesh's surface; each
//! change in steps 4 and 5 is also refused when a sample of the mesh's surface
//! would fall between the old and the new faces. The result is still checked
//! independently (winding number of every mesh vertex, and [`Cage::new`]'s
//! validation, which includes self-intersection), and an error says so if a
//! check fails.

mod checks;
mod guard;
mod measure;
mod shrink;
mod simplify;
mod surface;
mod voxels;
mod winding;

use super::{Cage, CageError, TriMesh};
use std::time::Instant;
use winding::TriangleTree;

/// What to generate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CageOptions {
    /// About how many vertices the cage should have (at least 8).
    pub target_vertices: usize,
    /// Gap between the mesh and the cage, as a fraction of the mesh's
    /// bounding-box diagonal. `None` picks one voxel.
    pub clearance: Option<f64>,
    /// Voxel size, as a fraction of the diagonal. `None` picks one from the
    /// mesh's size and the target. Parts closer than about three voxels merge.
    pub cell_size: Option<f64>,
}

impl CageOptions {
    pub fn new(target_vertices: usize) -> CageOptions {
        CageOptions {
            target_vertices,
            clearance: None,
            cell_size: None,
        }
    }
}

/// The most vertices a generated cage may have: a cage is coarse by definition,
/// and binding cost grows with it.
pub const MAX_TARGET_VERTICES: usize = 20_000;
/// The fewest: a box.
pub const MIN_TARGET_VERTICES: usize = 8;

/// A generated cage and what was measured on it.
#[derive(Clone, Debug)]
pub struct GeneratedCage {
    pub cage: Cage,
    pub stats: CageStats,
}

/// Measured properties of a generated cage. Distances are in the mesh's units.
#[derive(Clone, Debug, PartialEq)]
pub struct CageStats {
    pub vertices: usize,
    pub triangles: usize,
    pub target_vertices: usize,
    /// Connected parts of the cage (separate solids).
    pub shells: usize,
    /// Smallest distance from a mesh vertex to the cage surface.
    pub min_clearance: f64,
    /// The mesh's bounding-box diagonal, to state distances relative to it.
    pub mesh_diagonal: f64,
    /// Mesh vertices not strictly inside the cage (winding number below 0.5).
    /// Always 0 for a returned cage; kept so reports can say so.
    pub outside_vertices: usize,
    pub cage_volume: f64,
    /// The mesh's volume: its own when it is closed, otherwise the volume of its
    /// inside as voxelised by winding number.
    pub mesh_volume: f64,
    pub mesh_volume_from_voxels: bool,
    /// Smallest angle of any cage triangle, in degrees.
    pub min_angle_degrees: f64,
    /// Voxel size and grid used.
    pub cell_size: f64,
    pub grid: [usize; 3],
    /// Vertices of the voxel surface before simplification.
    pub surface_vertices: usize,
    pub seconds: f64,
}

impl CageStats {
    /// Cage volume ÷ mesh volume; `None` when the mesh encloses no volume.
    pub fn volume_ratio(&self) -> Option<f64> {
        (self.mesh_volume > 0.0).then(|| self.cage_volume / self.mesh_volume)
    }

    /// Whether the vertex count is within ±15 % of the target.
    pub fn target_reached(&self) -> bool {
        let target = self.target_vertices as f64;
        (self.vertices as f64 - target).abs() <= 0.15 * target
    }
}

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
}

/// Voxel size when none is asked for, as a fraction of the diagonal: parts
/// about 2.5 % of the diagonal apart stay apart.
pub const DEFAULT_CELL_SIZE: f64 = 1.0 / 128.0;
/// The most voxels along the longest side, so that a tiny requested cell size
/// cannot exhaust memory.
const MAX_CELLS_PER_SIDE: f64 = 512.0;

/// Empty cells around the mesh's bounds: how far the cage may ever be from it.
const MARGIN_CELLS: usize = 12;

/// Generate a cage around `mesh`. `progress` is called with the fraction done
/// (0 to 1) and returns `false` to cancel.
pub fn generate_cage(
    mesh: &TriMesh,
    options: &CageOptions,
    progress: &dyn Fn(f32) -> bool,
) -> Result<GeneratedCage, AutoCageError> {
    let started = Instant::now();
    check_options(mesh, options)?;
    let diagonal = mesh.diagonal();
    let (lo, hi) = mesh.bounds();
    let longest = (hi - lo).max_element();
    let cell = (options.cell_size.unwrap_or(DEFAULT_CELL_SIZE) * diagonal)
        .max(longest / MAX_CELLS_PER_SIDE);
    let clearance_cells = options
        .clearance
        .map_or(1, |c| (c * diagonal / cell).ceil().max(1.0) as usize);
    let stage = |from: f32, to: f32| move |f: f32| progress(from + (to - from) * f);

    let tree = TriangleTree::new(&mesh.positions, &mesh.triangles);
    let mut voxels = voxels::voxelise(
        mesh,
        &tree,
        cell,
        clearance_cells + MARGIN_CELLS,
        &stage(0.0, 0.15),
    )
    .ok_or(AutoCageError::Cancelled)?;
    let voxel_volume = voxels.count() as f64 * cell.powi(3);
    let envelope = voxels::Envelope {
        origin: voxels.origin,
        cell,
        dims: voxels.dims,
        distance: voxels::distance_from_set(&voxels),
        limit: (clearance_cells + 2) as u16,
    };
    voxels::dilate(&mut voxels, clearance_cells);
    voxels::fill_cavities(&mut voxels);
    voxels::make_well_composed(&mut voxels);
    let surface = surface::boundary_surface(&voxels);
    if !progress(0.2) {
        return Err(AutoCageError::Cancelled);
    }
    let surface_vertices = surface.positions.len();
    let mesh_points = measure::surface_samples(mesh, 0.5 * clearance_cells as f64 * cell);
    let simplified = simplify::simplify(
        mesh_points,
        surface.positions,
        surface.triangles,
        envelope,
        &simplify::Goal {
            target_vertices: options.target_vertices,
            max_limit: (clearance_cells + MARGIN_CELLS) as u16,
            clearance: clearance_cells as f64 * cell,
            diagonal,
        },
        &stage(0.2, 0.95),
    )
    .ok_or(AutoCageError::Cancelled)?;
    let triangle_faces = (0..simplified.triangles.len() as u32).collect();
    let (cage, report) = Cage::new(TriMesh {
        positions: simplified.positions,
        triangles: simplified.triangles,
        triangle_faces,
    })
    .map_err(AutoCageError::Invalid)?;
    let enclosure = measure::enclosure(&cage, mesh);
    if let Some(first) = enclosure.first_outside {
        return Err(AutoCageError::NotEnclosing {
            outside: enclosure.outside,
            first,
        });
    }
    let (mesh_volume, mesh_volume_from_voxels) = match measure::closed_volume(mesh) {
        Some(volume) => (volume, false),
        None => (voxel_volume, true),
    };
    progress(1.0);
    let stats = CageStats {
        vertices: cage.vertex_count(),
        triangles: cage.triangle_count(),
        target_vertices: options.target_vertices,
        shells: measure::shell_count(&cage),
        min_clearance: enclosure.min_clearance,
        mesh_diagonal: diagonal,
        outside_vertices: 0,
        cage_volume: report.volume,
        mesh_volume,
        mesh_volume_from_voxels,
        min_angle_degrees: measure::min_angle_degrees(&cage),
        cell_size: cell,
        grid: voxels.dims,
        surface_vertices,
        seconds: started.elapsed().as_secs_f64(),
    };
    Ok(GeneratedCage { cage, stats })
}

fn check_options(mesh: &TriMesh, options: &CageOptions) -> Result<(), AutoCageError> {
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
        if !(value > 0.0 && value < 0.5) {
            return Err(AutoCageError::BadClearance { value });
        }
    }
    if let Some(value) = options.cell_size {
        if !(value > 0.0 && value < 0.25) {
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
