//! GPU binds agree with the CPU reference, batch as configured, report progress and
//! cancel. Without an adapter each test says it was not run, unless
//! `PMVC_REQUIRE_GPU=1`, which turns a missing adapter into a failure.

use glam::DVec3;
use pmvc::coords::{bind_cpu, BindOptions, BindProgress, Method, Weights};
use pmvc::geometry::procedural::{
    comb_outline, cube_cage, extrude, points_inside, refine_outline, star_outline,
};
use pmvc::geometry::{classify_points, Cage, PointClass, TriMesh};
use pmvc::gpu::{
    Backend, BatchSize, BindConfig, BindError, BindInput, Binder, GpuContext, GpuWeights,
};
use std::io::Write as _;
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

/// The shared test device, or `None` (after saying so) when there is no adapter.
/// With `PMVC_REQUIRE_GPU=1` a missing adapter fails the test instead.
fn test_context(test: &str) -> Option<Arc<GpuContext>> {
    static CONTEXT: OnceLock<Result<Arc<GpuContext>, String>> = OnceLock::new();
    let context = CONTEXT.get_or_init(|| {
        let context = GpuContext::new().map(Arc::new).map_err(|e| e.to_string());
        if let Ok(context) = &context {
            eprintln!("GPU tests run on {}", context.describe());
        }
        context
    });
    match context {
        Ok(context) => Some(Arc::clone(context)),
        Err(error) => {
            if std::env::var("PMVC_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                panic!("PMVC_REQUIRE_GPU=1 but no GPU: {error}");
            }
            // Straight to stderr: the harness captures `eprintln!`, and a skip should show.
            let _ = writeln!(
                std::io::stderr(),
                "{test}: not run, no GPU adapter ({error})"
            );
            None
        }
    }
}

fn comb() -> Cage {
    extrude(&comb_outline(5, 1.0, 0.25, 4.0), -0.5, 0.5)
}

fn star() -> Cage {
    extrude(&star_outline(6, 0.4, 1.0), -0.3, 0.3)
}

fn input(cage: &Cage, points: Vec<DVec3>, method: Method) -> BindInput {
    let classes = classify_points(cage, &points).classes;
    BindInput {
        points: points.into(),
        classes: classes.into(),
        cage: Arc::new(cage.clone()),
        options: BindOptions {
            method,
            resolution: 32,
            ..Default::default()
        },
    }
}

/// Uniform points in the cage's bounding box grown by 10% (inside and outside),
/// plus every cage vertex and triangle centroid (on the surface).
fn mixed_points(cage: &Cage, count: usize, seed: u64) -> Vec<DVec3> {
    let (lo, hi) = pmvc::geometry::bounds_of(cage.positions());
    let (lo, hi) = (lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo));
    let mut random = pmvc::geometry::procedural::SplitMix64(seed);
    let mut points: Vec<DVec3> = (0..count)
        .map(|_| lo + (hi - lo) * DVec3::new(random.unit(), random.unit(), random.unit()))
        .collect();
    points.extend(cage.positions());
    points.extend((0..cage.triangles().len()).map(|t| {
        let [a, b, c] = cage.triangle(t);
        (a + b + c) / 3.0
    }));
    points
}

fn cpu(input: &BindInput) -> Weights {
    bind_cpu(
        &input.points,
        &input.classes,
        &input.cage,
        input.options,
        &BindProgress::default(),
    )
    .expect("not cancelled")
}

fn gpu(context: &Arc<GpuContext>, input: &BindInput, batch: BatchSize) -> Weights {
    let config = BindConfig {
        batch,
        ..BindConfig::default()
    };
    let output = Binder::new(Backend::Gpu(Arc::clone(context)))
        .with_config(config)
        .bind_blocking(input, &BindProgress::default())
        .expect("GPU bind");
    eprintln!(
        "  {} rows: {} on the GPU, {} on the CPU, {} batches, {:?}",
        input.points.len(),
        output.stats.gpu_rows,
        output.stats.cpu_rows,
        output.stats.batches,
        output.stats.elapsed
    );
    // `pmvc bench` reports this share: the GPU's part of the bind, never all of it.
    if output.stats.gpu_rows > 0 {
        let wait = output.stats.gpu_wait;
        assert!(
            wait > Duration::ZERO && wait < output.stats.elapsed,
            "waited {wait:?} on the GPU in a bind of {:?}",
            output.stats.elapsed
        );
    }
    output.weights.expect("CPU weights requested")
}

