//! What a generation will allocate, predicted before it is: the surface
//! samples grow with the inverse square of the clearance, the voxel grid with
//! the inverse cube of the voxel size (and its margins with the clearance), and
//! the voxel surface with its area in voxels. Each is refused, with its size
//! and a value that would fit, before anything is made.

use super::{AutoCageError, CageOptions, DEFAULT_CELL_SIZE, DEFAULT_CLEARANCE, MARGIN_CELLS};
use crate::budget::{bytes_for, check_memory};
use crate::geometry::TriMesh;
use glam::DVec3;

/// Bytes per surface sample: the point (24) and its share of the point tree's
/// nodes (64 bytes per node, a node per 4 points at worst).
const SAMPLE_BYTES: u64 = 40;
/// Bytes per voxel at the voxel stage's peak: the flags, the region ids and
/// lists or the breadth-first queues (8 bytes per cell, doubled as they grow),
/// and the envelope's distances.
const CELL_BYTES: u64 = 24;
/// Bytes per vertex of the voxel surface while it is simplified: positions,
/// quadrics, stars, spatial hashes, the candidate heap and the faces that
/// collapses append. A bound from a measurement: a sphere's surface of about
/// 32,000 vertices peaked at 58 MB for the whole process (1.8 KB a vertex).
const SURFACE_VERTEX_BYTES: u64 = 2_000;
/// The most surface samples besides the mesh's vertices: about 800 MB, and a
/// few seconds to make. Finer clearances need more (the inverse square).
pub const MAX_SURFACE_SAMPLES: u64 = 20_000_000;
/// The most voxels in a grid: 512 along the longest side with the margins of
/// the default clearance fit (about 6 GB at the peak).
pub const MAX_GRID_CELLS: u64 = 1 << 28;
/// The most voxels along the longest side: a finer voxel size is coarsened.
pub(super) const MAX_CELLS_PER_SIDE: f64 = 512.0;

/// What a generation will use, in the mesh's units, predicted before it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct CagePlan {
    /// The mesh's bounding-box centre: the generator works relative to it.
    pub centre: DVec3,
    pub diagonal: f64,
    pub clearance: f64,
    /// Points on the surface kept inside the cage, and their bytes.
    pub samples: u64,
    pub sample_bytes: u64,
    /// The first voxel size and its grid; later ones are coarser.
    pub cell_size: f64,
    /// The voxel size asked for, when it was finer than the grid allows and
    /// was coarsened to `cell_size`.
    pub cell_size_asked: Option<f64>,
    pub grid: [usize; 3],
    pub grid_bytes: u64,
}

