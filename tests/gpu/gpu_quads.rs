//! The GPU binder on cages with quads: PMVC's kernel takes them as bilinear
//! patches and agrees with an f64 ray caster (and with the CPU reference once it
//! takes patches); a quad's corner order does not matter, and splitting quads
//! does; MVC there is QMVC and Green QGC, bound on the CPU whatever the
//! backend, and both bind their split on the GPU. Without an adapter each test says it was not
//! run, unless `PMVC_REQUIRE_GPU=1`, which turns a missing adapter into a failure.

use crate::gpu_support;
use glam::DVec3;
use gpu_support::*;
use pmvc::coords::cubemap::{TexelTable, CUBE_FACES};
use pmvc::coords::{BindOptions, BindProgress, Method, Weights};
use pmvc::geometry::procedural::points_inside;
use pmvc::geometry::procedural_quads::{cage_from_polygons, quad_comb, twisted_box};
use pmvc::geometry::quads::{bilinear_basis, bilinear_normal, bilinear_point};
use pmvc::geometry::{classify_points, Cage, PointClass, QuadSplit};
use pmvc::gpu::backend_choice::{decide, BackendRequest, Work};
use pmvc::gpu::{Backend, BindOutput, Binder, GpuContext};
use std::sync::Arc;

/// Largest |Δ| allowed per weight between the f32 kernel and f64: a texel is
/// about 1/6000 of a row at 32², and only rounding (a few 1e-7 per texel) and
/// rays within f32 rounding of a patch edge or silhouette may differ.
const TOLERANCE: f64 = 1e-4;
const RESOLUTION: u32 = 32;

/// The nearest hit at t > 0 of the ray x + t·d with triangle `corners`:
/// (t, barycentrics).
fn triangle_hit(x: DVec3, d: DVec3, corners: [DVec3; 3]) -> Option<(f64, [f64; 3])> {
    let [a, b, c] = corners.map(|p| p - x);
    let det = a.dot(b.cross(c));
    let edges = [d.dot(b.cross(c)), d.dot(c.cross(a)), d.dot(a.cross(b))];
    let sum: f64 = edges.iter().sum();
    let same_side = edges.iter().all(|&e| e * det.signum() >= 0.0);
    if det == 0.0 || !same_side || sum == 0.0 {
        return None;
    }
    let t = det / sum;
    (t > 0.0).then(|| (t, edges.map(|e| e / sum)))
}

/// The nearest hit at t > 0 of x + t·d with the patch `q`: (t, basis). Solved
/// another way than the kernel: two planes through the ray give two bilinear
/// equations in (u, v), whose resultant in u is a quadratic.
fn patch_hit(x: DVec3, d: DVec3, q: [DVec3; 4]) -> Option<(f64, [f64; 4])> {
    let d_hat = d.normalize();
    let n1 = d_hat.any_orthonormal_vector();
    let n2 = d_hat.cross(n1);
    // P(u, v) − x = A + u·B + v·C + uv·D.
    let terms = [
        q[0] - x,
        q[1] - q[0],
        q[3] - q[0],
        q[0] - q[1] + q[2] - q[3],
    ];
    let [a1, b1, c1, d1] = terms.map(|t| n1.dot(t));
    let [a2, b2, c2, d2] = terms.map(|t| n2.dot(t));
    let quadratic = b2 * d1 - d2 * b1;
    let linear = a2 * d1 + b2 * c1 - c2 * b1 - d2 * a1;
    let constant = a2 * c1 - c2 * a1;
    let mut roots = Vec::new();
    let scale = quadratic.abs().max(linear.abs()).max(constant.abs());
    if quadratic.abs() <= 1e-14 * scale {
        if linear != 0.0 {
            roots.push(-constant / linear);
        }
    } else {
        let discriminant = linear * linear - 4.0 * quadratic * constant;
        if discriminant < 0.0 {
            return None;
        }
        let root = -0.5 * (linear + linear.signum() * discriminant.sqrt());
        roots.push(root / quadratic);
        if root != 0.0 {
            roots.push(constant / root);
        }
    }
    let mut best: Option<(f64, [f64; 4])> = None;
    for u in roots.into_iter().filter(|u| (0.0..=1.0).contains(u)) {
        let (num1, den1) = (a1 + b1 * u, c1 + d1 * u);
        let (num2, den2) = (a2 + b2 * u, c2 + d2 * u);
        let v = if den1.abs() > den2.abs() {
            -num1 / den1
        } else {
            -num2 / den2
        };
        if !(0.0..=1.0).contains(&v) {
            continue;
        }
        let t = (bilinear_point(&q, u, v) - x).dot(d) / d.length_squared();
        if t > 0.0 && best.is_none_or(|(nearest, _)| t < nearest) {
            best = Some((t, bilinear_basis(u, v)));
        }
    }
    best
}

