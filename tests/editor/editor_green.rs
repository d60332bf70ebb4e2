//! Green coordinates in the editor: bound on demand like the other families, the
//! vertex shader's blend of their face columns keeping a similarity of the cage a
//! similarity of the mesh, ψ of a chosen triangle as a heatmap, and the negativity
//! view over φ only (ψ is not a weight of a cage vertex).

use crate::common;

use common::editor::*;
use egui_kittest::kittest::Queryable;

use pmvc::app::compare::{Overlay, Pane};
use pmvc::coords::green::bind_green;
use pmvc::coords::{BindProgress, Method};
use pmvc::render::Colouring;

#[test]
fn green_binds_follows_a_similarity_and_shows_psi_and_phi_negativity() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().set_active_method(Method::Green);
    run_until_bound(&mut harness);
    let app = harness.state();
    let cage = app.document().cage().clone();
    let (vertices, triangles) = (cage.vertex_count(), cage.triangle_count());
    let weights = app
        .document()
        .weights(Method::Green)
        .expect("bound")
        .clone();
    assert_eq!(weights.cols, vertices + triangles);
    let quality = app.document().bound(Method::Green).unwrap().quality;
    assert!(quality.max_partition_error < 1e-5, "{quality:?}");
    assert!(quality.max_linear_precision_error < 1e-5, "{quality:?}");

    // A rotation and uniform scale of the whole cage, loaded as a pose: the drawn
    // mesh is the rest mesh under the same map (to f32 blending).
    let expected = load_a_similarity_pose(&mut harness);
    let drawn = harness.state().read_back_deformed().unwrap().unwrap();
    let worst = max_distance(&drawn, &expected);
    assert!(
        worst < 2e-4 * cage.diagonal() as f32,
        "worst {worst} of diagonal {}",
        cage.diagonal()
    );

    // ψ of triangle 5 as a heatmap: the drawn values are that column, signed.
    harness.state_mut().view_mut().overlay = Overlay::Heatmap;
    harness.state_mut().view_mut().heat_triangle = Some(5);
    harness.run_steps(2);
    let shading = harness.state_mut().shading_of(Pane::Method(Method::Green));
    assert_eq!(shading.colouring, Colouring::TriangleWeight(5));
    let read = harness.state().read_back(&shading).unwrap().unwrap();
    let column: Vec<f32> = (0..weights.rows)
        .map(|r| weights.row(r)[vertices + 5])
        .collect();
    for (drawn, stored) in read.values.iter().zip(&column) {
        assert!((drawn - stored).abs() < 1e-6, "{drawn} vs {stored}");
    }
    let largest = column.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    assert_eq!(shading.colour_limit, largest);
    // MVC has no ψ: its pane shows the mesh shaded, with no value.
    let shading = harness.state_mut().shading_of(Pane::Method(Method::Mvc));
    let read = harness.state().read_back(&shading).unwrap().unwrap();
    assert!(read.values.iter().all(|&v| v == 0.0));

    // The negativity view takes each row's smallest φ, never a ψ.
    harness.state_mut().view_mut().overlay = Overlay::Negativity;
    harness.run_steps(2);
    let shading = harness.state_mut().shading_of(Pane::Method(Method::Green));
    let read = harness.state().read_back(&shading).unwrap().unwrap();
    for (row, drawn) in read.values.iter().enumerate() {
        let phi = &weights.row(row)[..vertices];
        let phi_min = phi.iter().copied().fold(f32::INFINITY, f32::min);
        assert_eq!(*drawn, phi_min, "row {row}");
    }
}

/// `--heatmap-triangle` beyond the cage's triangles is an error (a scripted run
/// then exits non-zero), and the view falls back to a triangle that exists.
#[test]
fn a_triangle_out_of_range_is_reported_and_clamped() {
    use pmvc::app::compare::ViewSettings;
    use pmvc::app::EditorOptions;
    let Some(harness) = editor_with(EditorOptions {
        view: ViewSettings {
            overlay: Overlay::Heatmap,
            heat_triangle: Some(100_000),
            ..Default::default()
        },
        ..Default::default()
    }) else {
        return;
    };
    let app = harness.state();
    let triangles = app.document().cage().triangle_count();
    let error = app.last_error().expect("an error");
    assert!(
        error.contains("--heatmap-triangle 100000")
            && error.contains(&format!("{triangles} triangles")),
        "{error}"
    );
    assert_eq!(app.view().heat_triangle, Some(triangles - 1));
}

/// Switched to Green with the toolbar and dragged by a handle, the drawn mesh
/// is where the library's own Green deformation puts it: fresh coordinates in
/// f64, the deformed cage's stretched normals, nothing shared with the editor's
/// weights or its shader.
#[test]
fn a_dragged_handle_moves_the_mesh_as_the_library_deforms_it() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.get_by_label("Green").click();
    harness.run_steps(2);
    run_until_bound(&mut harness);
    assert_eq!(harness.state().active_method(), Method::Green);
    assert!(harness.state().document().weights(Method::Green).is_some());
    let (handle, rest_drawn) = drag_an_isolated_handle(&mut harness);
    let app = harness.state();
    let cage = app.document().cage();
    let pose = app.document().pose().to_vec();
    assert!(pose[handle].distance(cage.positions()[handle]) > 1e-3);
    let points = &app.document().mesh().positions;
    let expected = bind_green(points, cage, &BindProgress::new(points.len()))
        .unwrap()
        .deform(cage, &pose)
        .unwrap();
    let expected: Vec<glam::Vec3> = expected.iter().map(|p| p.as_vec3()).collect();
    let drawn = app.read_back_deformed().unwrap().unwrap();
    let moved = max_distance(&drawn, &rest_drawn);
    assert!(moved > 1e-3, "the drawn mesh moved by {moved}");
    let worst = max_distance(&drawn, &expected);
    assert!(
        worst < 1e-4 * cage.diagonal() as f32,
        "worst {worst} of diagonal {}",
        cage.diagonal()
    );
}
