//! The cage as the binding kernels read it: triangle corners and the vertex →
//! incident-corner table in one buffer, and the parameters that locate them.

use crate::geometry::Cage;
use crate::gpu::kernels::{Kernel, Params, BAND_TEXELS};

/// Triangle corners, then the vertex → incident-corner CSR, and the kernel params
/// that locate them.
pub(super) fn topology(
    cage: &Cage,
    kernel: Kernel,
    resolution: u32,
    rows: usize,
) -> (Vec<u32>, Params) {
    let triangles = cage.triangle_count();
    let vertices = cage.vertex_count();
    let mut topology: Vec<u32> = cage.triangles().iter().flatten().copied().collect();
    let offsets_at = topology.len();
    let mut counts = vec![0u32; vertices + 1];
    for &corner in cage.triangles().iter().flatten() {
        counts[corner as usize + 1] += 1;
    }
    for v in 0..vertices {
        counts[v + 1] += counts[v];
    }
    topology.extend_from_slice(&counts);
    let entries_at = topology.len();
    topology.resize(entries_at + 3 * triangles, 0);
    let mut next = counts;
    for (t, corners) in cage.triangles().iter().enumerate() {
        for (k, &corner) in corners.iter().enumerate() {
            let slot = &mut next[corner as usize];
            topology[entries_at + *slot as usize] = (3 * t + k) as u32;
            *slot += 1;
        }
    }
    let texels = f64::from(resolution) * f64::from(resolution);
    let params = Params {
        point_count: rows as u32,
        triangle_count: triangles as u32,
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
    (topology, params)
}
