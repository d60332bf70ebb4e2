//! One level of the harmonic solve's grid: where the cage crosses the grid lines,
//! which nodes are inside, and the cut-cell stencil of every inside node.
//!
//! The stencil is the symmetric cut-cell discretisation of Gibou, Fedkiw, Cheng and
//! Kang (2002): along each axis an arm to an inside neighbour has coefficient 1/h²;
//! an arm that the cage cuts at θh (0 < θ ≤ 1) ends at the crossing, where the value
//! is known (the boundary data of the crossed face), with coefficient 1/(θh²).
//! The matrix is symmetric and an M-matrix (so the discrete maximum principle holds:
//! weights are non-negative and sum to one), and a linear function is reproduced
//! exactly at every node: its two arms' terms cancel whatever θ is.
//!
//! The cage's surface is that of [`super::patches`]: on a cage with quads, its
//! lone triangles and its quads as bilinear patches, whose crossings decide
//! which nodes are inside as well as where arms are cut.

use super::patches::{closest_boundary_value, patch_line_crossings, BoundaryValue};
use crate::geometry::Cage;
use glam::{DVec2, DVec3};

/// No unknown here: the node is outside the cage, or the arm is cut.
pub(in crate::coords) const NONE: u32 = u32::MAX;
/// Arms shorter than this share of a cell are lengthened to it, bounding the
/// diagonal; the boundary then moves by at most this share of a cell.
pub(in crate::coords) const THETA_MIN: f64 = 1e-3;

/// Where a grid line crosses the cage: `s` along the line in cells from its first
/// node, and the boundary data there.
#[derive(Clone, Copy, Debug)]
pub(in crate::coords) struct Crossing {
    pub s: f64,
    pub value: BoundaryValue,
}

/// A cut arm: the unknown it belongs to, which of its arms it is (−x, +x, −y,
/// +y, −z, +z), its coefficient `1/θ`, the values at the crossing, and their
/// surface gradients' components along the arm's axis, in cells⁻¹ (what
/// bounded biharmonic weights' boundary rows read).
#[derive(Clone, Copy, Debug)]
pub(in crate::coords) struct CutArm {
    pub unknown: u32,
    pub arm: u8,
    pub coefficient: f32,
    pub corners: [u32; 4],
    pub values: [f32; 4],
    pub slopes: [f32; 4],
}

/// The grid's placement, shared by all levels (a level doubles `h`).
#[derive(Clone, Copy, Debug)]
pub(in crate::coords) struct Frame {
    pub origin: DVec3,
    pub h: f64,
    pub dims: [usize; 3],
}

