//! The inside of the mesh as voxels: the cells its surface passes through, plus
//! the cells whose centre has a winding number above one half; then dilated by
//! the clearance, with cavities filled and made well-composed so that the
//! boundary of the cell set is a 2-manifold.

use super::plan::lattice_divisions;
use super::winding::TriangleTree;
use crate::geometry::TriMesh;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::{BTreeSet, VecDeque};
use std::sync::atomic::{AtomicBool, Ordering};

/// A box of cells of side `cell` starting at `origin`; `inside` holds one flag
/// per cell, x fastest.
pub(super) struct Voxels {
    pub origin: DVec3,
    pub cell: f64,
    pub dims: [usize; 3],
    pub inside: Vec<bool>,
}

impl Voxels {
    fn index(&self, x: usize, y: usize, z: usize) -> usize {
        x + self.dims[0] * (y + self.dims[1] * z)
    }

    fn coordinates(&self, index: usize) -> [usize; 3] {
        let [nx, ny, _] = self.dims;
        [index % nx, (index / nx) % ny, index / (nx * ny)]
    }

    pub(super) fn centre(&self, index: usize) -> DVec3 {
        let [x, y, z] = self.coordinates(index);
        self.origin + (DVec3::new(x as f64, y as f64, z as f64) + 0.5) * self.cell
    }

    /// The 6 face neighbours of a cell that lie in the grid.
    fn neighbours(&self, index: usize) -> impl Iterator<Item = usize> + '_ {
        let [x, y, z] = self.coordinates(index);
        let [nx, ny, nz] = self.dims;
        let steps: [(bool, isize); 6] = [
            (x > 0, -1),
            (x + 1 < nx, 1),
            (y > 0, -(nx as isize)),
            (y + 1 < ny, nx as isize),
            (z > 0, -((nx * ny) as isize)),
            (z + 1 < nz, (nx * ny) as isize),
        ];
        steps
            .into_iter()
            .filter(|(ok, _)| *ok)
            .map(move |(_, step)| (index as isize + step) as usize)
    }

    fn on_border(&self, index: usize) -> bool {
        let [x, y, z] = self.coordinates(index);
        let [nx, ny, nz] = self.dims;
        x == 0 || y == 0 || z == 0 || x + 1 == nx || y + 1 == ny || z + 1 == nz
    }
}

/// Voxelise the inside of `mesh` in a grid of `cell`-sized cells with `margin`
/// empty cells around its bounds (`dims`, predicted and checked by the caller).
/// `progress` gets fractions of this stage. For an `open` mesh, also returns
/// its winding-number volume inside its bounding box.
pub(super) fn voxelise(
    mesh: &TriMesh,
    tree: &TriangleTree,
    (cell, margin, dims): (f64, usize, [usize; 3]),
    open: bool,
    progress: &dyn Fn(f32) -> bool,
) -> Option<(Voxels, Option<f64>)> {
    let (lo, _) = mesh.bounds();
    let origin = lo - DVec3::splat(margin as f64 * cell);
    let mut voxels = Voxels {
        origin,
        cell,
        dims,
        inside: vec![false; dims[0] * dims[1] * dims[2]],
    };
    mark_surface(mesh, &mut voxels);
    if !progress(0.3) {
        return None;
    }
    let surface = open.then(|| voxels.inside.clone());
    classify_empty_cells(&mut voxels, tree, &|f| progress(0.3 + 0.6 * f))?;
    let volume = surface.map(|surface| winding_volume(mesh, &voxels, &surface, tree));
    progress(1.0).then_some((voxels, volume))
}

