//! The viewport reads the first weights columns of each row as vertex attributes
//! (`render::weight_attributes`) and the rest from storage. These tests read back
//! what the vertex shader draws (`render::drawn`) and compare it with the CPU's
//! deformation, for rows wholly in attributes, rows that go on past them, and
//! weights split over several buffers, which are drawn from storage alone. See
//! `common::editor` for how a missing GPU is handled.

use crate::common;

use common::editor::*;
use egui_kittest::Harness;
use glam::{DVec3, Vec3};
use pmvc::app::{EditorApp, EditorOptions};
use pmvc::coords::Method;
use pmvc::geometry::procedural;

/// The editor with `options` on `state`'s device, bound without a notice.
fn bound_on(
    state: Option<eframe::egui_wgpu::RenderState>,
    options: EditorOptions,
) -> Option<Harness<'static, EditorApp>> {
    let mut harness = editor_on(state?, options);
    run_until_bound(&mut harness);
    assert_eq!(harness.state().last_error(), None);
    Some(harness)
}

fn drawn(app: &EditorApp, method: Method) -> Vec<Vec3> {
    app.read_back_drawn(method)
        .expect("a GPU scene")
        .expect("read back")
}

#[test]
fn rows_read_as_vertex_attributes_draw_the_cpu_deformation() {
    let options = EditorOptions {
        pose: Some(guide_pose()),
        ..Default::default()
    };
    let Some(harness) = bound_on(render_state(), options) else {
        return;
    };
    let app = harness.state();
    let document = app.document();
    let diagonal = document.cage().diagonal() as f32;
    let rest = rest_positions(app);
    for method in [Method::Pmvc, Method::Mvc] {
        let columns = document.weights(method).expect("bound").cols as u32;
        assert_eq!(app.attribute_columns(method), Some(columns), "{method:?}");
        let expected: Vec<Vec3> = document
            .deformed_positions(method)
            .iter()
            .map(|p| p.as_vec3())
            .collect();
        assert!(max_distance(&expected, &rest) > 0.05 * diagonal, "posed");
        let error = max_distance(&drawn(app, method), &expected);
        assert!(error < 1e-5 * diagonal, "{method:?}: {error} of {diagonal}");
    }
}

#[test]
fn columns_past_the_vertex_attributes_come_from_storage() {
    // 162 cage vertices: more columns than any device's vertex attributes hold.
    let cage = procedural::icosphere(1.0, 2);
    let inside = procedural::points_inside(&cage, 200, 7, 0.02);
    // An affine pose: MVC reproduce affine maps, so every mesh vertex must land
    // on the same map of itself.
    let posed = |p: DVec3| DVec3::new(1.2 * p.x + 0.3, 0.9 * p.y - 0.2, p.z + 0.1 * p.x);
    let moved: Vec<DVec3> = cage.positions().iter().map(|&p| posed(p)).collect();
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage_path, pose) = common::posed_scene_files(dir.path(), &cage, &inside, &moved);
    let options = EditorOptions {
        mesh: Some(mesh),
        cage: Some(cage_path),
        pose: Some(pose),
        method: Some(Method::Mvc),
        ..Default::default()
    };
    let Some(harness) = bound_on(render_state(), options) else {
        return;
    };
    let app = harness.state();
    let weights = app.document().weights(Method::Mvc).expect("bound");
    let in_attributes = app
        .attribute_columns(Method::Mvc)
        .expect("read as attributes") as usize;
    assert!(in_attributes < weights.cols, "{in_attributes}");
    // The columns past the attributes carry much of each row, so leaving them
    // out would leave the mesh far from its place.
    let tail_share = (0..weights.rows)
        .map(|row| {
            weights.values[row * weights.cols..(row + 1) * weights.cols][in_attributes..]
                .iter()
                .sum::<f32>()
        })
        .fold(f32::INFINITY, f32::min);
    assert!(tail_share > 0.05, "{tail_share}");
    let expected: Vec<Vec3> = inside.iter().map(|&p| posed(p).as_vec3()).collect();
    let error = max_distance(&drawn(app, Method::Mvc), &expected);
    assert!(error < 1e-4, "{error}");
}

#[test]
fn weights_split_over_several_buffers_are_drawn_from_storage() {
    // Storage bindings of 256 KiB: the default scene's weights take several.
    let limits = small_storage_bindings(256 << 10);
    let options = EditorOptions {
        pose: Some(guide_pose()),
        ..Default::default()
    };
    let Some(harness) = bound_on(render_state_limited_to(limits), options) else {
        return;
    };
    let app = harness.state();
    assert_eq!(app.attribute_columns(Method::Pmvc), None);
    let document = app.document();
    let expected: Vec<Vec3> = document
        .deformed_positions(Method::Pmvc)
        .iter()
        .map(|p| p.as_vec3())
        .collect();
    let diagonal = document.cage().diagonal() as f32;
    let error = max_distance(&drawn(app, Method::Pmvc), &expected);
    assert!(error < 1e-5 * diagonal, "{error} of {diagonal}");
}
