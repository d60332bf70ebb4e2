//! Weights split by rows over several storage buffers (`render::weight_chunks`): on
//! a device whose storage bindings hold only a part of the default scene's weights,
//! the shaders deform and colour the mesh exactly as the CPU weights say, and a
//! matrix beyond the device's buffers is refused with its sizes; and the column
//! displacements the blend reads from a uniform copy give way to the storage
//! buffer past that copy's columns. See `common::editor` for how a missing GPU is
//! handled.

use crate::common;

use common::editor::*;
use egui_kittest::Harness;
use pmvc::app::{EditorApp, EditorOptions};
use pmvc::coords::Method;
use pmvc::geometry::procedural;
use pmvc::render::weight_chunks::{ChunkLimits, UNIFORM_COLUMNS};
use pmvc::render::{Colouring, Shading};

/// Small storage bindings: 256 KiB, a fifth of the default scene's weights (and
/// room for its rest positions and readback output, which are not split).
const BINDING_BYTES: u64 = 256 << 10;

fn limits(storage_buffers_per_stage: u32) -> wgpu::Limits {
    wgpu::Limits {
        max_storage_buffer_binding_size: BINDING_BYTES,
        max_storage_buffers_per_shader_stage: storage_buffers_per_stage,
        ..Default::default()
    }
}

/// The default scene, posed (the guide's bent prong), bound on a device with `limits`.
fn posed_editor_on(limits: wgpu::Limits) -> Option<Harness<'static, EditorApp>> {
    let mut harness = editor_on(
        render_state_limited_to(limits)?,
        EditorOptions {
            pose: Some(guide_pose()),
            ..Default::default()
        },
    );
    run_until_bound(&mut harness);
    harness.run_steps(3);
    Some(harness)
}

fn read_back(app: &EditorApp, shading: Shading) -> pmvc::render::ReadBack {
    app.read_back(&shading)
        .expect("a GPU scene")
        .expect("read back")
}

#[test]
fn chunked_weights_deform_and_colour_the_mesh_as_the_cpu_does() {
    let device_limits = limits(32);
    let Some(harness) = posed_editor_on(device_limits.clone()) else {
        return;
    };
    let app = harness.state();
    assert_eq!(app.last_error(), None);
    let document = app.document();
    let chunks = ChunkLimits::of(&device_limits);
    for method in [Method::Pmvc, Method::Mvc] {
        let weights = document.weights(method).expect("bound");
        let split = chunks.split(weights.rows, weights.cols).expect("fits");
        assert!(split.chunks >= 3, "{method:?} is split: {split:?}");
    }
    let diagonal = document.cage().diagonal();
    let tolerance = (1e-5 * diagonal) as f32;
    let cpu = |method| -> Vec<glam::Vec3> {
        let positions = document.deformed_positions(method);
        positions.iter().map(|p| p.as_vec3()).collect()
    };
    let (pmvc, mvc) = (cpu(Method::Pmvc), cpu(Method::Mvc));
    let rest = rest_positions(app);
    assert!(max_distance(&pmvc, &rest) > 0.05 * diagonal as f32, "posed");

    for (method, expected) in [(Method::Pmvc, &pmvc), (Method::Mvc, &mvc)] {
        let shading = Shading {
            method,
            ..Default::default()
        };
        let gpu = read_back(app, shading).positions;
        let error = max_distance(&gpu, expected);
        assert!(error < tolerance, "{method:?}: {error} of {diagonal}");
    }

    // The difference view reads the compared family from the chunks after the
    // shown family's.
    let difference = read_back(
        app,
        Shading {
            method: Method::Pmvc,
            against: Some(Method::Mvc.into()),
            colouring: Colouring::MethodDistance,
            cage_size: diagonal as f32,
            ..Default::default()
        },
    );
    let worst = difference
        .values
        .iter()
        .zip(pmvc.iter().zip(&mvc))
        .map(|(value, (p, q))| (value - p.distance(*q) / diagonal as f32).abs())
        .fold(0.0, f32::max);
    assert!(
        worst < 1e-5,
        "distances over the diagonal differ by {worst}"
    );

    // Single weights come from the right chunk and row.
    let weights = document.weights(Method::Mvc).expect("bound");
    let column = weights.cols - 1;
    let heat = read_back(
        app,
        Shading {
            method: Method::Mvc,
            colouring: Colouring::CageVertexWeight(column as u32),
            ..Default::default()
        },
    );
    let expected: Vec<f32> = (0..weights.rows)
        .map(|row| weights.values[row * weights.cols + column])
        .collect();
    assert_eq!(heat.values, expected);
}

#[test]
fn weights_beyond_the_devices_buffers_are_refused_with_their_sizes() {
    // Eight storage buffers per stage leave one weights chunk per family.
    let Some(harness) = posed_editor_on(limits(8)) else {
        return;
    };
    let app = harness.state();
    let weights = app
        .document()
        .weights(Method::Pmvc)
        .expect("bound on the CPU");
    let error = app.last_error().expect("a notice");
    let sizes = format!("{} mesh vertices × {} columns", weights.rows, weights.cols);
    assert!(
        error.contains(&sizes) && error.contains("at most 1 × 0.25 MiB"),
        "{error}"
    );
    let rest = rest_positions(app);
    let shown = app
        .read_back_deformed()
        .expect("a GPU scene")
        .expect("read back");
    assert_eq!(shown, rest, "the mesh stays at rest without weights");
}

#[test]
fn columns_past_the_uniform_copy_of_the_displacements_still_move_the_mesh() {
    // 2,562 cage vertices: MVC columns well past the uniform copy's 1,024.
    let cage = procedural::icosphere(1.0, 4);
    assert!(cage.vertex_count() > 2 * UNIFORM_COLUMNS as usize);
    let inside = procedural::points_inside(&cage, 150, 11, 0.02);
    // Translating the whole cage moves every column by the same vector, so with
    // weights summing to 1 every mesh vertex moves by exactly that vector.
    let shift = glam::DVec3::new(0.3, -0.2, 0.1);
    let moved: Vec<glam::DVec3> = cage.positions().iter().map(|p| *p + shift).collect();
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, pose) = common::posed_scene_files(dir.path(), &cage, &inside, &moved);
    let Some(state) = render_state() else {
        return;
    };
    let mut harness = editor_on(
        state,
        EditorOptions {
            mesh: Some(mesh),
            cage: Some(cage_path),
            pose: Some(pose),
            method: Some(Method::Mvc),
            ..Default::default()
        },
    );
    run_until_bound(&mut harness);
    let app = harness.state();
    assert_eq!(app.last_error(), None);
    let weights = app.document().weights(Method::Mvc).expect("bound");
    // The columns past the copy carry much of each row, so leaving them out
    // would leave the mesh far behind the cage.
    let tail_share = (0..weights.rows)
        .map(|row| {
            let values = &weights.values[row * weights.cols..(row + 1) * weights.cols];
            values[UNIFORM_COLUMNS as usize..].iter().sum::<f32>()
        })
        .fold(f32::INFINITY, f32::min);
    assert!(tail_share > 0.05, "{tail_share}");
    let expected: Vec<glam::Vec3> = inside.iter().map(|p| (*p + shift).as_vec3()).collect();
    let gpu = read_back(
        app,
        Shading {
            method: Method::Mvc,
            ..Default::default()
        },
    )
    .positions;
    let error = max_distance(&gpu, &expected);
    assert!(error < 1e-4, "{error}");
}