/// max |Δ| ≤ 2e-4 and mean |Δ| ≤ 5e-6; for PMVC also no negative weight inside.
fn assert_agree(name: &str, input: &BindInput, gpu: &Weights, cpu: &Weights) {
    assert_eq!((gpu.rows, gpu.cols), (cpu.rows, cpu.cols), "{name}: shape");
    let mut max: f64 = 0.0;
    let mut sum = 0.0;
    let mut worst = 0;
    for (k, (&g, &c)) in gpu.values.iter().zip(&cpu.values).enumerate() {
        // NaN counts as the worst difference.
        let delta = (f64::from(g) - f64::from(c)).abs();
        let delta = if delta.is_nan() { f64::INFINITY } else { delta };
        if delta > max {
            max = delta;
            worst = k;
        }
        sum += delta;
    }
    let mean = sum / gpu.values.len().max(1) as f64;
    eprintln!("  {name}: max |Δ| = {max:.3e}, mean |Δ| = {mean:.3e}");
    let row = worst / gpu.cols.max(1);
    assert!(
        max <= 2e-4,
        "{name}: max |Δ| = {max:e} at row {row} ({:?}, {:?})",
        input.points[row],
        input.classes[row]
    );
    assert!(mean <= 5e-6, "{name}: mean |Δ| = {mean:e}");
    if input.options.method == Method::Pmvc {
        for (row, class) in input.classes.iter().enumerate() {
            if *class == PointClass::Inside {
                let min = gpu.row(row).iter().copied().fold(f32::INFINITY, f32::min);
                assert!(
                    min >= 0.0,
                    "{name}: negative PMVC weight {min} at row {row}"
                );
            }
        }
    }
}

fn check_scene(test: &str, cage: &Cage, points: Vec<DVec3>) {
    let Some(context) = test_context(test) else {
        return;
    };
    for method in [Method::Pmvc, Method::Mvc] {
        let input = input(cage, points.clone(), method);
        let expected = cpu(&input);
        let actual = gpu(&context, &input, BatchSize::default());
        assert_agree(
            &format!("{test} {}", method.name()),
            &input,
            &actual,
            &expected,
        );
    }
}

#[test]
fn cube_agrees_with_cpu() {
    let cage = cube_cage(1.0);
    let mut points = points_inside(&cage, 500, 1, 1e-3);
    // Symmetric points send texel rays exactly through shared edges and corners,
    // where two triangles reach the same depth.
    points.extend([
        DVec3::ZERO,
        DVec3::new(0.5, 0.0, 0.0),
        DVec3::new(0.25, 0.25, 0.0),
        DVec3::new(-0.5, 0.5, 0.5),
    ]);
    check_scene("cube", &cage, points);
}

#[test]
fn comb_agrees_with_cpu() {
    let cage = comb();
    let points = points_inside(&cage, 500, 2, 1e-3);
    check_scene("comb", &cage, points);
}

#[test]
fn star_agrees_with_cpu() {
    let cage = star();
    let points = points_inside(&cage, 500, 3, 1e-3);
    check_scene("star", &cage, points);
}

#[test]
fn random_points_inside_outside_and_on_the_surface_agree_with_cpu() {
    let cage = comb();
    let points = mixed_points(&cage, 2000, 4);
    check_scene("random 2000", &cage, points);
}

/// PMVC on the GPU against the CPU; returns the inside rows the GPU left to the CPU.
fn pmvc_agrees(test: &str, context: &Arc<GpuContext>, cage: &Cage, points: Vec<DVec3>) -> usize {
    let input = input(cage, points, Method::Pmvc);
    let expected = cpu(&input);
    let output = Binder::new(Backend::Gpu(Arc::clone(context)))
        .bind_blocking(&input, &BindProgress::default())
        .expect("GPU bind");
    let inside = input.classes.iter().filter(|c| **c == PointClass::Inside);
    let redone = inside.count() - output.stats.gpu_rows;
    eprintln!("  {test}: {redone} inside rows redone on the CPU");
    assert_agree(
        test,
        &input,
        &output.weights.expect("CPU weights"),
        &expected,
    );
    redone
}

#[test]
fn a_cage_of_more_than_1500_vertices_agrees_with_cpu() {
    let Some(context) = test_context("1500+ vertices") else {
        return;
    };
    // A comb with 1,600 vertices: more triangles per cube face than one chunk of
    // set-ups holds, and teeth hiding one another.
    let outline = refine_outline(&comb_outline(8, 1.0, 0.25, 4.0), 800);
    let cage = extrude(&outline, -0.5, 0.5);
    assert!(
        cage.vertex_count() >= 1500,
        "{} vertices",
        cage.vertex_count()
    );
    let redone = pmvc_agrees(
        "1500+ vertices",
        &context,
        &cage,
        points_inside(&cage, 120, 6, 1e-3),
    );
    assert_eq!(redone, 0);
}

