//! The boundary of a voxel set as a closed triangle surface: every face between
//! an inside cell and an empty one becomes two triangles facing the empty side.
//! The set is well-composed, so each lattice corner can be one vertex.

use super::voxels::Voxels;
use glam::DVec3;
use std::collections::HashMap;

pub(super) struct Surface {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

pub(super) fn boundary_surface(voxels: &Voxels) -> Surface {
    let [nx, ny, nz] = voxels.dims;
    let inside = |x: isize, y: isize, z: isize| {
        x >= 0
            && y >= 0
            && z >= 0
            && (x as usize) < nx
            && (y as usize) < ny
            && (z as usize) < nz
            && voxels.inside[x as usize + nx * (y as usize + ny * z as usize)]
    };
    let mut corner_ids: HashMap<[isize; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut corner = |p: [isize; 3]| -> u32 {
        *corner_ids.entry(p).or_insert_with(|| {
            positions.push(
                voxels.origin + DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) * voxels.cell,
            );
            (positions.len() - 1) as u32
        })
    };
    for z in -1..nz as isize {
        for y in -1..ny as isize {
            for x in -1..nx as isize {
                let here = inside(x, y, z);
                for axis in 0..3 {
                    let mut next = [x, y, z];
                    next[axis] += 1;
                    let there = inside(next[0], next[1], next[2]);
                    if here == there {
                        continue;
                    }
                    // The shared face lies at next[axis]; with b, c the two other
                    // axes in cyclic order, e_b × e_c = e_axis.
                    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
                    let at = |db: isize, dc: isize| {
                        let mut p = next;
                        p[b] += db;
                        p[c] += dc;
                        p
                    };
                    let mut quad = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)];
                    if there {
                        // Inside on the far side: face the other way.
                        quad.reverse();
                    }
                    let ids = quad.map(&mut corner);
                    triangles.push([ids[0], ids[1], ids[2]]);
                    triangles.push([ids[0], ids[2], ids[3]]);
                }
            }
        }
    }
    Surface {
        positions,
        triangles,
    }
}