/// Mark every cell the surface passes through, by sampling each triangle at a
/// third of a cell. A cell missed at a corner is within a cell of a marked
/// one, so the dilation that follows still covers it. The marks go straight
/// into the grid, so memory does not grow with the faces' sizes.
fn mark_surface(mesh: &TriMesh, voxels: &mut Voxels) {
    let step = voxels.cell / 3.0;
    // Points no face uses are enclosed too.
    for &p in &mesh.positions {
        let index = cell_of(voxels, p);
        voxels.inside[index] = true;
    }
    let marks: Vec<AtomicBool> = voxels.inside.iter().map(|&b| AtomicBool::new(b)).collect();
    let [nx, ny, nz] = voxels.dims;
    // In cell units from the origin, where truncation is the floor (clamped
    // to the grid): `floor` is a library call, and this runs per sample.
    let to_cells = |p: DVec3| (p - voxels.origin) / voxels.cell;
    let clamp = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
    mesh.triangles.par_iter().for_each(|t| {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let n = lattice_divisions([a, b, c], step).max(1.0) as usize;
        let a = to_cells(a);
        let (step_b, step_c) = ((to_cells(b) - a) / n as f64, (to_cells(c) - a) / n as f64);
        for i in 0..=n {
            let row = a + step_b * i as f64;
            for j in 0..=n - i {
                let p = row + step_c * j as f64;
                let index = clamp(p.x, nx) + nx * (clamp(p.y, ny) + ny * clamp(p.z, nz));
                marks[index].store(true, Ordering::Relaxed);
            }
        }
    });
    for (inside, mark) in voxels.inside.iter_mut().zip(marks) {
        *inside = mark.into_inner();
    }
}

/// Samples of the winding number over the cells the surface passes through,
/// for the volume of an open mesh: enough for a percent or so.
const VOLUME_SAMPLES: usize = 1024;

/// The volume inside an open mesh's bounding box where its winding number is
/// over one half: the decided empty cells, and the surface cells in the
/// proportion a strided sample of them is inside. An open mesh has no volume
/// of its own, and stacked sheets none at all; this one never exceeds the box.
fn winding_volume(mesh: &TriMesh, voxels: &Voxels, surface: &[bool], tree: &TriangleTree) -> f64 {
    let (lo, hi) = mesh.bounds();
    let in_box = |i: usize| {
        let c = voxels.centre(i);
        c.cmpge(lo).all() && c.cmple(hi).all()
    };
    let empty_inside = (0..surface.len())
        .filter(|&i| !surface[i] && voxels.inside[i] && in_box(i))
        .count();
    let surface_cells = (0..surface.len())
        .filter(|&i| surface[i] && in_box(i))
        .count();
    let stride = (surface_cells / VOLUME_SAMPLES).max(1);
    let sampled: Vec<usize> = (0..surface.len())
        .filter(|&i| surface[i] && in_box(i))
        .step_by(stride)
        .collect();
    let inside = sampled
        .par_iter()
        .filter(|&&i| tree.winding_number(voxels.centre(i)).abs() > 0.5)
        .count();
    let fraction = inside as f64 / sampled.len().max(1) as f64;
    (empty_inside as f64 + fraction * surface_cells as f64) * voxels.cell.powi(3)
}

impl Voxels {
    /// Whether `p` lies in a cell outside the set (or beyond the grid).
    pub(super) fn is_outside(&self, p: DVec3) -> bool {
        let c = ((p - self.origin) / self.cell).floor();
        let beyond = (0..3).any(|k| c[k] < 0.0 || c[k] >= self.dims[k] as f64);
        beyond || !self.inside[cell_of(self, p)]
    }
}

fn cell_of(voxels: &Voxels, p: DVec3) -> usize {
    let c = ((p - voxels.origin) / voxels.cell).floor();
    let clamp = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
    voxels.index(
        clamp(c.x, voxels.dims[0]),
        clamp(c.y, voxels.dims[1]),
        clamp(c.z, voxels.dims[2]),
    )
}