/// PMVC of x by casting every texel's ray against every lone triangle and
/// patch in f64, and how many rays escaped.
fn reference_pmvc(cage: &Cage, x: DVec3, table: &TexelTable) -> (Vec<f64>, usize) {
    let mut row = vec![0.0; cage.vertex_count()];
    let mut missed = 0;
    let r = table.resolution as usize;
    let lone: Vec<usize> = cage.lone_triangles().collect();
    for face in CUBE_FACES {
        for j in 0..r {
            for i in 0..r {
                let d = table.centres[i] * face.right + table.centres[j] * face.up + face.normal;
                let mut nearest: Option<(f64, Vec<(u32, f64)>)> = None;
                let mut offer = |t: f64, spread: Vec<(u32, f64)>| {
                    if nearest.as_ref().is_none_or(|(best, _)| t < *best) {
                        nearest = Some((t, spread));
                    }
                };
                for &t in &lone {
                    if let Some((depth, bary)) = triangle_hit(x, d, cage.triangle(t)) {
                        offer(depth, cage.triangles()[t].into_iter().zip(bary).collect());
                    }
                }
                for (k, quad) in cage.quads().iter().enumerate() {
                    if let Some((depth, basis)) = patch_hit(x, d, cage.quad(k)) {
                        offer(depth, quad.corners.into_iter().zip(basis).collect());
                    }
                }
                match nearest {
                    Some((t, spread)) => {
                        let weight = table.solid_angle_over_length[j * r + i] / t;
                        for (corner, share) in spread {
                            row[corner as usize] += weight * share;
                        }
                    }
                    None => missed += 1,
                }
            }
        }
    }
    let total: f64 = row.iter().sum();
    row.iter_mut().for_each(|w| *w /= total);
    (row, missed)
}

fn bind_on(context: &Arc<GpuContext>, input: &pmvc::gpu::BindInput) -> BindOutput {
    Binder::new(Backend::Gpu(Arc::clone(context)))
        .bind_blocking(input, &BindProgress::default())
        .expect("GPU bind")
}

/// max |Δ| over the matrices.
fn max_difference(a: &Weights, b: &Weights) -> f64 {
    assert_eq!((a.rows, a.cols), (b.rows, b.cols));
    a.values
        .iter()
        .zip(&b.values)
        .map(|(&x, &y)| (f64::from(x) - f64::from(y)).abs())
        .fold(0.0, f64::max)
}

/// A box [−1, 1]² × [0, 1] of five quads under a roof of four triangles: lone
/// triangles beside patches, the top ring of quads bent.
fn house() -> Cage {
    let mut positions: Vec<DVec3> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 0.0))
        .collect();
    let eaves = [
        (-1.1, -1.0, 1.2),
        (1.0, -1.0, 1.0),
        (1.0, 1.1, 1.0),
        (-1.0, 1.0, 1.1),
    ];
    positions.extend(eaves.iter().map(|&(x, y, z)| DVec3::new(x, y, z)));
    positions.push(DVec3::new(0.1, 0.0, 1.8));
    let polygons = vec![
        vec![0, 3, 2, 1],
        vec![0, 1, 5, 4],
        vec![1, 2, 6, 5],
        vec![2, 3, 7, 6],
        vec![3, 0, 4, 7],
        vec![4, 5, 8],
        vec![5, 6, 8],
        vec![6, 7, 8],
        vec![7, 4, 8],
    ];
    cage_from_polygons(&positions, &polygons)
        .expect("a house")
        .0
}

