//! Somigliana coordinates in the editor: bound on demand, the vertex shader's
//! blend of their block columns (vectors recomputed per pose from the fitted
//! similarity) following a similarity of the cage and drawing what the CPU
//! computes for a pulled finger, and a vertex's heatmap showing its block's
//! x-from-x entry; the deformation settings (bulging, the local blend, whose
//! normalised columns the shader solves with) chosen in the side panel.

use crate::common;

use common::editor::*;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use glam::DVec3;
use pmvc::app::compare::{Overlay, Pane};
use pmvc::coords::{Method, Parameter};
use pmvc::render::Colouring;

/// The editor on its comb with Somigliana coordinates bound and shown
/// (`None` without a GPU, as `editor()`).
fn somigliana_shown() -> Option<Harness<'static, pmvc::app::EditorApp>> {
    let mut harness = editor()?;
    run_until_bound(&mut harness);
    harness.state_mut().set_active_method(Method::Somigliana);
    run_until_bound(&mut harness);
    Some(harness)
}

#[test]
fn somigliana_binds_follows_a_similarity_and_shows_a_block_entry() {
    let Some(mut harness) = somigliana_shown() else {
        return;
    };
    let app = harness.state();
    let cage = app.document().cage().clone();
    let (vertices, triangles) = (cage.vertex_count(), cage.triangle_count());
    let weights = app
        .document()
        .weights(Method::Somigliana)
        .expect("bound")
        .clone();
    assert_eq!(weights.cols, 9 * (vertices + triangles));
    let quality = app.document().bound(Method::Somigliana).unwrap().quality;
    assert!(quality.max_partition_error < 1e-5, "{quality:?}");

    // A rotation, scale and shift of the whole cage: the drawn mesh is the rest
    // mesh under the same map (to f32 blending).
    let expected = load_a_similarity_pose(&mut harness);
    let drawn = harness.state().read_back_deformed().unwrap().unwrap();
    let rest = rest_positions(harness.state());
    let worst = max_distance(&drawn, &expected);
    assert!(worst < 2e-4 * cage.diagonal() as f32, "similarity: {worst}");

    // A pulled finger tip: the drawn mesh is the CPU's f64 deformation.
    let mut pulled = cage.positions().to_vec();
    pulled[12] += DVec3::new(0.5, 1.0, 0.0);
    pulled[32] += DVec3::new(0.5, 1.0, 0.0);
    harness.state_mut().reset_pose();
    harness.state_mut().set_handle_position(12, pulled[12]);
    harness.state_mut().set_handle_position(32, pulled[32]);
    harness.run_steps(2);
    let app = harness.state();
    let drawn = app.read_back_deformed().unwrap().unwrap();
    let on_cpu: Vec<glam::Vec3> = (app.document().deformed_positions(Method::Somigliana))
        .iter()
        .map(|p| p.as_vec3())
        .collect();
    let worst = max_distance(&drawn, &on_cpu);
    assert!(worst < 1e-4 * cage.diagonal() as f32, "pulled: {worst}");
    assert!(max_distance(&drawn, &rest) > 0.3, "the finger moved");

    // Cage vertex 3's heatmap: column 27, the (x, x) entry of its block.
    harness.state_mut().view_mut().overlay = Overlay::Heatmap;
    harness.state_mut().view_mut().heat_vertex = 3;
    harness.run_steps(2);
    let shading = harness
        .state_mut()
        .shading_of(Pane::Method(Method::Somigliana));
    assert_eq!(shading.colouring, Colouring::CageVertexWeight(3));
    let read = harness.state().read_back(&shading).unwrap().unwrap();
    let column: Vec<f32> = (0..weights.rows).map(|r| weights.row(r)[27]).collect();
    for (drawn, stored) in read.values.iter().zip(&column) {
        assert!((drawn - stored).abs() < 1e-6, "{drawn} vs {stored}");
    }
    let range = (harness.state_mut())
        .value_range(shading.colouring, Pane::Method(Method::Somigliana))
        .unwrap();
    let low = column.iter().copied().fold(f32::INFINITY, f32::min);
    let high = column.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    assert_eq!((range.min, range.max), (low, high));
    // Triangle 5's function: the (x, x) entry of its face block.
    harness.state_mut().view_mut().heat_triangle = Some(5);
    harness.run_steps(2);
    let shading = harness
        .state_mut()
        .shading_of(Pane::Method(Method::Somigliana));
    let read = harness.state().read_back(&shading).unwrap().unwrap();
    let face_column = 9 * (vertices + 5);
    for (row, drawn) in read.values.iter().enumerate() {
        assert!(
            (drawn - weights.row(row)[face_column]).abs() < 1e-6,
            "row {row}"
        );
    }
}

