//! A scene far from the world origin is drawn and edited as the same scene at
//! the origin: the GPU works in f32 (spacing 0.0625 at 1e6), so the viewport
//! draws relative to a scene origin near the cage (`render::SceneOrigin`), and
//! the cameras, picking and the 3D cursor use the same origin. Each test runs
//! the same sphere in a box cage at the origin and shifted, and compares what
//! the editor does after subtracting the shift. See `common::editor` for how a
//! missing GPU is handled.

use crate::common;

use common::editor::*;
use egui::{Event, Modifiers, PointerButton, Pos2};
use egui_kittest::Harness;
use glam::DVec3;
use pmvc::app::{EditorApp, EditorOptions};
use pmvc::coords::Method;
use pmvc::geometry::procedural;

/// The shifts: along the diagonal as in the report of the fault, and an
/// ECEF-like point that is on no power-of-two grid.
fn shifts() -> Vec<DVec3> {
    let mut shifts: Vec<DVec3> = [1e3, 1e6, 1e7].into_iter().map(DVec3::splat).collect();
    shifts.push(DVec3::new(4_510_731.37, 4_510_731.91, -1_234_567.123));
    shifts
}

/// The editor on a unit sphere in a box cage, both moved by `shift`, showing MVC.
fn sphere_in_box(shift: DVec3) -> Option<Harness<'static, EditorApp>> {
    let state = render_state()?;
    let dir = tempfile::tempdir().unwrap();
    let sphere = procedural::icosphere(1.0, 3);
    let cage = procedural::cube_cage(1.25);
    let moved = |points: &[DVec3]| -> Vec<DVec3> { points.iter().map(|&p| p + shift).collect() };
    let mesh_path = common::write(
        dir.path(),
        "sphere.obj",
        &common::triangles_obj(&moved(sphere.positions()), sphere.triangles()),
    );
    let cage_path = common::write(
        dir.path(),
        "box.obj",
        &common::triangles_obj(&moved(cage.positions()), cage.triangles()),
    );
    let mut harness = editor_on(
        state,
        EditorOptions {
            mesh: Some(mesh_path),
            cage: Some(cage_path),
            method: Some(Method::Mvc),
            ..Default::default()
        },
    );
    run_until_bound(&mut harness);
    assert_eq!(harness.state().last_error(), None, "shift {shift}");
    Some(harness)
}

fn diagonal(app: &EditorApp) -> f64 {
    app.document().cage().diagonal()
}

/// What the vertex shader draws, in world coordinates less `shift`.
fn drawn_less(app: &EditorApp, shift: DVec3) -> Vec<DVec3> {
    let drawn = app.read_back_drawn_world(Method::Mvc).expect("a GPU scene");
    drawn
        .expect("read back")
        .iter()
        .map(|&p| p - shift)
        .collect()
}

fn largest_distance(a: &[DVec3], b: &[DVec3]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f64::max)
}

/// Handle 0 moved by the same vector at every shift.
fn pose_one_handle(harness: &mut Harness<'static, EditorApp>) {
    let rest = harness.state().document().cage().positions()[0];
    harness
        .state_mut()
        .set_handle_position(0, rest + DVec3::new(0.4, 0.25, -0.3));
    harness.run_steps(2);
}

#[test]
fn a_shifted_scene_is_drawn_as_the_same_scene_at_the_origin() {
    let Some(mut at_origin) = sphere_in_box(DVec3::ZERO) else {
        return;
    };
    let reference_rest = drawn_less(at_origin.state(), DVec3::ZERO);
    pose_one_handle(&mut at_origin);
    let reference_posed = drawn_less(at_origin.state(), DVec3::ZERO);
    let tolerance = 1e-5 * diagonal(at_origin.state());
    assert!(
        largest_distance(&reference_rest, &reference_posed) > 0.05,
        "posed"
    );
    for shift in shifts() {
        let mut harness = sphere_in_box(shift).expect("the same GPU");
        let rest = drawn_less(harness.state(), shift);
        let error = largest_distance(&rest, &reference_rest);
        eprintln!("shift {shift}: at rest {error}");
        assert!(error < tolerance, "shift {shift}: at rest {error}");
        pose_one_handle(&mut harness);
        let app = harness.state();
        let posed = drawn_less(app, shift);
        let cpu: Vec<DVec3> = (app.document().deformed_positions(Method::Mvc).iter())
            .map(|&p| p - shift)
            .collect();
        let error = largest_distance(&posed, &cpu);
        assert!(
            error < tolerance,
            "shift {shift}: posed, from the CPU's {error}"
        );
        let error = largest_distance(&posed, &reference_posed);
        eprintln!("shift {shift}: posed {error}");
        assert!(
            error < tolerance,
            "shift {shift}: posed, from the origin's {error}"
        );
    }
}

