#![allow(clippy::needless_range_loop)]
//! An independent reference for local barycentric coordinates on box cages:
//! the discrete total variation written out from its definition
//! (docs/coordinates.md, LBC) with the box's boundary data in closed form, and
//! minimised by a different algorithm, the primal-dual method of Chambolle and
//! Pock, with each node's projection onto its barycentric set done by a
//! primal active-set method. The library's ADMM must reach the same energy.

use super::bbw_reference::hats_on_face;
use glam::DVec3;
use pmvc::coords::lbc::{node_weights, LbcSettings};
use pmvc::coords::BindProgress;
use pmvc::geometry::{procedural, Cage};
use std::collections::HashMap;

/// Rows of `D`: interior differences `w[to] − w[from]` grouped per owning
/// node, then cut rows `w[node] − g` with `g` per handle.
struct Problem {
    groups: Vec<Vec<(usize, usize)>>,
    cuts: Vec<(usize, Vec<f64>)>,
}

fn problem(cage: &Cage, half: DVec3, positions: &[DVec3], h: f64) -> Problem {
    let origin = positions[0];
    let key = |p: DVec3| (((p - origin) / h).round().as_i64vec3()).to_array();
    let index: HashMap<[i64; 3], usize> = positions
        .iter()
        .enumerate()
        .map(|(i, &p)| (key(p), i))
        .collect();
    let mut groups = vec![Vec::new(); positions.len()];
    let mut cuts = Vec::new();
    for (i, &p) in positions.iter().enumerate() {
        for axis in 0..3 {
            for sign in [-1.0f64, 1.0] {
                let mut next = p;
                next[axis] += sign * h;
                if next[axis].abs() < half[axis] {
                    if sign > 0.0 {
                        groups[i].push((i, index[&key(next)]));
                    }
                } else {
                    let mut crossing = p;
                    crossing[axis] = sign * half[axis];
                    cuts.push((i, hats_on_face(cage, crossing, axis, sign * half[axis])));
                }
            }
        }
    }
    Problem { groups, cuts }
}

/// Σₖ TV(wₖ), `w` node-major.
fn energy(problem: &Problem, w: &[f64], k: usize) -> f64 {
    let mut total = 0.0;
    for handle in 0..k {
        for group in &problem.groups {
            let squares: f64 = group
                .iter()
                .map(|&(from, to)| (w[to * k + handle] - w[from * k + handle]).powi(2))
                .sum();
            total += squares.sqrt();
        }
        for (node, g) in &problem.cuts {
            total += (w[node * k + handle] - g[handle]).abs();
        }
    }
    total
}