/// Decide the cells the surface does not touch by winding number. Such cells
/// form regions bounded by surface cells; in a closed mesh each region is all
/// inside or all outside, so a few samples decide it. A region whose samples
/// disagree (an open mesh's inside leaking through a hole) is decided cell by
/// cell.
fn classify_empty_cells(
    voxels: &mut Voxels,
    tree: &TriangleTree,
    progress: &dyn Fn(f32) -> bool,
) -> Option<()> {
    const SAMPLES: usize = 24;
    let mut region = vec![u32::MAX; voxels.inside.len()];
    let mut regions: Vec<Vec<usize>> = Vec::new();
    let total = voxels.inside.len().max(1);
    let mut labelled = 0usize;
    for start in 0..voxels.inside.len() {
        if voxels.inside[start] || region[start] != u32::MAX {
            continue;
        }
        let id = regions.len() as u32;
        let mut cells = vec![start];
        region[start] = id;
        let mut next = 0;
        while next < cells.len() {
            let index = cells[next];
            next += 1;
            // Filling a fine grid's outside takes long: report it by the
            // percent of cells, as the first half of this stage.
            if next.is_multiple_of(1 << 20)
                && !progress(0.5 * (labelled + next) as f32 / total as f32)
            {
                return None;
            }
            for n in voxels.neighbours(index) {
                if !voxels.inside[n] && region[n] == u32::MAX {
                    region[n] = id;
                    cells.push(n);
                }
            }
        }
        labelled += cells.len();
        regions.push(cells);
    }
    let (mut done, mut reported) = (0usize, 0usize);
    for cells in regions {
        done += cells.len();
        // Reported by the percent: pockets between faces can be many.
        if done * 100 / total > reported {
            reported = done * 100 / total;
            if !progress(0.5 + 0.5 * done as f32 / total as f32) {
                return None;
            }
        }
        let stride = (cells.len() / SAMPLES).max(1);
        let samples: Vec<f64> = cells
            .par_iter()
            .step_by(stride)
            .map(|&i| tree.winding_number(voxels.centre(i)))
            .collect();
        let all_inside = samples.iter().all(|&w| w.abs() > 0.5);
        let all_outside = samples.iter().all(|&w| w.abs() <= 0.5);
        let inside: Vec<usize> = if all_inside {
            cells
        } else if all_outside {
            Vec::new()
        } else {
            cells
                .par_iter()
                .copied()
                .filter(|&i| tree.winding_number(voxels.centre(i)).abs() > 0.5)
                .collect()
        };
        for index in inside {
            voxels.inside[index] = true;
        }
    }
    Some(())
}

/// Grow the set by `radius` cells in every direction (a cube, so that every
/// point outside is at least `radius` cells from the original set).
pub(super) fn dilate(voxels: &mut Voxels, radius: usize) {
    let dims = voxels.dims;
    let strides = [1, dims[0], dims[0] * dims[1]];
    for axis in 0..3 {
        let length = dims[axis];
        let stride = strides[axis];
        let mut next = voxels.inside.clone();
        // The first cell of every line of cells along the axis.
        let [u, v] = [(axis + 1) % 3, (axis + 2) % 3];
        let starts =
            (0..dims[v]).flat_map(|j| (0..dims[u]).map(move |i| i * strides[u] + j * strides[v]));
        for start in starts {
            // Sliding count of set cells in the window [i - radius, i + radius].
            let at = |i: usize| voxels.inside[start + i * stride] as usize;
            let mut count: usize = (0..radius.min(length)).map(at).sum();
            for i in 0..length {
                if i + radius < length {
                    count += at(i + radius);
                }
                if i > radius {
                    count -= at(i - radius - 1);
                }
                next[start + i * stride] = count > 0;
            }
        }
        voxels.inside = next;
    }
}

/// Make cavities (empty regions that do not reach the grid's border) inside:
/// the cage is a solid around the mesh.
pub(super) fn fill_cavities(voxels: &mut Voxels) {
    let mut outside = vec![false; voxels.inside.len()];
    let mut queue: VecDeque<usize> = (0..voxels.inside.len())
        .filter(|&i| voxels.on_border(i) && !voxels.inside[i])
        .collect();
    for &i in &queue {
        outside[i] = true;
    }
    while let Some(index) = queue.pop_front() {
        for n in voxels.neighbours(index) {
            if !voxels.inside[n] && !outside[n] {
                outside[n] = true;
                queue.push_back(n);
            }
        }
    }
    for (inside, outside) in voxels.inside.iter_mut().zip(outside) {
        *inside = !outside;
    }
}

/// Add cells until no two cells of the same kind (inside or empty) meet only
/// along an edge or at a corner with both cells of the other kind between them.
/// Such a set is well-composed, and the faces between inside and empty cells
/// form a 2-manifold. Only inside cells are added, so containment is kept.
///
/// Blocks are filled in raster order, pass after pass, until a pass fills
/// none. After the first pass only blocks with a cell filled since they were
/// last looked at can have changed, so only they are looked at again, still
/// in raster order: the same cells are filled as by whole passes, which went
/// over every block at least twice.
pub(super) fn make_well_composed(voxels: &mut Voxels) {
    let [nx, ny, nz] = voxels.dims;
    if nx < 2 || ny < 2 || nz < 2 {
        return;
    }
    let blocks = Blocks::new(voxels.dims);
    let mut again = BTreeSet::new();
    for z in 0..nz - 1 {
        for y in 0..ny - 1 {
            let row = voxels.index(0, y, z);
            for first in row..row + nx - 1 {
                // Blocks after this one are looked at in this pass anyway.
                blocks.fill_if_critical(voxels, first, |block| {
                    if block < first {
                        again.insert(block);
                    }
                });
            }
        }
    }
    while !again.is_empty() {
        let mut pass = std::mem::take(&mut again);
        while let Some(first) = pass.pop_first() {
            blocks.fill_if_critical(voxels, first, |block| {
                if block > first {
                    pass.insert(block);
                } else {
                    again.insert(block);
                }
            });
        }
    }
}