/// Pick `choice` in the side panel's list `label`, which shows `current`;
/// then what the GPU draws and what the CPU computes.
fn choose_setting(
    harness: &mut Harness<'static, pmvc::app::EditorApp>,
    label: &str,
    current: &str,
    choice: &str,
) -> (Vec<glam::Vec3>, Vec<glam::Vec3>) {
    let list = harness.get_by_role_and_label(egui::accesskit::Role::ComboBox, label);
    assert_eq!(list.value().as_deref(), Some(current));
    list.click_accesskit();
    harness.run_steps(2);
    harness.get_by_label(choice).click_accesskit();
    harness.run_steps(3);
    let app = harness.state();
    let drawn = app.read_back_deformed().unwrap().unwrap();
    let on_cpu = (app.document().deformed_positions(Method::Somigliana))
        .iter()
        .map(|p| p.as_vec3())
        .collect();
    (drawn, on_cpu)
}

/// The side panel's bulging γ: chosen in its list, it moves the drawn mesh to
/// the CPU's bulged deformation with the same weights (nothing is bound
/// again), is one undo step, and is saved with the session.
#[test]
fn bulging_is_chosen_in_the_side_panel_and_undone() {
    let Some(mut harness) = somigliana_shown() else {
        return;
    };
    let weights = harness
        .state()
        .document()
        .weights(Method::Somigliana)
        .unwrap()
        .clone();
    let cage = harness.state().document().cage().clone();
    harness
        .state_mut()
        .set_handle_position(12, cage.positions()[12] + DVec3::new(0.5, 1.0, 0.0));
    harness
        .state_mut()
        .set_handle_position(32, cage.positions()[32] + DVec3::new(0.5, 1.0, 0.0));
    harness.run_steps(2);
    let plain = harness.state().read_back_deformed().unwrap().unwrap();

    let (drawn, on_cpu) = choose_setting(&mut harness, "Bulging γ", "γ 0", "γ 4");
    let app = harness.state();
    assert_eq!(app.document().deform_value(Parameter::Bulging), 400);
    let same = app.document().weights(Method::Somigliana).unwrap();
    assert!(std::sync::Arc::ptr_eq(same, &weights), "bound again");
    let diagonal = cage.diagonal() as f32;
    assert!(
        max_distance(&drawn, &on_cpu) < 1e-4 * diagonal,
        "bulged: GPU and CPU differ"
    );
    let bulge = max_distance(&drawn, &plain);
    assert!(
        bulge > 1e-3 * diagonal,
        "the bulging moved nothing: {bulge}"
    );
    assert_eq!(app.undo_label().as_deref(), Some("Bulging γ 4"));

    // A session keeps it.
    let dir = tempfile::tempdir().unwrap();
    let session = dir.path().join("s.json");
    assert!(harness.state_mut().save_session(&session));
    let text = std::fs::read_to_string(&session).unwrap();
    assert!(text.contains("\"bulging\": 4.0"), "{text}");

    harness.state_mut().undo();
    harness.run_steps(3);
    assert_eq!(
        harness.state().document().deform_value(Parameter::Bulging),
        0
    );
    let drawn = harness.state().read_back_deformed().unwrap().unwrap();
    assert!(
        max_distance(&drawn, &plain) < 1e-5 * diagonal,
        "undo left the bulge"
    );
}