/// Check `options` for `mesh` and predict what generating its cage allocates
/// first, refusing what cannot fit. [`super::generate_cage`] starts with it;
/// callers that create files first (the command line) call it before.
pub fn plan_cage(mesh: &TriMesh, options: &CageOptions) -> Result<CagePlan, AutoCageError> {
    super::check_options(mesh, options)?;
    let (lo, hi) = mesh.bounds();
    let centre = (lo + hi) * 0.5;
    let diagonal = (hi - lo).length();
    let clearance_fraction = options.clearance.unwrap_or(DEFAULT_CLEARANCE);
    let clearance = clearance_fraction * diagonal;
    let spacing = 0.5 * clearance;
    let samples = sample_count(mesh, spacing);
    let extra = samples.saturating_sub(mesh.positions.len() as u64);
    let suggest_clearance = |limit: u64| suggested_clearance(mesh, clearance_fraction, limit);
    if extra > MAX_SURFACE_SAMPLES {
        return Err(AutoCageError::TooManySamples {
            clearance: clearance_fraction,
            points: samples,
            bytes: bytes_for(samples, SAMPLE_BYTES),
            suggested: suggest_clearance(MAX_SURFACE_SAMPLES),
        });
    }
    // The centred copy of the mesh is made with the samples.
    let mesh_bytes = bytes_for(mesh.positions.len() as u64, 24)
        .saturating_add(bytes_for(mesh.triangles.len() as u64, 16));
    let sample_bytes = bytes_for(samples, SAMPLE_BYTES);
    check_memory(
        || format!("the surface samples ({samples} points, at a clearance of {clearance_fraction} of the diagonal)"),
        sample_bytes.saturating_add(mesh_bytes),
    )
    .map_err(|limit| {
        // Half what is left: the voxels need room too.
        let fits = limit.available.unwrap_or(0).saturating_sub(mesh_bytes) / SAMPLE_BYTES / 2;
        AutoCageError::NotEnoughMemory {
            advice: format!(
                "a clearance of {} of the diagonal or more would fit",
                short(suggest_clearance(fits.saturating_sub(mesh.positions.len() as u64)))
            ),
            limit,
        }
    })?;

    let finest = (hi - lo).max_element() / MAX_CELLS_PER_SIDE;
    let asked = options.cell_size.unwrap_or(DEFAULT_CELL_SIZE) * diagonal;
    let cell_size = asked.max(finest);
    let cell_size_asked = (options.cell_size.is_some() && asked < finest).then_some(asked);
    let grid = grid_dims(mesh, cell_size, clearance);
    let grid_bytes = check_grid(mesh, grid, cell_size, clearance, sample_bytes)?;
    Ok(CagePlan {
        centre,
        diagonal,
        clearance,
        samples,
        sample_bytes,
        cell_size,
        cell_size_asked,
        grid,
        grid_bytes,
    })
}

/// Cells per axis of the grid around `mesh` at voxel size `cell`, with the
/// margins the clearance and the envelope need.
pub(super) fn grid_dims(mesh: &TriMesh, cell: f64, clearance: f64) -> [usize; 3] {
    let (lo, hi) = mesh.bounds();
    let margin = margin_cells(cell, clearance);
    ((hi - lo) / cell)
        .ceil()
        .to_array()
        // Saturating: a count this large is refused by its size anyway.
        .map(|n| (n.clamp(1.0, 1e12) as usize).saturating_add(2 * margin))
}

/// Clearance in whole cells (at least one).
pub(super) fn clearance_cells(cell: f64, clearance: f64) -> usize {
    (clearance / cell).ceil().clamp(1.0, 1e12) as usize
}

fn margin_cells(cell: f64, clearance: f64) -> usize {
    clearance_cells(cell, clearance) + MARGIN_CELLS
}

fn cell_count(dims: [usize; 3]) -> u64 {
    dims.iter()
        .fold(1u64, |product, &n| product.saturating_mul(n as u64))
}

/// Refuse a grid over [`MAX_GRID_CELLS`] or the memory left (less `reserved`,
/// bytes about to be allocated besides), naming a voxel size that fits.
/// Returns the grid's bytes.
pub(super) fn check_grid(
    mesh: &TriMesh,
    dims: [usize; 3],
    cell: f64,
    clearance: f64,
    reserved: u64,
) -> Result<u64, AutoCageError> {
    let cells = cell_count(dims);
    let bytes = bytes_for(cells, CELL_BYTES);
    let diagonal = mesh.diagonal();
    let suggest = |limit: u64| {
        let mut larger = cell * (cells as f64 / limit.max(1) as f64).cbrt().max(1.0);
        while cell_count(grid_dims(mesh, larger, clearance)) > limit && larger < diagonal {
            larger *= 1.1;
        }
        round_up(larger / diagonal)
    };
    if cells > MAX_GRID_CELLS {
        return Err(AutoCageError::GridTooLarge {
            dims,
            bytes,
            suggested: suggest(MAX_GRID_CELLS),
        });
    }
    check_memory(
        || {
            format!(
                "the voxel grid ({} × {} × {} cells)",
                dims[0], dims[1], dims[2]
            )
        },
        bytes.saturating_add(reserved),
    )
    .map_err(|limit| {
        // Half what is left: the rest of the generation needs room too.
        let fits = limit.available.unwrap_or(0).saturating_sub(reserved) / CELL_BYTES / 2;
        AutoCageError::NotEnoughMemory {
            advice: format!(
                "a voxel size of {} of the diagonal or more would fit",
                short(suggest(fits))
            ),
            limit,
        }
    })?;
    Ok(bytes)
}

