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

/// How many cell faces lie between an inside cell and an empty one: the voxel
/// surface has as many vertices (plus two per shell) and twice as many triangles.
pub(super) fn boundary_face_count(voxels: &Voxels) -> usize {
    let mut count = 0;
    for_each_boundary_face(voxels, |_, _, _| count += 1);
    count
}

/// The boundary of `voxels`, which has `faces` boundary faces.
pub(super) fn boundary_surface(voxels: &Voxels, faces: usize) -> Surface {
    let mut corner_ids: HashMap<[isize; 3], u32> = HashMap::with_capacity(faces + 16);
    let mut positions = Vec::with_capacity(faces + 16);
    let mut triangles = Vec::with_capacity(2 * faces);
    for_each_boundary_face(voxels, |next, axis, there| {
        let mut corner = |p: [isize; 3]| -> u32 {
            *corner_ids.entry(p).or_insert_with(|| {
                positions.push(
                    voxels.origin + DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) * voxels.cell,
                );
                (positions.len() - 1) as u32
            })
        };
        // The shared face lies at next[axis]; with b, c the two other axes in
        // cyclic order, e_b × e_c = e_axis.
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
    });
    Surface {
        positions,
        triangles,
    }
}

/// Calls `face(next, axis, there)` for each face between cells that differ,
/// where `next` is the cell past the face along `axis` and `there` whether it
/// is the inside one.
fn for_each_boundary_face(voxels: &Voxels, mut face: impl FnMut([isize; 3], usize, bool)) {
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
    for z in -1..nz as isize {
        for y in -1..ny as isize {
            for x in -1..nx as isize {
                let here = inside(x, y, z);
                for axis in 0..3 {
                    let mut next = [x, y, z];
                    next[axis] += 1;
                    let there = inside(next[0], next[1], next[2]);
                    if here != there {
                        face(next, axis, there);
                    }
                }
            }
        }
    }
}
