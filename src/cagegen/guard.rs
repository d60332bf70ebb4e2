//! Spatial hashing of the simplified surface's triangles and vertices, for the
//! checks that keep a collapse from making the cage cross itself or swallow
//! another of its parts.

use glam::DVec3;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Items (triangle or vertex indices) filed under every cell their box touches.
/// Entries go stale as the surface changes; callers check what they get back.
pub(super) struct SpatialHash {
    cell: f64,
    cells: HashMap<[i32; 3], Vec<u32>, BuildHasherDefault<CellHasher>>,
    /// Entries filed, stale ones included.
    entries: usize,
}

impl SpatialHash {
    pub(super) fn new(cell: f64) -> SpatialHash {
        SpatialHash {
            cell,
            cells: HashMap::default(),
            entries: 0,
        }
    }

    pub(super) fn cell_size(&self) -> f64 {
        self.cell
    }

    pub(super) fn entries(&self) -> usize {
        self.entries
    }

    fn key(&self, p: DVec3) -> [i32; 3] {
        (p / self.cell).floor().as_ivec3().to_array()
    }

    pub(super) fn insert(&mut self, item: u32, lo: DVec3, hi: DVec3) {
        let (a, b) = (self.key(lo), self.key(hi));
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    self.cells.entry([x, y, z]).or_default().push(item);
                    self.entries += 1;
                }
            }
        }
    }

    /// Every live item filed in a cell that the box touches, each once
    /// (using `seen`, a per-item stamp array, and `stamp`, a value not used
    /// before). Items no longer `alive` are dropped from the cells visited:
    /// a collapse leaves its old faces' entries behind, and between rebuilds
    /// they were most of what a query read.
    pub(super) fn query(
        &mut self,
        (lo, hi): (DVec3, DVec3),
        alive: &[bool],
        (seen, stamp): (&mut [u32], u32),
        out: &mut Vec<u32>,
    ) {
        out.clear();
        let (a, b) = (self.key(lo), self.key(hi));
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    if let Some(items) = self.cells.get_mut(&[x, y, z]) {
                        let before = items.len();
                        items.retain(|&item| alive[item as usize]);
                        self.entries -= before - items.len();
                        for &item in items.iter() {
                            if seen[item as usize] != stamp {
                                seen[item as usize] = stamp;
                                out.push(item);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Six times the signed volume of the tetrahedron (a, b, c, d).
pub(super) fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    (b - a).cross(c - a).dot(d - a)
}

/// Whether `p` lies strictly inside the tetrahedron (apex, a, b, c), with
/// `tolerance` on the six-fold volumes.
pub(super) fn inside_tetrahedron(
    p: DVec3,
    apex: DVec3,
    [a, b, c]: [DVec3; 3],
    tolerance: f64,
) -> bool {
    let total = orient(apex, a, b, c);
    if total.abs() <= tolerance {
        return false;
    }
    let sign = total.signum();
    [
        orient(p, a, b, c),
        orient(apex, p, b, c),
        orient(apex, a, p, c),
        orient(apex, a, b, p),
    ]
    .iter()
    .all(|&v| v * sign > tolerance)
}

/// Smallest interior angle of a triangle, in radians.
pub(super) fn min_angle([a, b, c]: [DVec3; 3]) -> f64 {
    let angle = |p: DVec3, q: DVec3, r: DVec3| (q - p).angle_between(r - p);
    let (x, y) = (angle(a, b, c), angle(b, c, a));
    x.min(y).min(std::f64::consts::PI - x - y)
}

/// A multiply-and-rotate hash for cell keys: the keys are not chosen by an
/// adversary, and the default hasher was a tenth of the simplification's time.
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(4) {
            let mut word = [0u8; 4];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u32(u32::from_le_bytes(word));
        }
    }

    fn write_u32(&mut self, value: u32) {
        self.0 = (self.0.rotate_left(5) ^ u64::from(value)).wrapping_mul(0x517c_c1b7_2722_0a95);
    }

    fn write_usize(&mut self, value: usize) {
        self.write_u32(value as u32);
    }
}
