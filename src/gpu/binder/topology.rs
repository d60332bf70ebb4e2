//! The cage as the binding kernels read it: primitive corners and the vertex →
//! incident-corner table in one buffer, and the parameters that locate them.

use crate::geometry::Cage;
use crate::gpu::kernels::{Kernel, Params, BAND_TEXELS};

/// The fourth corner slot of a triangle among patches (`NO_CORNER` in
/// shaders/shared/pmvc_patches.wgsl).
const NO_CORNER: u32 = u32::MAX;

/// The cage's primitives as one kernel reads them.
pub(super) struct Topology {
    /// Corners of each primitive, then the vertex → incident-corner CSR.
    pub words: Vec<u32>,
    pub params: Params,
    /// Corner slots per primitive: 3, or 4 where PMVC takes quads as bilinear
    /// patches (the quad pipeline, `CORNERS` in shaders/bind_pmvc.wgsl).
    pub corners: usize,
}

impl Topology {
    pub fn primitives(&self) -> usize {
        self.params.triangle_count as usize
    }
}

/// The kernel's view of `cage`: its triangles, or for PMVC on a cage with quads
/// its lone triangles (fourth slot [`NO_CORNER`]) and then its quads.
pub(super) fn topology(cage: &Cage, kernel: Kernel, resolution: u32, rows: usize) -> Topology {
    let patches = kernel == Kernel::Pmvc && cage.has_quads();
    let (corners, mut words): (usize, Vec<u32>) = if patches {
        let lone = cage
            .lone_triangles()
            .map(|t| cage.triangles()[t])
            .map(|[a, b, c]| [a, b, c, NO_CORNER]);
        let quads = cage.quads().iter().map(|quad| quad.corners);
        (4, lone.chain(quads).flatten().collect())
    } else {
        (3, cage.triangles().iter().flatten().copied().collect())
    };
    let primitives = words.len() / corners;
    let vertices = cage.vertex_count();
    let offsets_at = words.len();
    let mut counts = vec![0u32; vertices + 1];
    for &corner in words.iter().filter(|&&c| c != NO_CORNER) {
        counts[corner as usize + 1] += 1;
    }
    for v in 0..vertices {
        counts[v + 1] += counts[v];
    }
    let entries = counts[vertices] as usize;
    words.extend_from_slice(&counts);
    let entries_at = words.len();
    words.resize(entries_at + entries, 0);
    let mut next = counts;
    for slot in 0..primitives * corners {
        let corner = words[slot];
        if corner != NO_CORNER {
            let at = &mut next[corner as usize];
            words[entries_at + *at as usize] = slot as u32;
            *at += 1;
        }
    }
    let texels = f64::from(resolution) * f64::from(resolution);
    let params = Params {
        point_count: rows as u32,
        triangle_count: primitives as u32,
        vertex_count: vertices as u32,
        resolution,
        band_rows: (BAND_TEXELS / resolution).max(1),
        max_missed: if kernel == Kernel::Pmvc {
            (0.01 * 6.0 * texels).floor() as u32
        } else {
            0
        },
        incidence_offsets: offsets_at as u32,
        incidence_entries: entries_at as u32,
    };
    Topology {
        words,
        params,
        corners,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::procedural_quads::{cage_from_polygons, twisted_box};
    use glam::DVec3;

    /// Every corner slot that names a vertex is listed once under that vertex.
    fn check_incidence(topology: &Topology) {
        let Params {
            incidence_offsets: offsets,
            incidence_entries: entries,
            vertex_count,
            ..
        } = topology.params;
        let words = &topology.words;
        let mut listed = 0;
        for v in 0..vertex_count {
            let (start, end) = (
                words[(offsets + v) as usize],
                words[(offsets + v + 1) as usize],
            );
            for n in start..end {
                let slot = words[(entries + n) as usize] as usize;
                assert_eq!(words[slot], v);
                listed += 1;
            }
        }
        let named = words[..topology.primitives() * topology.corners]
            .iter()
            .filter(|&&c| c != NO_CORNER)
            .count();
        assert_eq!(listed, named);
    }

    #[test]
    fn pmvc_on_quads_takes_patches_and_lone_triangles_and_the_rest_take_triangles() {
        // A square pyramid: one quad and four lone triangles.
        let positions = [
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
        ];
        let polygons = vec![
            vec![0, 3, 2, 1],
            vec![0, 1, 4],
            vec![1, 2, 4],
            vec![2, 3, 4],
            vec![3, 0, 4],
        ];
        let (pyramid, _) = cage_from_polygons(&positions, &polygons).expect("a pyramid");
        let pmvc = topology(&pyramid, Kernel::Pmvc, 8, 1);
        assert_eq!((pmvc.corners, pmvc.primitives()), (4, 5));
        assert_eq!(&pmvc.words[16..20], pyramid.quads()[0].corners.as_slice());
        assert_eq!(pmvc.words[3], NO_CORNER);
        check_incidence(&pmvc);
        for kernel in [Kernel::Mvc, Kernel::Green] {
            let triangles = topology(&pyramid, kernel, 8, 1);
            assert_eq!((triangles.corners, triangles.primitives()), (3, 6));
            check_incidence(&triangles);
        }
        let boxed = topology(&twisted_box(2.0, 0.6), Kernel::Pmvc, 8, 1);
        assert_eq!((boxed.corners, boxed.primitives()), (4, 6));
        check_incidence(&boxed);
    }
}
