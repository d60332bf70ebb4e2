#![allow(clippy::needless_range_loop)]
//! An independent reference for bounded biharmonic weights on box cages: the
//! discrete energy written out densely from its definition (docs/coordinates.md,
//! BBW) with the box's geometry known in closed form, and the bound-constrained
//! programme solved exactly by a primal-dual active-set method with dense
//! Cholesky solves. The library's ADMM on its sparse factor must agree.

use glam::DVec3;
use pmvc::coords::bbw::{node_weights, AdmmSettings};
use pmvc::coords::BindProgress;
use pmvc::geometry::{procedural, Cage};
use std::collections::HashMap;

/// The hat function of every cage vertex at `p` on the box face `axis = side`.
pub(crate) fn hats_on_face(cage: &Cage, p: DVec3, axis: usize, side: f64) -> Vec<f64> {
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    let mut out = vec![0.0; cage.vertex_count()];
    for t in cage.triangles() {
        let q = t.map(|k| cage.positions()[k as usize]);
        if q.iter().any(|v| (v[axis] - side).abs() > 1e-12) {
            continue;
        }
        let area =
            (q[1][b] - q[0][b]) * (q[2][c] - q[0][c]) - (q[2][b] - q[0][b]) * (q[1][c] - q[0][c]);
        let edge = |i: usize, k: usize| {
            (q[k][b] - q[i][b]) * (p[c] - q[i][c]) - (q[k][c] - q[i][c]) * (p[b] - q[i][b])
        };
        let w = [edge(1, 2), edge(2, 0), edge(0, 1)].map(|e| e / area);
        if w.iter().all(|&w| w >= -1e-12) {
            for (&k, &w) in t.iter().zip(&w) {
                out[k as usize] = w;
            }
            return out;
        }
    }
    panic!("no face triangle holds {p}");
}

/// Dense Cholesky solve of the SPD system `a x = b` (row-major `n × n`).
fn cholesky_solve(a: &[f64], n: usize, b: &[f64]) -> Vec<f64> {
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let mut sum = a[i * n + j];
            for k in 0..j {
                sum -= l[i * n + k] * l[j * n + k];
            }
            if i == j {
                assert!(sum > 0.0, "not positive definite");
                l[i * n + i] = sum.sqrt();
            } else {
                l[i * n + j] = sum / l[j * n + j];
            }
        }
    }
    let mut y = b.to_vec();
    for i in 0..n {
        for k in 0..i {
            y[i] -= l[i * n + k] * y[k];
        }
        y[i] /= l[i * n + i];
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            y[i] -= l[k * n + i] * y[k];
        }
        y[i] /= l[i * n + i];
    }
    y
}

/// `min ½xᵀQx + qᵀx, 0 ≤ x ≤ 1` by primal-dual active sets; with the number
/// of bounds active at the solution. Panics unless the KKT conditions hold.
fn box_qp(q_mat: &[f64], q: &[f64], n: usize) -> (Vec<f64>, usize) {
    let gradient = |x: &[f64]| -> Vec<f64> {
        (0..n)
            .map(|i| (0..n).map(|j| q_mat[i * n + j] * x[j]).sum::<f64>() + q[i])
            .collect()
    };
    let mut x = vec![0.5; n];
    let mut g = vec![0.0; n];
    let mut previous: Option<Vec<i8>> = None;
    for _ in 0..100 {
        // −1 at the lower bound, +1 at the upper, 0 free.
        let state: Vec<i8> = (0..n)
            .map(|i| {
                if x[i] - g[i] < 0.0 {
                    -1
                } else if x[i] - g[i] > 1.0 {
                    1
                } else {
                    0
                }
            })
            .collect();
        if previous.as_ref() == Some(&state) {
            break;
        }
        let free: Vec<usize> = (0..n).filter(|&i| state[i] == 0).collect();
        let fixed = |i: usize| if state[i] == 1 { 1.0 } else { 0.0 };
        let m = free.len();
        let mut a = vec![0.0; m * m];
        let mut rhs = vec![0.0; m];
        for (r, &i) in free.iter().enumerate() {
            rhs[r] = -q[i];
            for j in 0..n {
                if state[j] != 0 {
                    rhs[r] -= q_mat[i * n + j] * fixed(j);
                }
            }
            for (s, &j) in free.iter().enumerate() {
                a[r * m + s] = q_mat[i * n + j];
            }
        }
        let solved = cholesky_solve(&a, m, &rhs);
        for i in 0..n {
            x[i] = fixed(i);
        }
        for (r, &i) in free.iter().enumerate() {
            x[i] = solved[r];
        }
        g = gradient(&x);
        previous = Some(state);
    }
    // KKT: within bounds, gradient zero where free, signed where at a bound.
    let scale = q.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for i in 0..n {
        assert!((-1e-12..=1.0 + 1e-12).contains(&x[i]), "x[{i}] = {}", x[i]);
        let tolerance = 1e-9 * scale;
        if x[i] == 0.0 {
            assert!(g[i] >= -tolerance, "lower bound multiplier {}", g[i]);
        } else if x[i] == 1.0 {
            assert!(g[i] <= tolerance, "upper bound multiplier {}", g[i]);
        } else {
            assert!(g[i].abs() <= tolerance, "free gradient {}", g[i]);
        }
    }
    let active = x.iter().filter(|&&x| x == 0.0 || x == 1.0).count();
    (x, active)
}