impl Frame {
    pub fn node_count(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    pub fn index(&self, [x, y, z]: [usize; 3]) -> usize {
        x + self.dims[0] * (y + self.dims[1] * z)
    }

    pub fn coordinates(&self, index: usize) -> [usize; 3] {
        let x = index % self.dims[0];
        let y = (index / self.dims[0]) % self.dims[1];
        [x, y, index / (self.dims[0] * self.dims[1])]
    }

    pub fn position(&self, [x, y, z]: [usize; 3]) -> DVec3 {
        self.origin + self.h * DVec3::new(x as f64, y as f64, z as f64)
    }

    /// The next level's frame: twice the spacing, on every other node.
    pub fn coarser(&self) -> Frame {
        Frame {
            origin: self.origin,
            h: 2.0 * self.h,
            dims: self.dims.map(|n| (n - 1) / 2 + 1),
        }
    }
}

/// One level: the inside nodes (the unknowns) and their stencils.
pub(in crate::coords) struct Level {
    pub frame: Frame,
    /// Per grid node: its unknown, or [`NONE`] outside the cage.
    pub unknown_of: Vec<u32>,
    /// Per unknown: its grid node.
    pub nodes: Vec<u32>,
    /// Per unknown: the sum of its arms' coefficients.
    pub diagonal: Vec<f32>,
    /// Per unknown, arms −x, +x, −y, +y, −z, +z: the neighbouring unknown, or
    /// [`NONE`] where the arm is cut.
    pub neighbours: Vec<[u32; 6]>,
    /// Every cut arm, for the right-hand sides (finest level only).
    pub cut_arms: Vec<CutArm>,
}

/// Crossings of every grid line along `axis`, sorted along each line. Lines are
/// indexed by their coordinates on the other two axes `(axis+1, axis+2) % 3`.
fn line_crossings(cage: &Cage, frame: &Frame, axis: usize) -> Vec<Vec<Crossing>> {
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    let (nb, nc) = (frame.dims[b], frame.dims[c]);
    let mut lines = vec![Vec::new(); nb * nc];
    let to_grid = |k: u32| (cage.positions()[k as usize] - frame.origin) / frame.h;
    for t in cage.lone_triangles() {
        let corners = cage.triangles()[t];
        let q = corners.map(to_grid);
        // Twice the projected signed area; zero for a triangle along the axis.
        let area =
            (q[1][b] - q[0][b]) * (q[2][c] - q[0][c]) - (q[2][b] - q[0][b]) * (q[1][c] - q[0][c]);
        if area == 0.0 {
            continue;
        }
        for jc in line_range(&q, c, nc) {
            for jb in line_range(&q, b, nb) {
                let (u, v) = (jb as f64, jc as f64);
                // Barycentrics of (u, v) in the projected triangle.
                let edge = |i: usize, k: usize| {
                    (q[k][b] - q[i][b]) * (v - q[i][c]) - (q[k][c] - q[i][c]) * (u - q[i][b])
                };
                let weights = [edge(1, 2), edge(2, 0), edge(0, 1)].map(|w| w / area);
                if weights.iter().any(|&w| w < 0.0) {
                    continue;
                }
                let s = weights[0] * q[0][axis] + weights[1] * q[1][axis] + weights[2] * q[2][axis];
                lines[jb + nb * jc].push(Crossing {
                    s,
                    value: BoundaryValue::triangle(corners, weights).with_triangle_gradients(q),
                });
            }
        }
    }
    for quad in cage.quads() {
        let q = quad.corners.map(to_grid);
        for jc in line_range(&q, c, nc) {
            for jb in line_range(&q, b, nb) {
                let point = DVec2::new(jb as f64, jc as f64);
                for [s, u, v] in patch_line_crossings(&q, axis, point).into_iter().flatten() {
                    lines[jb + nb * jc].push(Crossing {
                        s,
                        value: BoundaryValue::quad(quad.corners, u, v)
                            .with_patch_gradients(&q, u, v),
                    });
                }
            }
        }
    }
    for line in &mut lines {
        line.sort_by(|a, b| a.s.total_cmp(&b.s));
    }
    lines
}

/// Grid lines (indices along `axis`, of `n`) within the span of the points `q`:
/// a triangle or a patch lies in its corners' box.
fn line_range(q: &[DVec3], axis: usize, n: usize) -> std::ops::Range<usize> {
    let lo = q.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min);
    let hi = q.iter().map(|p| p[axis]).fold(f64::NEG_INFINITY, f64::max);
    let first = lo.ceil().max(0.0) as usize;
    let last = (hi.floor().max(-1.0) + 1.0).min(n as f64) as usize;
    first..last.max(first)
}

/// The line along `axis` through node `[x, y, z]`, and the node's place on it.
fn line_of(frame: &Frame, axis: usize, node: [usize; 3]) -> (usize, usize) {
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    (node[b] + frame.dims[b] * node[c], node[axis])
}

/// Which grid nodes are inside the cage: odd crossings before them along x.
pub(in crate::coords) fn inside_nodes(
    cage: &Cage,
    frame: &Frame,
) -> (Vec<bool>, [Vec<Vec<Crossing>>; 3]) {
    let lines = [0, 1, 2].map(|axis| line_crossings(cage, frame, axis));
    let mut inside = vec![false; frame.node_count()];
    for (index, flag) in inside.iter_mut().enumerate() {
        let node = frame.coordinates(index);
        let (line, at) = line_of(frame, 0, node);
        let before = lines[0][line].partition_point(|crossing| crossing.s < at as f64);
        *flag = before % 2 == 1;
    }
    (inside, lines)
}