/// `count` points inside every one of `cages` (the same cage with its quads as
/// patches or split: a bent patch leaves some of the triangles' inside outside).
fn inside_all(cages: &[&Cage], count: usize, seed: u64) -> Vec<DVec3> {
    let mut candidates = points_inside(cages[0], 2 * count, seed, 1e-3);
    for cage in cages {
        let classes = classify_points(cage, &candidates).classes;
        candidates = candidates
            .into_iter()
            .zip(classes)
            .filter(|(_, class)| *class == PointClass::Inside)
            .map(|(x, _)| x)
            .collect();
    }
    let inside: Vec<DVec3> = candidates.into_iter().take(count).collect();
    assert_eq!(inside.len(), count);
    inside
}

/// GPU PMVC of `count` inside points against the f64 ray caster: every row on
/// the GPU, non-negative, summing to one, within [`TOLERANCE`]. Returns the
/// input and the GPU's weights.
fn pmvc_agrees_with_ray_caster(
    name: &str,
    context: &Arc<GpuContext>,
    cage: &Cage,
    count: usize,
) -> (pmvc::gpu::BindInput, Weights) {
    let input = input(cage, inside_all(&[cage], count, 11), Method::Pmvc);
    let output = bind_on(context, &input);
    assert_eq!(
        output.stats.gpu_rows, count,
        "{name}: every row bound by the quad kernel"
    );
    let gpu = output.weights.expect("CPU weights");
    let table = TexelTable::new(RESOLUTION);
    let mut worst: f64 = 0.0;
    for (row, &x) in input.points.iter().enumerate() {
        let (expected, missed) = reference_pmvc(cage, x, &table);
        assert_eq!(missed, 0, "{name}: the reference lost rays at {x}");
        let actual = gpu.row(row);
        let sum: f64 = actual.iter().map(|&w| f64::from(w)).sum();
        assert!((sum - 1.0).abs() < 1e-5, "{name}: row {row} sums to {sum}");
        for (&a, &e) in actual.iter().zip(&expected) {
            assert!(a >= 0.0, "{name}: negative weight {a} at row {row}");
            worst = worst.max((f64::from(a) - e).abs());
        }
    }
    eprintln!("  {name}: max |Δ| against the f64 ray caster {worst:.2e}");
    assert!(worst <= TOLERANCE, "{name}: max |Δ| = {worst:e}");
    (input, gpu)
}

/// Once the CPU reference takes patches (its weights on the quad cage differ
/// from those on the cage split along the shorter diagonal), the GPU agrees
/// with it too.
fn agrees_with_cpu_reference(name: &str, input: &pmvc::gpu::BindInput, gpu: &Weights) {
    let expected = cpu(input);
    let split = input.with_options(BindOptions {
        quads: QuadSplit::Shorter,
        ..input.options
    });
    if max_difference(&expected, &cpu(&split)) == 0.0 {
        eprintln!("  {name}: the CPU reference still binds triangles; not compared");
        return;
    }
    let worst = max_difference(gpu, &expected);
    eprintln!("  {name}: max |Δ| against the CPU reference {worst:.2e}");
    assert!(worst <= TOLERANCE, "{name}: max |Δ| = {worst:e}");
}

#[test]
fn quad_pmvc_on_a_twisted_box_agrees_with_an_f64_ray_caster() {
    let Some(context) = test_context("twisted box") else {
        return;
    };
    let cage = twisted_box(2.0, 0.6);
    let (input, gpu) = pmvc_agrees_with_ray_caster("twisted box", &context, &cage, 40);
    agrees_with_cpu_reference("twisted box", &input, &gpu);
}