/// The side panel's local blend: the vertex shader solves with the columns'
/// blended matrices and draws what the CPU computes, with the same weights;
/// back at 0 it draws the global variant again.
#[test]
fn a_local_blend_is_drawn_as_the_cpu_computes_it() {
    let Some(mut harness) = somigliana_shown() else {
        return;
    };
    let weights = (harness.state().document())
        .weights(Method::Somigliana)
        .unwrap()
        .clone();
    let cage = harness.state().document().cage().clone();
    // The middle finger's tip turned by 60° about the finger's base (past 81°
    // the finger's sides fold over).
    let (pivot, turn) = (
        DVec3::new(3.3, 1.1, 0.0),
        glam::DQuat::from_rotation_z(std::f64::consts::FRAC_PI_3),
    );
    for vertex in [10, 11, 30, 31] {
        let moved = pivot + turn * (cage.positions()[vertex] - pivot);
        harness.state_mut().set_handle_position(vertex, moved);
    }
    harness.run_steps(2);
    let plain = harness.state().read_back_deformed().unwrap().unwrap();

    let (drawn, on_cpu) = choose_setting(
        &mut harness,
        "Local blend",
        "local blend 0",
        "local blend 1",
    );
    let app = harness.state();
    assert_eq!(app.document().deform_value(Parameter::LocalBlend), 100);
    let same = app.document().weights(Method::Somigliana).unwrap();
    assert!(std::sync::Arc::ptr_eq(same, &weights), "bound again");
    let diagonal = cage.diagonal() as f32;
    let gap = max_distance(&drawn, &on_cpu);
    assert!(
        gap < 1e-4 * diagonal,
        "blended: GPU and CPU differ by {gap}"
    );
    let change = max_distance(&drawn, &plain);
    println!(
        "local blend 1 moved the mesh by {} of the diagonal",
        change / diagonal
    );
    assert!(
        change > 1e-3 * diagonal,
        "the blend moved nothing: {change}"
    );
    // Smooth shading's normals share the buffer with the columns' matrices:
    // drawn with them, the vertex shader still draws the CPU's positions.
    harness.state_mut().view_mut().smooth_shading = true;
    harness.run_steps(3);
    harness.render().unwrap();
    let app = harness.state();
    let normals = app
        .read_back_normals(Method::Somigliana)
        .expect("normals drawn");
    let shaded = app.read_back_drawn(Method::Somigliana).unwrap().unwrap();
    let gap = max_distance(&shaded, &on_cpu);
    assert!(gap < 1e-4 * diagonal, "smooth shaded: {gap}");
    let deformed = app.document().deformed_positions(Method::Somigliana);
    let cpu_normals = pmvc::geometry::vertex_normals(&deformed, &app.document().mesh().triangles);
    let worst = (normals.iter().zip(&cpu_normals))
        .map(|(g, c)| g.as_dvec3().angle_between(*c))
        .fold(0.0f64, f64::max);
    assert!(worst < 2e-3, "normals off by {worst} rad");
    assert_eq!(app.undo_label().as_deref(), Some("Local blend 1"));
    // Compared against PMVC in the difference view, the blended family is the
    // other one: its matrices are read from the compared slot.
    let pane = Pane::Difference {
        against: Method::Somigliana.into(),
        shown: Method::Pmvc,
    };
    let shading = harness.state_mut().shading_of(pane);
    assert_eq!(shading.colouring, Colouring::MethodDistance);
    let app = harness.state();
    let values = app.read_back(&shading).unwrap().unwrap().values;
    let pmvc = app.document().deformed_positions(Method::Pmvc);
    let somigliana = app.document().deformed_positions(Method::Somigliana);
    for (i, value) in values.iter().enumerate() {
        let expected = (pmvc[i].distance(somigliana[i]) / f64::from(shading.cage_size)) as f32;
        assert!(
            (value - expected).abs() < 1e-4,
            "vertex {i}: {value} {expected}"
        );
    }

    harness.state_mut().undo();
    harness.run_steps(3);
    let drawn = harness.state().read_back_deformed().unwrap().unwrap();
    assert!(
        max_distance(&drawn, &plain) < 1e-5 * diagonal,
        "undo left the blend"
    );
}