#[test]
fn an_eight_vertex_box_whose_triangles_cover_whole_faces_agrees_with_cpu() {
    let Some(context) = test_context("eight-vertex box") else {
        return;
    };
    // Stretched, so that one triangle spans several cube-map faces from inside.
    let cube = cube_cage(1.0);
    let stretched: Vec<DVec3> = cube
        .positions()
        .iter()
        .map(|p| *p * DVec3::new(4.0, 1.0, 0.5))
        .collect();
    let triangles = cube.triangles().to_vec();
    let mesh = TriMesh {
        positions: stretched,
        triangle_faces: (0..triangles.len() as u32).collect(),
        triangles,
    };
    let (cage, _) = Cage::new(mesh).expect("a box");
    assert_eq!(cage.vertex_count(), 8);
    let mut points = points_inside(&cage, 300, 7, 1e-3);
    points.extend([
        DVec3::ZERO,
        DVec3::new(3.5, 0.0, 0.0),
        DVec3::new(-1.0, 0.9, 0.45),
    ]);
    let redone = pmvc_agrees("eight-vertex box", &context, &cage, points);
    assert_eq!(redone, 0);
}

#[test]
fn points_close_to_the_cage_agree_with_cpu_and_few_go_to_the_cpu() {
    let Some(context) = test_context("close to the cage") else {
        return;
    };
    let cage = comb();
    let diagonal = cage.diagonal();
    // Each triangle's centroid and a point near its first corner, moved inwards by
    // 1e-3 to 1e-6 of the diagonal.
    let mut points = Vec::new();
    for (t, corners) in cage.triangles().iter().enumerate() {
        let [a, b, c] = corners.map(|k| cage.positions()[k as usize]);
        let inward = -(b - a).cross(c - a).normalize();
        let depth = diagonal * [1e-3, 1e-4, 1e-5, 1e-6][t % 4];
        points.push((a + b + c) / 3.0 + depth * inward);
        points.push(0.9 * a + 0.05 * (b + c) + depth * inward);
    }
    let classes = classify_points(&cage, &points).classes;
    let inside = classes.iter().filter(|c| **c == PointClass::Inside).count();
    assert!(
        inside * 10 >= points.len() * 9,
        "{inside} of {} inside",
        points.len()
    );
    let redone = pmvc_agrees("close to the cage", &context, &cage, points);
    // Rays that escape through the nearest triangle's edges send a row to the CPU;
    // most rows must still be the kernel's.
    assert!(
        redone * 20 <= inside,
        "{redone} of {inside} inside rows redone on the CPU"
    );
}

#[test]
fn several_batches_give_the_same_weights_as_one() {
    let Some(context) = test_context("several batches") else {
        return;
    };
    let cage = star();
    for method in [Method::Pmvc, Method::Mvc] {
        let input = input(&cage, mixed_points(&cage, 300, 5), method);
        let rows = input.points.len();
        let one = gpu(&context, &input, BatchSize::Fixed(rows));
        let many = gpu(&context, &input, BatchSize::Fixed(37));
        assert_eq!(one, many, "{}: batching changed the weights", method.name());
    }
}

#[test]
fn resident_gpu_weights_match_the_readback() {
    let Some(context) = test_context("resident weights") else {
        return;
    };
    let cage = comb();
    let input = input(&cage, mixed_points(&cage, 200, 6), Method::Pmvc);
    let config = BindConfig {
        cpu_weights: true,
        gpu_buffer: true,
        batch: BatchSize::Fixed(50),
    };
    let output = Binder::new(Backend::Gpu(Arc::clone(&context)))
        .with_config(config)
        .bind_blocking(&input, &BindProgress::default())
        .expect("GPU bind");
    let weights = output.weights.expect("CPU weights requested");
    let resident = output.gpu_weights.expect("GPU weights requested");
    assert_eq!((resident.rows, resident.cols), (weights.rows, weights.cols));
    assert_eq!(read_resident(&context, &resident), weights);
}