impl Level {
    /// The level on `frame`; `with_cut_arms` keeps the data for right-hand sides.
    pub fn new(cage: &Cage, frame: Frame, with_cut_arms: bool) -> Level {
        let (inside, lines) = inside_nodes(cage, &frame);
        let mut unknown_of = vec![NONE; frame.node_count()];
        let mut nodes = Vec::new();
        for (index, _) in inside.iter().enumerate().filter(|(_, &inside)| inside) {
            unknown_of[index] = nodes.len() as u32;
            nodes.push(index as u32);
        }
        let mut diagonal = vec![0.0f32; nodes.len()];
        let mut neighbours = vec![[NONE; 6]; nodes.len()];
        let mut cut_arms = Vec::new();
        for (unknown, &index) in nodes.iter().enumerate() {
            let node = frame.coordinates(index as usize);
            for (arm, slot) in neighbours[unknown].iter_mut().enumerate() {
                let (axis, forward) = (arm / 2, arm % 2 == 1);
                let (line, at) = line_of(&frame, axis, node);
                let crossings = &lines[axis][line];
                let at = at as f64;
                let first_cut = if forward {
                    let k = crossings.partition_point(|c| c.s <= at);
                    crossings.get(k).filter(|c| c.s <= at + 1.0)
                } else {
                    let k = crossings.partition_point(|c| c.s < at);
                    k.checked_sub(1)
                        .map(|k| &crossings[k])
                        .filter(|c| c.s >= at - 1.0)
                };
                let mut neighbour_node = node;
                neighbour_node[axis] = if forward {
                    node[axis] + 1
                } else {
                    node[axis] - 1
                };
                let neighbour = unknown_of[frame.index(neighbour_node)];
                let cut = match (first_cut, neighbour) {
                    (None, NONE) => Some(nearest_crossing(cage, crossings, at, &frame, node)),
                    (None, _) => None,
                    (Some(crossing), _) => Some(*crossing),
                };
                match cut {
                    None => {
                        *slot = neighbour;
                        diagonal[unknown] += 1.0;
                    }
                    Some(crossing) => {
                        let theta = (crossing.s - at).abs().clamp(THETA_MIN, 1.0);
                        let coefficient = (1.0 / theta) as f32;
                        diagonal[unknown] += coefficient;
                        if with_cut_arms {
                            cut_arms.push(CutArm {
                                unknown: unknown as u32,
                                arm: arm as u8,
                                coefficient,
                                corners: crossing.value.corners,
                                values: crossing.value.values.map(|w| w as f32),
                                slopes: crossing.value.gradients.map(|g| g[axis] as f32),
                            });
                        }
                    }
                }
            }
        }
        Level {
            frame,
            unknown_of,
            nodes,
            diagonal,
            neighbours,
            cut_arms,
        }
    }

    pub fn unknowns(&self) -> usize {
        self.nodes.len()
    }
}

/// An outside neighbour with no crossing in between: the lines along different
/// axes disagree by rounding. Take the line's nearest crossing, or failing that the
/// closest point of the cage, as the boundary one cell away.
fn nearest_crossing(
    cage: &Cage,
    crossings: &[Crossing],
    at: f64,
    frame: &Frame,
    node: [usize; 3],
) -> Crossing {
    if let Some(nearest) = crossings
        .iter()
        .min_by(|a, b| (a.s - at).abs().total_cmp(&(b.s - at).abs()))
    {
        return Crossing {
            s: at + 1.0,
            ..*nearest
        };
    }
    Crossing {
        s: at + 1.0,
        value: closest_boundary_value(cage, frame.position(node)),
    }
}