#[test]
fn quad_pmvc_on_a_bent_comb_agrees_with_an_f64_ray_caster() {
    let Some(context) = test_context("quad comb") else {
        return;
    };
    let cage = quad_comb(3, 1.0, 0.5, 3.0, 1.0, 0.3);
    let (input, gpu) = pmvc_agrees_with_ray_caster("quad comb", &context, &cage, 40);
    agrees_with_cpu_reference("quad comb", &input, &gpu);
}

#[test]
fn quad_pmvc_with_lone_triangles_beside_patches_agrees_with_an_f64_ray_caster() {
    let Some(context) = test_context("house") else {
        return;
    };
    let cage = house();
    assert_eq!((cage.quads().len(), cage.lone_triangles().count()), (5, 4));
    let (input, gpu) = pmvc_agrees_with_ray_caster("house", &context, &cage, 30);
    agrees_with_cpu_reference("house", &input, &gpu);
}

#[test]
fn points_close_to_bent_patches_agree_with_an_f64_ray_caster() {
    let Some(context) = test_context("close to patches") else {
        return;
    };
    let cage = twisted_box(2.0, 0.6);
    let diagonal = cage.diagonal();
    // Inside each patch, near its middle, an edge and a corner, moved inwards
    // along its normal by 1e-4 to 1e-6 of the diagonal.
    let mut points = Vec::new();
    for k in 0..cage.quads().len() {
        let q = cage.quad(k);
        for (n, (u, v)) in [(0.5, 0.5), (0.02, 0.6), (0.97, 0.97)]
            .into_iter()
            .enumerate()
        {
            let inward = -bilinear_normal(&q, u, v).normalize();
            let depth = diagonal * [1e-4, 1e-5, 1e-6][(n + k) % 3];
            points.push(bilinear_point(&q, u, v) + depth * inward);
        }
    }
    let input = input(&cage, points, Method::Pmvc);
    let output = bind_on(&context, &input);
    let inside = input
        .classes
        .iter()
        .filter(|c| **c == PointClass::Inside)
        .count();
    eprintln!(
        "  close to patches: {} of {inside} inside rows redone on the CPU",
        inside - output.stats.gpu_rows
    );
    assert!(inside >= 12 && inside - output.stats.gpu_rows <= inside / 6);
    let gpu = output.weights.expect("CPU weights");
    let table = TexelTable::new(RESOLUTION);
    let mut worst: f64 = 0.0;
    for (row, &x) in input.points.iter().enumerate() {
        if input.classes[row] != PointClass::Inside {
            continue;
        }
        let (expected, _) = reference_pmvc(&cage, x, &table);
        for (&a, &e) in gpu.row(row).iter().zip(&expected) {
            worst = worst.max((f64::from(a) - e).abs());
        }
    }
    eprintln!("  close to patches: max |Δ| against the f64 ray caster {worst:.2e}");
    assert!(worst <= TOLERANCE, "close to patches: max |Δ| = {worst:e}");
}

/// `cage` rebuilt with every quad's corner list turned by `turn` places.
fn turned(cage: &Cage, turn: usize) -> Cage {
    let mut polygons: Vec<Vec<u32>> = cage
        .quads()
        .iter()
        .map(|quad| {
            let mut corners = quad.corners.to_vec();
            corners.rotate_left(turn);
            corners
        })
        .collect();
    polygons.extend(cage.lone_triangles().map(|t| cage.triangles()[t].to_vec()));
    cage_from_polygons(cage.positions(), &polygons)
        .expect("the same cage")
        .0
}