/// Copy a resident weights matrix back to the CPU.
fn read_resident(context: &GpuContext, resident: &GpuWeights) -> Weights {
    let bytes = (resident.rows * resident.cols * 4) as u64;
    let staging = context.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = context
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    encoder.copy_buffer_to_buffer(&resident.buffer, 0, &staging, 0, bytes);
    context.queue.submit([encoder.finish()]);
    staging.map_async(wgpu::MapMode::Read, .., |result| result.expect("map"));
    context
        .device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll");
    let values: Vec<f32> =
        bytemuck::pod_collect_to_vec(&staging.get_mapped_range(..).expect("mapped"));
    Weights {
        rows: resident.rows,
        cols: resident.cols,
        values,
    }
}

#[test]
fn a_handed_in_device_keeps_the_weights_on_the_gpu_only() {
    let Some(shared) = test_context("handed-in device") else {
        return;
    };
    // As the editor does with eframe's device and queue.
    let context = Arc::new(GpuContext::from_device(
        shared.device.clone(),
        shared.queue.clone(),
        shared.info.clone(),
    ));
    let cage = star();
    for method in [Method::Pmvc, Method::Mvc] {
        let input = input(&cage, mixed_points(&cage, 300, 12), method);
        let config = BindConfig {
            cpu_weights: false,
            gpu_buffer: true,
            batch: BatchSize::default(),
        };
        let output = Binder::new(Backend::Gpu(Arc::clone(&context)))
            .with_config(config)
            .bind_blocking(&input, &BindProgress::default())
            .expect("GPU bind");
        assert!(output.weights.is_none());
        let resident = output.gpu_weights.expect("GPU weights requested");
        let name = format!("handed-in {}", method.name());
        assert_agree(
            &name,
            &input,
            &read_resident(&context, &resident),
            &cpu(&input),
        );
    }
}

