//! A brute-force reference for the tests: the kernels written out by index
//! (Brebbia's form), integrated by a tensor Gauss rule on every cell of a
//! uniform subdivision of each triangle. Slow and only accurate away from the
//! surface, but independent of the polar scheme and of the adaptive rules.

use super::quadrature::gauss_legendre;
use crate::geometry::Cage;
use glam::{DMat3, DVec3};
use std::f64::consts::PI;

/// Every vertex block and face block of `x`, as (vertex blocks, face blocks).
pub(super) fn brute_force_blocks(
    x: DVec3,
    cage: &Cage,
    nu: f64,
    cells_per_edge: usize,
    order: usize,
) -> (Vec<DMat3>, Vec<DMat3>) {
    let (nodes, weights) = gauss_legendre(order);
    let mut vertex = vec![[[0.0f64; 3]; 3]; cage.vertex_count()];
    let mut face = Vec::with_capacity(cage.triangle_count());
    let dilation_traction = 2.0 * (1.0 + nu) / (1.0 - 2.0 * nu);
    for (t, corners) in cage.triangles().iter().enumerate() {
        let [a, b, c] = cage.triangle(t);
        let normal = (b - a).cross(c - a).normalize();
        let mut single = [[0.0f64; 3]; 3];
        let m = cells_per_edge as f64;
        // Cells of the barycentric grid: upward (i, j) and downward ones.
        for i in 0..cells_per_edge {
            for j in 0..cells_per_edge - i {
                let mut cells = vec![[[i, j], [i + 1, j], [i, j + 1]]];
                if i + j + 1 < cells_per_edge {
                    cells.push([[i + 1, j + 1], [i, j + 1], [i + 1, j]]);
                }
                for cell in cells {
                    let corner = |k: usize| {
                        let (p, q) = (cell[k][0] as f64 / m, cell[k][1] as f64 / m);
                        [1.0 - p - q, p, q]
                    };
                    let [c0, c1, c2] = [corner(0), corner(1), corner(2)];
                    let cell_area = (b - a).cross(c - a).length() / (2.0 * m * m);
                    // A Duffy map collapsed onto the cell's first corner.
                    for (&s, &ws) in nodes.iter().zip(&weights) {
                        for (&u, &wu) in nodes.iter().zip(&weights) {
                            let (s, u) = (0.5 * (s + 1.0), 0.5 * (u + 1.0));
                            let (l1, l2) = (s * (1.0 - u), s * u);
                            let l0 = 1.0 - l1 - l2;
                            let hats: [f64; 3] =
                                std::array::from_fn(|k| l0 * c0[k] + l1 * c1[k] + l2 * c2[k]);
                            let y = a * hats[0] + b * hats[1] + c * hats[2];
                            let w = 0.25 * ws * wu * s * 2.0 * cell_area;
                            let r = y - x;
                            let len = r.length();
                            let (rv, nv) = (r.to_array(), normal.to_array());
                            let r_dot_n = r.dot(normal) / len;
                            for p in 0..3 {
                                for q in 0..3 {
                                    let delta = if p == q { 1.0 } else { 0.0 };
                                    let rp_rq = rv[p] * rv[q] / (len * len);
                                    single[p][q] += w * ((3.0 - 4.0 * nu) * delta + rp_rq)
                                        / (16.0 * PI * (1.0 - nu) * len);
                                    let traction = -((((1.0 - 2.0 * nu) * delta + 3.0 * rp_rq)
                                        * r_dot_n)
                                        - (1.0 - 2.0 * nu) * (rv[p] * nv[q] - rv[q] * nv[p]) / len)
                                        / (8.0 * PI * (1.0 - nu) * len * len);
                                    for (k, &v) in corners.iter().enumerate() {
                                        vertex[v as usize][p][q] -= w * hats[k] * traction;
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        face.push(to_matrix(&single) * dilation_traction);
    }
    (vertex.iter().map(to_matrix).collect(), face)
}

/// From rows to glam's columns.
fn to_matrix(rows: &[[f64; 3]; 3]) -> DMat3 {
    DMat3::from_cols_array_2d(rows).transpose()
}