/// The 2×2×2 blocks of cells, named by their first cell.
struct Blocks {
    dims: [usize; 3],
    /// Corner k of a block at offset (k&1, k>>1&1, k>>2&1) from its first cell.
    offsets: [usize; 8],
    /// Whether each of the 256 blocks (bit k for corner k) is critical.
    critical: [bool; 256],
}

impl Blocks {
    fn new(dims: [usize; 3]) -> Blocks {
        let [nx, ny, _] = dims;
        Blocks {
            dims,
            offsets: std::array::from_fn(|k| (k & 1) + nx * (((k >> 1) & 1) + ny * ((k >> 2) & 1))),
            critical: std::array::from_fn(|bits| {
                block_is_critical(&std::array::from_fn(|k| bits >> k & 1 == 1))
            }),
        }
    }

    /// Fill the block at `first` if it is critical, and name to `touched`
    /// every other block holding a cell that this filled.
    fn fill_if_critical(&self, voxels: &mut Voxels, first: usize, mut touched: impl FnMut(usize)) {
        let bits = (0..8).fold(0usize, |bits, k| {
            bits | usize::from(voxels.inside[first + self.offsets[k]]) << k
        });
        if !self.critical[bits] {
            return;
        }
        let [nx, ny, nz] = self.dims;
        for k in (0..8).filter(|k| bits >> k & 1 == 0) {
            let cell = first + self.offsets[k];
            voxels.inside[cell] = true;
            let [x, y, z] = voxels.coordinates(cell);
            for (dx, dy, dz) in (0..8).map(|j| (j & 1, (j >> 1) & 1, (j >> 2) & 1)) {
                let inside_grid = x >= dx && y >= dy && z >= dz;
                if inside_grid && x - dx + 1 < nx && y - dy + 1 < ny && z - dz + 1 < nz {
                    let block = voxels.index(x - dx, y - dy, z - dz);
                    if block != first {
                        touched(block);
                    }
                }
            }
        }
    }
}

/// Whether a 2×2×2 block (corner k at offset (k&1, k>>1&1, k>>2&1)) holds an
/// edge-only or corner-only contact.
fn block_is_critical(cells: &[bool; 8]) -> bool {
    // The six 2×2 faces of the block: a diagonal pair of one kind and the other
    // pair of the other kind is an edge-only contact.
    const FACES: [[usize; 4]; 6] = [
        [0, 1, 2, 3],
        [4, 5, 6, 7],
        [0, 1, 4, 5],
        [2, 3, 6, 7],
        [0, 2, 4, 6],
        [1, 3, 5, 7],
    ];
    for [a, b, c, d] in FACES {
        // Corners a, b, c, d are laid out as a 2×2 square: a-d and b-c are the
        // diagonals.
        if cells[a] == cells[d] && cells[b] == cells[c] && cells[a] != cells[b] {
            return true;
        }
    }
    // Opposite corners of one kind with all six others of the other kind.
    for k in 0..4 {
        let opposite = 7 - k;
        let kind = cells[k];
        if cells[opposite] == kind
            && (0..8)
                .filter(|&j| j != k && j != opposite)
                .all(|j| cells[j] != kind)
        {
            return true;
        }
    }
    false
}

/// Where the cage may go: cells within `limit` cells of the mesh's inside.
/// Raising the limit trades tightness for fewer vertices; keeping it below half
/// a gap keeps the parts on either side apart.
pub(super) struct Envelope {
    pub origin: DVec3,
    pub cell: f64,
    pub dims: [usize; 3],
    pub distance: Vec<u16>,
    pub limit: u16,
}