#[test]
fn progress_is_monotone_and_reaches_the_total() {
    let Some(context) = test_context("progress") else {
        return;
    };
    let cage = comb();
    let input = input(&cage, points_inside(&cage, 400, 7, 1e-3), Method::Pmvc);
    let binder = Binder::new(Backend::Gpu(context)).with_config(BindConfig {
        batch: BatchSize::Fixed(40),
        ..BindConfig::default()
    });
    let mut handle = binder.start(input.clone());
    let progress = Arc::clone(handle.progress());
    let snapshot = || (progress.done(), progress.total());
    let mut seen = Vec::new();
    let result = loop {
        seen.push(snapshot());
        if let Some(result) = handle.try_take() {
            break result;
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    seen.push(snapshot());
    let output = result.expect("bind finishes");
    assert!(output.stats.batches >= 10);
    assert!(seen.windows(2).all(|w| w[0].0 <= w[1].0), "{seen:?}");
    assert!(seen.iter().all(|&(_, total)| total == 400));
    assert_eq!(seen.last(), Some(&(400, 400)));
    assert!(handle.try_take().is_none(), "the result is taken once");
}

#[test]
fn cancel_returns_within_a_batch_without_a_result() {
    let Some(context) = test_context("cancel") else {
        return;
    };
    let cage = comb();
    let input = input(&cage, points_inside(&cage, 3000, 8, 1e-3), Method::Pmvc);
    // Adaptive batches of about 75 ms.
    let handle = Binder::new(Backend::Gpu(context)).start(input);
    while handle.progress().done() < 100 && !handle.is_finished() {
        std::thread::sleep(Duration::from_millis(1));
    }
    let cancelled_at = Instant::now();
    let done_at_cancel = handle.progress().done();
    handle.cancel();
    let result = handle.wait();
    let waited = cancelled_at.elapsed();
    assert!(
        matches!(result, Err(BindError::Cancelled)),
        "expected a cancel, got {result:?}"
    );
    assert!(done_at_cancel < 3000, "the bind finished before the cancel");
    eprintln!("  cancel took {waited:?}");
    // One batch, with room for other tests' batches queued on the shared device.
    assert!(waited < Duration::from_secs(2), "cancel took {waited:?}");
}

#[test]
fn the_cpu_backend_reports_progress_and_honours_a_cancel() {
    let cage = cube_cage(1.0);
    let input = input(&cage, points_inside(&cage, 100, 9, 1e-3), Method::Pmvc);
    let binder = Binder::new(Backend::Cpu);
    let progress = BindProgress::new(100);
    let output = binder.bind_blocking(&input, &progress).expect("CPU bind");
    assert_eq!(progress.done(), 100, "every row counted once");
    assert_eq!(output.stats.cpu_rows, 100);
    assert_eq!(output.weights.expect("weights").rows, 100);
    let cancelled = BindProgress::new(100);
    cancelled.cancel();
    let result = binder.bind_blocking(&input, &cancelled);
    assert!(matches!(result, Err(BindError::Cancelled)), "{result:?}");
}

#[test]
fn a_resident_matrix_beyond_the_limits_is_an_error() {
    let Some(context) = test_context("too large") else {
        return;
    };
    let cage = pmvc::geometry::procedural::icosphere(1.0, 3);
    let limit = context.limits.max_storage_buffer_binding_size;
    let rows = (limit / (4 * cage.vertex_count() as u64)) as usize + 1;
    let input = BindInput {
        points: vec![DVec3::splat(5.0); rows].into(),
        classes: vec![PointClass::Outside; rows].into(),
        cage: Arc::new(cage),
        options: BindOptions::default(),
    };
    let config = BindConfig {
        cpu_weights: false,
        gpu_buffer: true,
        batch: BatchSize::default(),
    };
    let result = Binder::new(Backend::Gpu(context))
        .with_config(config)
        .bind_blocking(&input, &BindProgress::default());
    assert!(
        matches!(
            result,
            Err(BindError::Gpu(pmvc::gpu::GpuError::TooLarge { .. }))
        ),
        "{result:?}"
    );
}

#[test]
fn a_lost_device_is_an_error_not_a_panic() {
    if test_context("device loss").is_none() {
        return;
    }
    // A device of its own: destroying the shared one would break the other tests.
    let context = Arc::new(GpuContext::new().expect("a second device"));
    let cage = cube_cage(1.0);
    let input = input(&cage, points_inside(&cage, 50, 11, 1e-3), Method::Pmvc);
    context.device.destroy();
    let result = Binder::new(Backend::Gpu(context))
        .with_config(BindConfig::default())
        .bind_blocking(&input, &BindProgress::default());
    assert!(matches!(result, Err(BindError::Gpu(_))), "{result:?}");
}

#[test]
fn the_adapters_report_names_the_choice_and_the_limits() {
    let report = pmvc::gpu::adapters_report();
    eprintln!("{report}");
    match test_context("adapters report") {
        // The adapter the binds run on is the one reported as chosen, with the
        // limits of that adapter.
        Some(context) => {
            let chosen = report
                .lines()
                .find(|line| line.starts_with("chosen: "))
                .expect("a chosen line");
            assert!(chosen.contains(&context.info.name), "{report}");
            let limit = format!(
                "max storage buffer binding size: {} bytes",
                context.limits.max_storage_buffer_binding_size
            );
            assert!(report.contains(&limit), "{report}");
        }
        None => assert!(report.contains("chosen: none"), "{report}"),
    }
}

/// Green coordinates on the GPU: every φ and ψ within 1e-5 of the CPU's f64 values,
/// on a convex and two non-convex cages, for points inside (some 1e-4 of the
/// diagonal from the surface), on the surface and outside. Rows the kernel cannot
/// trust are redone on the CPU; most inside rows must stay on the GPU, or the
/// agreement would say nothing about the kernel.
#[test]
fn green_coordinates_agree_with_the_cpu_to_1e_5() {
    let Some(context) = test_context("green") else {
        return;
    };
    for (name, cage) in [("cube", cube_cage(1.0)), ("comb", comb()), ("star", star())] {
        let mut points = mixed_points(&cage, 600, 6);
        points.extend(points_inside(&cage, 400, 7, 1e-4));
        let input = input(&cage, points, Method::Green);
        let expected = cpu(&input);
        let output = Binder::new(Backend::Gpu(Arc::clone(&context)))
            .bind_blocking(&input, &BindProgress::default())
            .expect("GPU bind");
        let actual = output.weights.expect("CPU weights requested");
        assert_eq!(actual.cols, cage.vertex_count() + cage.triangle_count());
        let worst = actual
            .values
            .iter()
            .zip(&expected.values)
            .map(|(&g, &c)| {
                let delta = (f64::from(g) - f64::from(c)).abs();
                if delta.is_nan() {
                    f64::INFINITY
                } else {
                    delta
                }
            })
            .fold(0.0, f64::max);
        let inside = input
            .classes
            .iter()
            .filter(|class| matches!(class, PointClass::Inside))
            .count();
        let flagged = output.stats.cpu_rows - (input.points.len() - inside);
        eprintln!(
            "  green {name}: max |Δ| = {worst:.2e}; {flagged} of {inside} inside rows redone on the CPU"
        );
        assert!(worst <= 1e-5, "green {name}: max |Δ| = {worst:e}");
        assert!(
            flagged * 20 <= inside,
            "green {name}: {flagged} of {inside} inside rows flagged"
        );
    }
}
