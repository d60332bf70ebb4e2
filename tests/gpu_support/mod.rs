//! Helpers shared by the GPU binding suites: the test device, scenes, and binds
//! on both backends compared.
#![allow(dead_code)]

use glam::DVec3;
use pmvc::coords::{bind_cpu, BindOptions, BindProgress, Method, Weights};
use pmvc::geometry::procedural::{comb_outline, extrude, star_outline};
use pmvc::geometry::{classify_points, Cage, PointClass};
use pmvc::gpu::{Backend, BatchSize, BindConfig, BindInput, Binder, GpuContext, PmvcKernel};
use std::io::Write as _;
use std::sync::{Arc, OnceLock};
use std::time::Duration;

/// The shared test device, or `None` (after saying so) when there is no adapter.
/// With `PMVC_REQUIRE_GPU=1` a missing adapter fails the test instead.
pub fn test_context(test: &str) -> Option<Arc<GpuContext>> {
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

pub fn comb() -> Cage {
    extrude(&comb_outline(5, 1.0, 0.25, 4.0), -0.5, 0.5)
}

pub fn star() -> Cage {
    extrude(&star_outline(6, 0.4, 1.0), -0.3, 0.3)
}

pub fn input(cage: &Cage, points: Vec<DVec3>, method: Method) -> BindInput {
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
pub fn mixed_points(cage: &Cage, count: usize, seed: u64) -> Vec<DVec3> {
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

pub fn cpu(input: &BindInput) -> Weights {
    bind_cpu(
        &input.points,
        &input.classes,
        &input.cage,
        input.options,
        &BindProgress::default(),
    )
    .expect("not cancelled")
}

pub fn gpu(context: &Arc<GpuContext>, input: &BindInput, batch: BatchSize) -> Weights {
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
pub fn assert_agree(name: &str, input: &BindInput, gpu: &Weights, cpu: &Weights) {
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

pub fn check_scene(test: &str, cage: &Cage, points: Vec<DVec3>) {
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

/// PMVC on the GPU against the CPU; returns the inside rows the GPU left to the CPU.
pub fn pmvc_agrees(
    test: &str,
    context: &Arc<GpuContext>,
    cage: &Cage,
    points: Vec<DVec3>,
) -> usize {
    pmvc_kernel_agrees(test, context, cage, points, PmvcKernel::Auto, 32)
}

/// [`pmvc_agrees`] with the PMVC kernel and the cube-map resolution chosen.
pub fn pmvc_kernel_agrees(
    test: &str,
    context: &Arc<GpuContext>,
    cage: &Cage,
    points: Vec<DVec3>,
    kernel: PmvcKernel,
    resolution: u32,
) -> usize {
    let mut input = input(cage, points, Method::Pmvc);
    input.options.resolution = resolution;
    let expected = cpu(&input);
    let config = BindConfig {
        pmvc_kernel: kernel,
        ..BindConfig::default()
    };
    let output = Binder::new(Backend::Gpu(Arc::clone(context)))
        .with_config(config)
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
