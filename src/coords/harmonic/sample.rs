//! Harmonic coordinates at the mesh vertices: trilinear interpolation of the
//! vertex's grid cell. A corner outside the cage has no unknown; it takes the
//! boundary data at its closest point on the cage (hat values on a triangle, the
//! bilinear basis on a quad's patch: the boundary data, carried outwards),
//! which keeps every row non-negative and summing to one.

use super::grid::{Level, NONE};
use super::patches::closest_boundary_value;
use crate::coords::Weights;
use crate::geometry::{Cage, PointClass};
use glam::DVec3;
use rayon::prelude::*;
use std::collections::HashMap;

/// Negative values above this are the solver's tolerance (2·10⁻⁷ relative).
const SOLVER_ROUNDING: f32 = 1e-6;

/// Where a cell corner's values come from.
#[derive(Clone, Copy, Debug)]
enum Corner {
    /// An unknown of the finest level.
    Unknown(u32),
    /// Boundary data at a cage point: an index into [`Sampler::hats`].
    Hat(u32),
}

/// Per inside point, its eight corners and their trilinear weights.
pub(in crate::coords) struct Sampler {
    rows: Vec<(usize, [(Corner, f32); 8])>,
    /// Cage vertices and their boundary values, per outside corner used.
    hats: Vec<([u32; 4], [f32; 4])>,
}

impl Sampler {
    pub fn new(cage: &Cage, level: &Level, points: &[DVec3], classes: &[PointClass]) -> Sampler {
        let frame = &level.frame;
        let cells: Vec<(usize, [(usize, f32); 8])> = points
            .par_iter()
            .zip(classes)
            .enumerate()
            .filter(|(_, (_, class))| matches!(class, PointClass::Inside))
            .map(|(row, (&x, _))| {
                let q = (x - frame.origin) / frame.h;
                let mut cell = [0usize; 3];
                let mut t = [0.0f64; 3];
                for axis in 0..3 {
                    let top = frame.dims[axis] - 2;
                    let c = q[axis].floor().clamp(0.0, top as f64);
                    cell[axis] = c as usize;
                    t[axis] = (q[axis] - c).clamp(0.0, 1.0);
                }
                let mut corners = [(0usize, 0.0f32); 8];
                for (k, corner) in corners.iter_mut().enumerate() {
                    let offset = [k & 1, (k >> 1) & 1, (k >> 2) & 1];
                    let mut weight = 1.0;
                    let mut node = cell;
                    for axis in 0..3 {
                        node[axis] += offset[axis];
                        weight *= if offset[axis] == 1 {
                            t[axis]
                        } else {
                            1.0 - t[axis]
                        };
                    }
                    *corner = (frame.index(node), weight as f32);
                }
                (row, corners)
            })
            .collect();
        // Outside corners, each resolved once.
        let mut outside: Vec<usize> = cells
            .iter()
            .flat_map(|(_, corners)| corners.iter().map(|&(node, _)| node))
            .filter(|&node| level.unknown_of[node] == NONE)
            .collect();
        outside.sort_unstable();
        outside.dedup();
        let hats: Vec<([u32; 4], [f32; 4])> = outside
            .par_iter()
            .map(|&node| {
                let position = frame.position(frame.coordinates(node));
                let value = closest_boundary_value(cage, position);
                (value.corners, value.values.map(|w| w as f32))
            })
            .collect();
        let hat_of: HashMap<usize, u32> = outside
            .iter()
            .enumerate()
            .map(|(k, &node)| (node, k as u32))
            .collect();
        let rows = cells
            .into_iter()
            .map(|(row, corners)| {
                let corners = corners.map(|(node, weight)| {
                    let unknown = level.unknown_of[node];
                    let source = if unknown == NONE {
                        Corner::Hat(hat_of[&node])
                    } else {
                        Corner::Unknown(unknown)
                    };
                    (source, weight)
                });
                (row, corners)
            })
            .collect();
        Sampler { rows, hats }
    }

    /// Write columns `first..first + width` of every inside row from the solution
    /// `x` of that block (`width` values per unknown).
    pub fn write_block(&self, x: &[f32], first: usize, width: usize, weights: &mut Weights) {
        let columns = weights.cols;
        let columns_of_block = first..first + width;
        // Rows are distinct, so each row's slice is written by one task.
        let row_slices: HashMap<usize, usize> = self
            .rows
            .iter()
            .enumerate()
            .map(|(k, (row, _))| (*row, k))
            .collect();
        weights
            .values
            .par_chunks_mut(columns.max(1))
            .enumerate()
            .for_each(|(row, out)| {
                let Some(&k) = row_slices.get(&row) else {
                    return;
                };
                let out = &mut out[columns_of_block.clone()];
                out.fill(0.0);
                for &(source, weight) in &self.rows[k].1 {
                    if weight == 0.0 {
                        continue;
                    }
                    match source {
                        Corner::Unknown(unknown) => {
                            let values = &x[unknown as usize * width..][..width];
                            for (out, &value) in out.iter_mut().zip(values) {
                                *out += weight * value;
                            }
                        }
                        Corner::Hat(index) => {
                            let (corners, values) = self.hats[index as usize];
                            for (&corner, &value) in corners.iter().zip(&values) {
                                let corner = corner as usize;
                                if value != 0.0 && columns_of_block.contains(&corner) {
                                    out[corner - first] += weight * value;
                                }
                            }
                        }
                    }
                }
                // The exact solution is non-negative (maximum principle); what the
                // iteration leaves below zero is its tolerance, not a weight to show.
                for value in out.iter_mut() {
                    if (-SOLVER_ROUNDING..0.0).contains(value) {
                        *value = 0.0;
                    }
                }
            });
    }
}