/// Refuse simplifying a voxel surface of `vertices` vertices that would not fit.
pub(super) fn check_surface(vertices: u64, cell: f64, diagonal: f64) -> Result<(), AutoCageError> {
    check_memory(
        || {
            format!(
                "simplifying the voxel surface ({vertices} vertices at a voxel size of {} of the diagonal)",
                short(cell / diagonal)
            )
        },
        bytes_for(vertices, SURFACE_VERTEX_BYTES),
    )
    .map_err(|limit| AutoCageError::NotEnoughMemory {
        advice: format!(
            "a voxel size of {} of the diagonal or more would fit",
            short(
                cell / diagonal
                    * (vertices as f64 * SURFACE_VERTEX_BYTES as f64
                        / limit.available.unwrap_or(1).max(1) as f64)
                        .sqrt()
                        .max(1.0)
                    * 1.1
            )
        ),
        limit,
    })
}

/// How many points [`super::measure::surface_samples`] makes at `spacing`.
pub(super) fn sample_count(mesh: &TriMesh, spacing: f64) -> u64 {
    let interior: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let n = lattice_divisions([a, b, c], spacing);
            // Rows 1..n hold n - i + 1 points each, plus n - 1 on the last edge.
            if n < 2.0 {
                0.0
            } else {
                n * (n + 1.0) / 2.0 + n - 2.0
            }
        })
        .sum();
    (mesh.positions.len() as f64 + interior).min(u64::MAX as f64) as u64
}

/// Divisions of each edge of a face sampled at `spacing` (as a float: a tiny
/// spacing gives a count past any integer type, which is then refused).
pub(super) fn lattice_divisions([a, b, c]: [DVec3; 3], spacing: f64) -> f64 {
    let longest = a.distance(b).max(b.distance(c)).max(c.distance(a));
    (longest / spacing).ceil()
}

/// The smallest clearance (a fraction of the diagonal, from `from` up) whose
/// samples besides the vertices number at most `limit`.
fn suggested_clearance(mesh: &TriMesh, from: f64, limit: u64) -> f64 {
    let diagonal = mesh.diagonal();
    let vertices = mesh.positions.len() as u64;
    let extra =
        |fraction: f64| sample_count(mesh, 0.5 * fraction * diagonal).saturating_sub(vertices);
    // Samples fall about as the inverse square of the spacing.
    let mut fraction = from * (extra(from) as f64 / limit.max(1) as f64).sqrt().max(1.0);
    while extra(fraction) > limit && fraction < 0.5 {
        fraction *= 1.1;
    }
    // Two significant digits, rounded up so that it still fits.
    round_up(fraction)
}

/// `value` rounded up to two significant digits, as the f64 nearest that
/// decimal, so that it prints as written (0.00076, not 0.0007600000000000001).
fn round_up(value: f64) -> f64 {
    let exponent = value.log10().floor() as i32 - 1;
    let digits = (value / 10f64.powi(exponent)).ceil();
    format!("{digits}e{exponent}").parse().unwrap_or(value)
}

/// A fraction rounded up to two significant digits, as a message shows it.
fn short(value: f64) -> String {
    round_up(value).to_string()
}

#[cfg(test)]
mod tests {
    use super::round_up;

    #[test]
    fn suggestions_are_rounded_up_and_print_as_written() {
        assert_eq!(round_up(0.000_751).to_string(), "0.00076");
        assert_eq!(round_up(0.3).to_string(), "0.3");
        assert_eq!(round_up(0.2901).to_string(), "0.3");
        assert_eq!(round_up(12.3).to_string(), "13");
        assert!(round_up(0.1234) >= 0.1234);
    }
}
