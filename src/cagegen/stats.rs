//! What a generated cage reports about itself.

use super::{Cage, CageStart, GapReport, StartReason};

/// A generated cage and what was measured on it.
#[derive(Clone, Debug)]
pub struct GeneratedCage {
    pub cage: Cage,
    pub stats: CageStats,
}

/// Measured properties of a generated cage. Distances are in the mesh's units.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CageStats {
    pub vertices: usize,
    pub triangles: usize,
    /// Quads among the faces (with `quads` asked for); the rest are triangles.
    pub quads: usize,
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
    /// The mesh's volume: its own when it is closed, otherwise the volume of the
    /// voxels whose centre has a winding number over one half (0 for sheets
    /// that enclose nothing).
    pub mesh_volume: f64,
    pub mesh_volume_from_voxels: bool,
    /// Smallest angle of any cage triangle, in degrees.
    pub min_angle_degrees: f64,
    /// The clearance asked for (or the default), in the mesh's units.
    pub clearance: f64,
    /// Voxel size and grid used, and whether the generator chose the size.
    pub cell_size: f64,
    pub cell_size_chosen: bool,
    /// The voxel size asked for, when it was finer than the grid allows
    /// (1/512 of the longest side) and was coarsened to `cell_size`.
    pub cell_size_asked: Option<f64>,
    /// How far off the mesh's voxels the envelope let the cage go at last.
    pub reach: f64,
    pub grid: [usize; 3],
    /// Vertices of the voxel surface before simplification.
    pub surface_vertices: usize,
    /// The gaps between parts of the mesh, and which the cage keeps open.
    pub gaps: GapReport,
    /// Where the cage's shape came from (a second start replaces the voxels').
    pub start: CageStart,
    /// Why the start replaced the voxels' cage; `None` for the voxels'.
    pub start_reason: Option<StartReason>,
    pub seconds: f64,
}

impl CageStats {
    /// Cage volume ÷ mesh volume; `None` when the mesh encloses no volume.
    pub fn volume_ratio(&self) -> Option<f64> {
        (self.mesh_volume > 0.0).then(|| self.cage_volume / self.mesh_volume)
    }

    /// Parts of the mesh closer than this may share one part of the cage:
    /// those the voxels may join (the clearance and a voxel on each side,
    /// at least three voxels), or twice the reach when that is more than
    /// the gaps that keep gap points (a cage that far from both sides of a
    /// gap may cross it); any, from a start (it begins around every part).
    pub fn merge_distance(&self) -> f64 {
        if self.start != CageStart::Voxels {
            return f64::INFINITY;
        }
        let voxels = voxels_merge_distance(self.cell_size, self.clearance);
        if self.merge_set_by_reach() {
            voxels.max(2.0 * (self.reach + self.cell_size))
        } else {
            voxels
        }
    }

    /// Whether the cage stood off the mesh by more than half the widest gap
    /// the gap points keep open, so that wider gaps may have been bridged.
    pub fn merge_set_by_reach(&self) -> bool {
        2.0 * (self.reach + self.cell_size) > self.gaps.range
    }

    /// Whether the vertex count is within ±15 % of the target.
    pub fn target_reached(&self) -> bool {
        let target = self.target_vertices as f64;
        (self.vertices as f64 - target).abs() <= 0.15 * target
    }
}

/// Parts of the mesh closer than this may share one part of a voxel set of
/// voxel size `cell` grown by `clearance`: the clearance in whole voxels and
/// the voxel a surface passes through, on each side, and at least three voxels.
pub(super) fn voxels_merge_distance(cell: f64, clearance: f64) -> f64 {
    (3.0 * cell).max(2.0 * ((clearance / cell).ceil() + 1.0) * cell)
}