/// BBW of every handle at the inside nodes of a box `[-half, half]`, written
/// out densely from the definition; `raw` columns as the library returns them
/// (node-major), and bounds active in all.
fn dense_reference(cage: &Cage, half: DVec3, positions: &[DVec3], h: f64) -> (Vec<f64>, usize) {
    let n = positions.len();
    let origin = positions[0];
    let key = |p: DVec3| (((p - origin) / h).round().as_i64vec3()).to_array();
    let index: HashMap<[i64; 3], usize> = positions
        .iter()
        .enumerate()
        .map(|(i, &p)| (key(p), i))
        .collect();
    let columns = cage.vertex_count();
    // D (dense), mass, and the boundary vectors of every handle.
    let mut d = vec![0.0; n * n];
    let mut mass = vec![1.0; n];
    let mut b = vec![0.0; n * columns];
    // The flux rows of the cut arms: (unknown, coefficient, b per handle); a
    // box's hat functions vary along its faces only, so no surface gradient
    // has a component along an arm.
    let mut flux: Vec<(usize, f64, Vec<f64>)> = Vec::new();
    for (i, &p) in positions.iter().enumerate() {
        for axis in 0..3 {
            let mut theta = [1.0f64; 2];
            let mut target = [None; 2];
            for (side, sign) in [-1.0f64, 1.0].into_iter().enumerate() {
                let mut next = p;
                next[axis] += sign * h;
                if next[axis].abs() < half[axis] {
                    target[side] = Some(index[&key(next)]);
                } else {
                    theta[side] = ((sign * half[axis] - p[axis]).abs() / h).clamp(1e-3, 1.0);
                }
            }
            mass[i] *= 0.5 * (theta[0] + theta[1]);
            for (side, sign) in [-1.0f64, 1.0].into_iter().enumerate() {
                let c = 2.0 / (theta[side] * (theta[0] + theta[1]));
                d[i * n + i] += c;
                match target[side] {
                    Some(j) => d[i * n + j] -= c,
                    None => {
                        let mut crossing = p;
                        crossing[axis] = sign * half[axis];
                        let hats = hats_on_face(cage, crossing, axis, sign * half[axis]);
                        for k in 0..columns {
                            b[k * n + i] += c * hats[k];
                        }
                        let f = -sign / theta[side];
                        flux.push((i, f, hats.iter().map(|&g| f * g).collect()));
                    }
                }
            }
        }
    }
    let mut q_mat = vec![0.0; n * n];
    for r in 0..n {
        for i in 0..n {
            if d[r * n + i] == 0.0 {
                continue;
            }
            for j in 0..n {
                q_mat[i * n + j] += mass[r] * d[r * n + i] * d[r * n + j];
            }
        }
    }
    for (i, f, _) in &flux {
        q_mat[i * n + i] += f * f;
    }
    let mut raw = vec![0.0; n * columns];
    let mut active = 0;
    for k in 0..columns {
        let bk = &b[k * n..][..n];
        let mut q: Vec<f64> = (0..n)
            .map(|i| -(0..n).map(|r| d[r * n + i] * mass[r] * bk[r]).sum::<f64>())
            .collect();
        for (i, f, fb) in &flux {
            q[*i] -= f * fb[k];
        }
        let (x, a) = box_qp(&q_mat, &q, n);
        active += a;
        for i in 0..n {
            raw[i * columns + k] = x[i];
        }
    }
    (raw, active)
}

#[test]
fn admm_on_the_sparse_factor_agrees_with_a_dense_active_set_solve() {
    for (name, half) in [
        ("cube", DVec3::splat(1.0)),
        ("long box", DVec3::new(2.5, 1.0, 0.6)),
    ] {
        let cube = procedural::cube_cage(1.0);
        let cage = cube.with_positions(cube.positions().iter().map(|&p| p * half).collect());
        let (nodes, stats) =
            node_weights(&cage, 9, &AdmmSettings::default(), &BindProgress::new(0)).unwrap();
        let (reference, active) = dense_reference(&cage, half, &nodes.positions, nodes.cell);
        let worst = nodes
            .raw
            .iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "{name}: {} nodes, {active} bounds active in the reference, largest difference {worst:e}, {stats:?}",
            nodes.positions.len()
        );
        assert!(
            worst <= 1e-6,
            "{name}: ADMM differs from the reference by {worst}"
        );
        assert_eq!(stats.unconverged, 0);
        assert!(active > 0, "{name}: no bound active, nothing tested");
    }
}

#[test]
#[ignore]
fn step_sweep() {
    let comb = procedural::extrude(&procedural::comb_outline(5, 1.0, 0.25, 4.0), -0.5, 0.5);
    for rho in [1e-2, 3e-2, 0.1, 0.3, 1.0, 3.0] {
        let settings = AdmmSettings {
            rho,
            max_iterations: 4000,
            ..AdmmSettings::default()
        };
        for (name, half) in [
            ("cube", DVec3::splat(1.0)),
            ("long box", DVec3::new(2.5, 1.0, 0.6)),
        ] {
            let cube = procedural::cube_cage(1.0);
            let cage = cube.with_positions(cube.positions().iter().map(|&p| p * half).collect());
            let (nodes, stats) = node_weights(&cage, 9, &settings, &BindProgress::new(0)).unwrap();
            let (reference, active) = dense_reference(&cage, half, &nodes.positions, nodes.cell);
            let worst = nodes
                .raw
                .iter()
                .zip(&reference)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            println!(
                "rho {rho} {name}: active {active} error {worst:e} its {} unconv {} sumdev {:e}",
                stats.max_iterations, stats.unconverged, stats.sum_deviation
            );
        }
        let t = std::time::Instant::now();
        let (_, stats) = node_weights(&comb, 24, &settings, &BindProgress::new(0)).unwrap();
        println!(
            "rho {rho} comb 24: {:.2}s its {} unconv {} sumdev {:e} primal {:e}",
            t.elapsed().as_secs_f64(),
            stats.max_iterations,
            stats.unconverged,
            stats.sum_deviation,
            stats.primal_residual
        );
    }
}