/// The handle dragged and where it went, less the shift.
fn drag_a_handle(harness: &mut Harness<'static, EditorApp>) -> (usize, DVec3) {
    let (handle, at) = isolated_handle(harness);
    click(harness, at);
    drag(harness, at, at + egui::vec2(60.0, -30.0), Modifiers::NONE);
    harness.run_steps(2);
    let document = harness.state().document();
    (
        handle,
        document.pose()[handle] - document.cage().positions()[handle],
    )
}

#[test]
fn dragging_a_handle_of_a_shifted_scene_moves_it_as_at_the_origin() {
    let Some(mut at_origin) = sphere_in_box(DVec3::ZERO) else {
        return;
    };
    let (handle, moved) = drag_a_handle(&mut at_origin);
    assert!(
        moved.length() > 0.1,
        "the drag moved handle {handle}: {moved}"
    );
    let tolerance = 1e-5 * diagonal(at_origin.state());
    for shift in shifts() {
        let mut harness = sphere_in_box(shift).expect("the same GPU");
        let (shifted_handle, shifted_moved) = drag_a_handle(&mut harness);
        assert_eq!(shifted_handle, handle, "shift {shift}");
        let error = shifted_moved.distance(moved);
        eprintln!("shift {shift}: drag {error}");
        assert!(
            error < tolerance,
            "shift {shift}: moved {shifted_moved}, at the origin {moved}"
        );
        // Box selection: a band around the handle selects it alone.
        let at = harness.state().handle_screen_position(handle).unwrap();
        let corner = egui::vec2(12.0, 12.0);
        drag(&mut harness, at - corner, at + corner, Modifiers::COMMAND);
        let selection: Vec<usize> = harness
            .state()
            .document()
            .selection()
            .iter()
            .copied()
            .collect();
        assert_eq!(selection, [handle], "{shift}");
    }
}

/// Shift+right click at `at`: the 3D cursor goes to what is under it.
fn place_cursor(harness: &mut Harness<'static, EditorApp>, at: Pos2) -> DVec3 {
    harness.event(Event::ModifiersChanged(Modifiers::SHIFT));
    harness.hover_at(at);
    harness.run_steps(2);
    for pressed in [true, false] {
        harness.event(Event::PointerButton {
            pos: at,
            button: PointerButton::Secondary,
            pressed,
            modifiers: Modifiers::SHIFT,
        });
        harness.step();
    }
    harness.event(Event::ModifiersChanged(Modifiers::NONE));
    harness.run_steps(2);
    harness.state().cursor()
}

#[test]
fn the_3d_cursor_lands_on_the_same_mesh_point_of_a_shifted_scene() {
    let Some(mut at_origin) = sphere_in_box(DVec3::ZERO) else {
        return;
    };
    // The sphere's vertex drawn nearest the view's centre, far from every handle.
    let centre = at_origin.state().pane_rects()[0].1.center();
    let vertices = at_origin.state().document().mesh().positions.len();
    let at = (0..vertices)
        .filter_map(|v| at_origin.state_mut().mesh_vertex_screen_position(0, v))
        .min_by(|a, b| a.distance(centre).total_cmp(&b.distance(centre)))
        .expect("the sphere is on screen");
    let reference = place_cursor(&mut at_origin, at);
    assert!(
        (reference.length() - 1.0).abs() < 1e-3,
        "on the sphere: {reference}"
    );
    let tolerance = 1e-5 * diagonal(at_origin.state());
    for shift in shifts() {
        let mut harness = sphere_in_box(shift).expect("the same GPU");
        let cursor = place_cursor(&mut harness, at) - shift;
        let error = cursor.distance(reference);
        eprintln!("shift {shift}: cursor {error}");
        assert!(
            error < tolerance,
            "shift {shift}: {cursor}, at the origin {reference}"
        );
    }
}