/// Solve the 4×4 system `a x = b` by Gaussian elimination with pivoting.
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> [f64; 4] {
    for col in 0..4 {
        let pivot = (col..4)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..4 {
            let f = a[row][col] / a[col][col];
            for c in col..4 {
                a[row][c] -= f * a[col][c];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 4];
    for row in (0..4).rev() {
        let s: f64 = (row + 1..4).map(|c| a[row][c] * x[c]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x
}

/// The projection of `p` onto `{y ≥ 0, Σ y = 1, Σ y v = x}` by the primal
/// active-set method (Nocedal and Wright, algorithm 16.3) from the feasible
/// `y`: minimise over the weights not held at zero, step until a weight
/// reaches zero, and release the held weight whose multiplier is negative.
fn project(p: &[f64], vertices: &[DVec3], x: DVec3, y: &mut [f64]) {
    let a: Vec<[f64; 4]> = vertices
        .iter()
        .map(|&v| [1.0, v.x - x.x, v.y - x.y, v.z - x.z])
        .collect();
    let mut held: Vec<bool> = y.iter().map(|&y| y <= 0.0).collect();
    for _ in 0..200 {
        // The minimiser over the free weights: p − Aᵀμ with A(p − Aᵀμ) = c.
        let mut normal = [[0.0; 4]; 4];
        let mut rhs = [-1.0, 0.0, 0.0, 0.0];
        for i in (0..p.len()).filter(|&i| !held[i]) {
            for r in 0..4 {
                rhs[r] += a[i][r] * p[i];
                for c in 0..4 {
                    normal[r][c] += a[i][r] * a[i][c];
                }
            }
        }
        for r in 0..4 {
            normal[r][r] += 1e-14;
        }
        let mu = solve4(normal, rhs);
        let along = |i: usize| (0..4).map(|r| a[i][r] * mu[r]).sum::<f64>();
        let target: Vec<f64> = (0..p.len())
            .map(|i| if held[i] { 0.0 } else { p[i] - along(i) })
            .collect();
        let moves = target
            .iter()
            .zip(y.iter())
            .any(|(t, y)| (t - y).abs() > 1e-15);
        if !moves {
            let release = (0..p.len())
                .filter(|&i| held[i])
                .map(|i| (i, along(i) - p[i]))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            match release {
                Some((i, multiplier)) if multiplier < -1e-14 => held[i] = false,
                _ => return,
            }
            continue;
        }
        let mut step = 1.0;
        let mut blocking = None;
        for i in (0..p.len()).filter(|&i| !held[i]) {
            let d = target[i] - y[i];
            if d < 0.0 && -y[i] / d < step {
                step = -y[i] / d;
                blocking = Some(i);
            }
        }
        for i in 0..p.len() {
            y[i] += step * (target[i] - y[i]);
        }
        if let Some(i) = blocking {
            y[i] = 0.0;
            held[i] = true;
        }
    }
    panic!("the active set did not settle at {x}");
}

/// The trilinear weights of the box's corners at `x`: a feasible start.
fn trilinear(vertices: &[DVec3], half: DVec3, x: DVec3) -> Vec<f64> {
    vertices
        .iter()
        .map(|&v| {
            (0..3)
                .map(|axis| 0.5 * (1.0 + x[axis] * v[axis].signum() / half[axis]))
                .product()
        })
        .collect()
}

/// Chambolle–Pock on `min Σ TV(wₖ) + ι(barycentric)`; node-major weights.
fn chambolle_pock(
    problem: &Problem,
    positions: &[DVec3],
    vertices: &[DVec3],
    half: DVec3,
    steps: usize,
) -> Vec<f64> {
    let (n, k) = (positions.len(), vertices.len());
    // ‖D‖² ≤ (largest row sum) × (largest column sum) = 2 × 6.
    let (sigma, tau) = (0.28, 0.28);
    let mut w: Vec<f64> = Vec::with_capacity(n * k);
    for &x in positions {
        w.extend(trilinear(vertices, half, x));
    }
    let mut w_bar = w.clone();
    let mut q_groups: Vec<Vec<f64>> = problem
        .groups
        .iter()
        .map(|g| vec![0.0; g.len() * k])
        .collect();
    let mut q_cuts = vec![0.0; problem.cuts.len() * k];
    let mut gradient = vec![0.0; n * k];
    for _ in 0..steps {
        for (group, q) in problem.groups.iter().zip(q_groups.iter_mut()) {
            for handle in 0..k {
                let mut length = 0.0;
                for (e, &(from, to)) in group.iter().enumerate() {
                    let value = &mut q[e * k + handle];
                    *value += sigma * (w_bar[to * k + handle] - w_bar[from * k + handle]);
                    length += *value * *value;
                }
                let scale = 1.0 / length.sqrt().max(1.0);
                for e in 0..group.len() {
                    q[e * k + handle] *= scale;
                }
            }
        }
        for (c, (node, g)) in problem.cuts.iter().enumerate() {
            for handle in 0..k {
                let value = &mut q_cuts[c * k + handle];
                *value = (*value + sigma * (w_bar[node * k + handle] - g[handle])).clamp(-1.0, 1.0);
            }
        }
        gradient.fill(0.0);
        for (group, q) in problem.groups.iter().zip(&q_groups) {
            for (e, &(from, to)) in group.iter().enumerate() {
                for handle in 0..k {
                    gradient[to * k + handle] += q[e * k + handle];
                    gradient[from * k + handle] -= q[e * k + handle];
                }
            }
        }
        for (c, (node, _)) in problem.cuts.iter().enumerate() {
            for handle in 0..k {
                gradient[node * k + handle] += q_cuts[c * k + handle];
            }
        }
        for (node, &x) in positions.iter().enumerate() {
            let row: Vec<f64> = (0..k)
                .map(|h| w[node * k + h] - tau * gradient[node * k + h])
                .collect();
            let mut next = w[node * k..][..k].to_vec();
            project(&row, vertices, x, &mut next);
            for h in 0..k {
                w_bar[node * k + h] = 2.0 * next[h] - w[node * k + h];
                w[node * k + h] = next[h];
            }
        }
    }
    w
}

#[test]
fn admm_reaches_the_energy_of_an_independent_primal_dual_solve() {
    for (name, half) in [
        ("cube", DVec3::splat(1.0)),
        ("long box", DVec3::new(2.5, 1.0, 0.6)),
    ] {
        let cube = procedural::cube_cage(1.0);
        let cage = cube.with_positions(cube.positions().iter().map(|&p| p * half).collect());
        let (nodes, stats) =
            node_weights(&cage, 6, &LbcSettings::default(), &BindProgress::new(0)).unwrap();
        let problem = problem(&cage, half, &nodes.positions, nodes.cell);
        let k = cage.vertex_count();
        let library = energy(&problem, &nodes.values, k);
        let reference_weights =
            chambolle_pock(&problem, &nodes.positions, cage.positions(), half, 20_000);
        let reference = energy(&problem, &reference_weights, k);
        let largest = nodes
            .values
            .iter()
            .zip(&reference_weights)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        println!(
            "{name}: {} nodes, {} cut rows; energy: library {library:.9} (its own count {:.9}), reference {reference:.9}; largest weight difference {largest:e}; {stats:?}",
            nodes.positions.len(),
            problem.cuts.len(),
            stats.energy
        );
        // The grid keeps boundary data in float32: the two counts differ by that.
        assert!(
            (library - stats.energy).abs() <= 1e-7 * library,
            "{name}: the discretisations differ"
        );
        assert!(
            library <= reference * (1.0 + 1e-5),
            "{name}: {library} above {reference}"
        );
        assert!(
            reference <= library * (1.0 + 1e-3),
            "{name}: the reference did not converge"
        );
    }
}
