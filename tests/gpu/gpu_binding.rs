//! GPU binds agree with the CPU reference, batch as configured, report progress and
//! cancel. Without an adapter each test says it was not run, unless
//! `PMVC_REQUIRE_GPU=1`, which turns a missing adapter into a failure.

use crate::gpu_support;
use gpu_support::*;

use glam::DVec3;
use pmvc::coords::{BindOptions, BindProgress, Method, Weights};
use pmvc::geometry::procedural::{cube_cage, points_inside};
use pmvc::geometry::PointClass;
use pmvc::gpu::{
    Backend, BatchSize, BindConfig, BindError, BindInput, Binder, GpuContext, GpuWeights,
};
use std::sync::Arc;
use std::time::{Duration, Instant};

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
        ..BindConfig::default()
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
            ..BindConfig::default()
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
        ..BindConfig::default()
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