impl Envelope {
    /// Whether the cell holding `p`, in cell units from the origin, is allowed.
    fn allows_cell_point(&self, p: DVec3) -> bool {
        // Truncation is the floor for the non-negative; `floor` itself is a
        // library call here, and this runs for every sample of every face.
        if p.x < 0.0 || p.y < 0.0 || p.z < 0.0 {
            return false;
        }
        let [x, y, z] = [p.x as usize, p.y as usize, p.z as usize];
        let [nx, ny, nz] = self.dims;
        x < nx && y < ny && z < nz && self.distance[x + nx * (y + ny * z)] <= self.limit
    }

    /// Every point of the triangle, sampled at half a cell, is allowed: a band
    /// of forbidden cells is at least a cell wide, so no sample skips it.
    pub(super) fn allows_triangle(&self, [a, b, c]: [DVec3; 3]) -> bool {
        let longest = a.distance(b).max(b.distance(c)).max(c.distance(a));
        let n = (2.0 * longest / self.cell).ceil().max(1.0) as usize;
        let to_cells = |p: DVec3| (p - self.origin) / self.cell;
        let a = to_cells(a);
        let (step_b, step_c) = ((to_cells(b) - a) / n as f64, (to_cells(c) - a) / n as f64);
        (0..=n).all(|i| {
            let row = a + step_b * i as f64;
            (0..=n - i).all(|j| self.allows_cell_point(row + step_c * j as f64))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::procedural::SplitMix64;

    fn random_voxels(dims: [usize; 3], density: f64, random: &mut SplitMix64) -> Voxels {
        let count = dims[0] * dims[1] * dims[2];
        Voxels {
            origin: DVec3::ZERO,
            cell: 1.0,
            dims,
            inside: (0..count).map(|_| random.unit() < density).collect(),
        }
    }

    /// Whole passes over every block until one fills none, as written first.
    fn well_composed_by_whole_passes(voxels: &mut Voxels) {
        let [nx, ny, nz] = voxels.dims;
        loop {
            let mut changed = false;
            for z in 0..nz - 1 {
                for y in 0..ny - 1 {
                    for x in 0..nx - 1 {
                        let block: [usize; 8] = std::array::from_fn(|k| {
                            voxels.index(x + (k & 1), y + ((k >> 1) & 1), z + ((k >> 2) & 1))
                        });
                        if block_is_critical(&block.map(|i| voxels.inside[i])) {
                            block.iter().for_each(|&i| voxels.inside[i] = true);
                            changed = true;
                        }
                    }
                }
            }
            if !changed {
                return;
            }
        }
    }

    #[test]
    fn looking_again_only_where_cells_were_filled_fills_the_same_cells() {
        let mut random = SplitMix64(17);
        let mut filled_in_all = 0;
        for (dims, density) in [([9, 8, 7], 0.3), ([6, 12, 5], 0.5), ([16, 3, 9], 0.15)] {
            let mut fast = random_voxels(dims, density, &mut random);
            let mut plain = Voxels {
                inside: fast.inside.clone(),
                ..fast
            };
            let before = plain.inside.iter().filter(|&&b| b).count();
            make_well_composed(&mut fast);
            well_composed_by_whole_passes(&mut plain);
            assert_eq!(fast.inside, plain.inside, "{dims:?}");
            filled_in_all += plain.inside.iter().filter(|&&b| b).count() - before;
        }
        // Random sets have critical blocks, filled over more than one pass.
        assert!(filled_in_all > 50, "{filled_in_all}");
    }

    #[test]
    fn dilation_reaches_every_cell_within_the_radius() {
        let mut random = SplitMix64(23);
        let dims = [11, 7, 9];
        let original = random_voxels(dims, 0.02, &mut random);
        let [nx, ny, _] = dims;
        let at = |i: usize| [i % nx, (i / nx) % ny, i / (nx * ny)];
        for radius in [1, 2] {
            let mut grown = Voxels {
                inside: original.inside.clone(),
                ..original
            };
            dilate(&mut grown, radius);
            for cell in 0..grown.inside.len() {
                let near = (0..original.inside.len()).any(|s| {
                    original.inside[s] && (0..3).all(|k| at(cell)[k].abs_diff(at(s)[k]) <= radius)
                });
                assert_eq!(
                    grown.inside[cell],
                    near,
                    "cell {:?}, radius {radius}",
                    at(cell)
                );
            }
        }
    }
}