#[test]
fn turning_quad_corner_lists_keeps_the_weights_and_splitting_quads_changes_them() {
    let Some(context) = test_context("corner order") else {
        return;
    };
    let cage = twisted_box(2.0, 0.6);
    let split = [QuadSplit::Shorter, QuadSplit::Longer].map(|split| cage.split_quads(split));
    let points = inside_all(&[&cage, &split[0], &split[1]], 30, 5);
    let bind = |cage: &Cage, quads: QuadSplit| {
        let mut input = input(cage, points.clone(), Method::Pmvc);
        input.options.quads = quads;
        let output = bind_on(&context, &input);
        assert_eq!(output.stats.gpu_rows, points.len());
        output.weights.expect("CPU weights")
    };
    let patches = bind(&cage, QuadSplit::None);
    for turn in 1..4 {
        let other = turned(&cage, turn);
        assert_eq!(other.quads().len(), 6);
        assert_ne!(other.quads()[0].corners, cage.quads()[0].corners);
        let worst = max_difference(&patches, &bind(&other, QuadSplit::None));
        eprintln!("  turned by {turn}: max |Δ| {worst:.2e}");
        assert!(worst <= 1e-5, "turned by {turn}: max |Δ| = {worst:e}");
    }
    for (split, split_cage) in [QuadSplit::Shorter, QuadSplit::Longer]
        .into_iter()
        .zip(&split)
    {
        let split_weights = bind(&cage, split);
        // As binding the split cage itself, on the triangle kernel.
        let explicit = bind(split_cage, QuadSplit::None);
        assert!(max_difference(&split_weights, &explicit) <= 1e-6);
        let change = max_difference(&patches, &split_weights);
        eprintln!("  {} split: max |Δ| {change:.2e}", split.id());
        assert!(
            change > 1e-3,
            "{} split changes only {change:e}",
            split.id()
        );
    }
}

#[test]
fn mvc_on_a_quad_cage_is_qmvc_bound_on_the_cpu_and_said_so() {
    let Some(context) = test_context("QMVC") else {
        return;
    };
    let cage = quad_comb(3, 1.0, 0.5, 3.0, 1.0, 0.3);
    let input = input(&cage, mixed_points(&cage, 200, 3), Method::Mvc);
    let output = bind_on(&context, &input);
    assert_eq!(output.stats.gpu_rows, 0, "no row from the triangle kernel");
    assert_eq!(output.stats.device, "CPU");
    let weights = output.weights.expect("CPU weights");
    // coords::bind_cpu is MVC's CPU path, QMVC on quads.
    assert_eq!(weights, cpu(&input));
    let work = Work::of(input.options, input.points.len(), &cage);
    let decision = decide(BackendRequest::Gpu, Some(&context), &work);
    assert!(!decision.on_gpu(Method::Mvc));
    let line = decision.explain();
    assert!(
        line.starts_with("binding on the CPU") && line.contains("QMVC"),
        "{line}"
    );
    // Split quads are triangles again, and the MVC kernel takes them.
    let split = input.with_options(BindOptions {
        quads: QuadSplit::Shorter,
        ..input.options
    });
    let work = Work::of(split.options, split.points.len(), &cage);
    assert!(decide(BackendRequest::Gpu, Some(&context), &work).on_gpu(Method::Mvc));
    let output = bind_on(&context, &split);
    assert!(output.stats.gpu_rows > 0);
    assert_agree(
        "split MVC",
        &split,
        &output.weights.expect("CPU weights"),
        &cpu(&split),
    );
}

#[test]
fn green_on_a_quad_cage_is_qgc_on_the_cpu_and_its_split_binds_on_the_gpu() {
    let Some(context) = test_context("Green on quads") else {
        return;
    };
    let cage = twisted_box(2.0, 0.6);
    let input = input(&cage, mixed_points(&cage, 200, 4), Method::Green);
    let output = bind_on(&context, &input);
    assert_eq!(output.stats.gpu_rows, 0, "QGC has no GPU kernel");
    assert_eq!(output.weights.expect("CPU weights"), cpu(&input));
    let split = input.with_options(BindOptions {
        quads: QuadSplit::Shorter,
        ..input.options
    });
    let output = bind_on(&context, &split);
    assert!(output.stats.gpu_rows > 0);
    assert_agree(
        "split Green",
        &split,
        &output.weights.expect("CPU weights"),
        &cpu(&split),
    );
}
