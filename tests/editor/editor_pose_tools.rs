//! Posing tools through the editor, keys and pointer as a user gives them: G, R
//! and S transforms with axis constraints and typed amounts, Esc restoring the
//! pose exactly, one undo step per transform, symmetry mirroring an edit onto
//! the partner handle, and soft selection pulling neighbours part of the way.

use crate::common;

use common::editor::*;
use egui::{Event, Key, Modifiers, Pos2};
use egui_kittest::Harness;
use glam::{DMat3, DVec3};
use pmvc::app::{EditorApp, TransformKind};

/// Put the pointer in the first view, away from the handles.
fn hover_view(harness: &mut Harness<'static, EditorApp>) -> Pos2 {
    let (_, rect) = harness.state().pane_rects()[0];
    let at = rect.left_top() + egui::vec2(60.0, 120.0);
    harness.hover_at(at);
    harness.run_steps(2);
    at
}

fn press(harness: &mut Harness<'static, EditorApp>, key: Key) {
    harness.key_press(key);
    harness.run_steps(2);
}

fn type_number(harness: &mut Harness<'static, EditorApp>, text: &str) {
    harness.event(Event::Text(text.into()));
    harness.run_steps(2);
}

/// Select `handle` alone and move it along z by the typed `amount` (G, Z, the
/// number, Enter); the pose after.
fn move_along_z(
    harness: &mut Harness<'static, EditorApp>,
    handle: usize,
    amount: &str,
) -> Vec<DVec3> {
    harness.state_mut().select_only([handle]);
    hover_view(harness);
    press(harness, Key::G);
    press(harness, Key::Z);
    type_number(harness, amount);
    press(harness, Key::Enter);
    harness.state().document().pose().to_vec()
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-9
}

#[test]
fn r_with_an_axis_and_a_typed_angle_rotates_the_selection_about_its_centre() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let start = harness.state().document().pose().to_vec();
    harness.state_mut().select_only([10, 11, 12]);
    hover_view(&mut harness);
    press(&mut harness, Key::R);
    assert_eq!(
        harness.state().transform_under_way(),
        Some(TransformKind::Rotate)
    );
    press(&mut harness, Key::Z);
    type_number(&mut harness, "90");
    press(&mut harness, Key::Enter);
    assert_eq!(harness.state().transform_under_way(), None);

    let centre = (start[10] + start[11] + start[12]) / 3.0;
    let quarter = DMat3::from_rotation_z(std::f64::consts::FRAC_PI_2);
    let pose = harness.state().document().pose().to_vec();
    for i in [10, 11, 12] {
        let expected = centre + quarter * (start[i] - centre);
        assert!(
            close(pose[i], expected),
            "handle {i}: {} vs {expected}",
            pose[i]
        );
    }
    assert_eq!(pose[0], start[0], "unselected handles stay");
    // One Ctrl+Z undoes the whole transform.
    assert_eq!(
        harness.state().undo_label().as_deref(),
        Some("rotate handles")
    );
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(harness.state().document().pose(), start.as_slice());
}

#[test]
fn s_along_an_axis_scales_that_coordinate_only_and_esc_restores_exactly() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let start = harness.state().document().pose().to_vec();
    harness.state_mut().select_only([0, 1, 2, 3]);
    let at = hover_view(&mut harness);
    press(&mut harness, Key::S);
    press(&mut harness, Key::X);
    type_number(&mut harness, "2");
    press(&mut harness, Key::Enter);
    let centre = (start[0] + start[1] + start[2] + start[3]) / 4.0;
    let pose = harness.state().document().pose().to_vec();
    for i in 0..4 {
        let expected = DVec3::new(
            centre.x + 2.0 * (start[i].x - centre.x),
            start[i].y,
            start[i].z,
        );
        assert!(
            close(pose[i], expected),
            "handle {i}: {} vs {expected}",
            pose[i]
        );
    }

    // A pointer-driven move, then Esc: exactly the pose before, and no undo step.
    let before = pose;
    let edits = harness.state().document().edits();
    press(&mut harness, Key::G);
    for k in 1..=5 {
        harness.hover_at(at + egui::vec2(12.0 * k as f32, -8.0 * k as f32));
        harness.step();
    }
    harness.run_steps(2);
    assert_ne!(
        harness.state().document().pose(),
        before.as_slice(),
        "G follows the pointer"
    );
    press(&mut harness, Key::Escape);
    assert_eq!(harness.state().document().pose(), before.as_slice());
    assert_eq!(harness.state().document().edits(), edits);
    assert_eq!(
        harness.state().document().selection().len(),
        4,
        "Esc cancels, not deselects"
    );
}

#[test]
fn a_pointer_rotation_keeps_distances_to_the_pivot_and_a_click_confirms() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let start = harness.state().document().pose().to_vec();
    harness.state_mut().select_only([4, 5, 8, 9]);
    let at = hover_view(&mut harness);
    press(&mut harness, Key::R);
    for k in 1..=6 {
        harness.hover_at(at + egui::vec2(0.0, 15.0 * k as f32));
        harness.step();
    }
    click(&mut harness, at + egui::vec2(0.0, 90.0));
    assert_eq!(harness.state().transform_under_way(), None);
    let pose = harness.state().document().pose().to_vec();
    let centre = (start[4] + start[5] + start[8] + start[9]) / 4.0;
    assert!(pose[4] != start[4], "the selection turned");
    for i in [4, 5, 8, 9] {
        let before = (start[i] - centre).length();
        let after = (pose[i] - centre).length();
        assert!(
            (before - after).abs() < 1e-6,
            "handle {i}: {before} vs {after}"
        );
    }
}

#[test]
fn symmetry_mirrors_a_move_onto_the_partner_handle() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let start = harness.state().document().pose().to_vec();
    // The comb cage is an extrusion: every front handle has a back partner.
    let back = 0;
    let front = (0..start.len())
        .find(|&j| {
            j != back
                && (start[j].x - start[back].x).abs() < 1e-9
                && (start[j].y - start[back].y).abs() < 1e-9
        })
        .expect("a partner across z");
    harness.run_steps(2);
    // Turn symmetry on in the panel.
    use egui_kittest::kittest::Queryable;
    let z_buttons = harness.query_all_by_label("Z").count();
    assert!(z_buttons >= 1);
    harness.query_all_by_label("Z").last().unwrap().click();
    harness.run_steps(2);
    assert_eq!(harness.state().handles_without_partner(), 0);

    let pose = move_along_z(&mut harness, back, "-0.25");
    assert!(close(pose[back], start[back] + DVec3::new(0.0, 0.0, -0.25)));
    assert!(
        close(pose[front], start[front] + DVec3::new(0.0, 0.0, 0.25)),
        "the partner moves the mirrored way: {} from {}",
        pose[front],
        start[front]
    );
}

#[test]
fn soft_selection_pulls_near_handles_part_of_the_way_and_far_ones_not_at_all() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let start = harness.state().document().pose().to_vec();
    let diagonal = harness.state().document().cage().diagonal();
    let selected = 10;
    hover_view(&mut harness);
    press(&mut harness, Key::O);
    harness.state_mut().select_only([selected]);
    harness.run_steps(2);
    press(&mut harness, Key::G);
    press(&mut harness, Key::Y);
    type_number(&mut harness, "1");
    press(&mut harness, Key::Enter);
    let pose = harness.state().document().pose().to_vec();
    let radius = 0.15 * diagonal;
    let (mut partial, mut still) = (0, 0);
    for i in 0..start.len() {
        let distance = (start[i] - start[selected]).length();
        let t = (1.0 - distance / radius).clamp(0.0, 1.0);
        let expected = if i == selected {
            1.0
        } else {
            t * t * (3.0 - 2.0 * t)
        };
        let moved = pose[i] - start[i];
        assert!(
            close(moved, DVec3::new(0.0, expected, 0.0)),
            "handle {i} at {distance:.3} moved {moved}, expected {expected:.4} up"
        );
        partial += usize::from(expected > 0.0 && expected < 1.0);
        still += usize::from(expected == 0.0);
    }
    assert!(partial >= 1, "some handles follow part of the way");
    assert!(still >= 1, "far handles stay");
}

/// The comb's cage with every vertex moved by up to 1% of its mean edge, in a
/// fixed pseudo-random direction: symmetric only to within a tolerance, as an
/// artist's cage is.
fn roughly_symmetric_comb(dir: &std::path::Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let (mesh, _, cage, _) = common::comb_scene(dir, 200);
    let rest = cage.positions();
    let edge = pmvc::app::pose_tools::mean_edge_length(rest, cage.triangles());
    let moved: Vec<DVec3> = rest
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let k = i as f64;
            let wobble = DVec3::new((k * 1.7).sin(), (k * 2.3).cos(), (k * 0.9).sin());
            p + wobble.normalize() * 0.01 * edge
        })
        .collect();
    let path = common::write(
        dir,
        "rough_cage.obj",
        &common::cage_obj(&cage.with_positions(moved)),
    );
    (mesh, path)
}

#[test]
fn symmetry_pairs_a_cage_symmetric_to_within_one_percent_of_an_edge() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage) = roughly_symmetric_comb(dir.path());
    let Some(mut harness) = editor_on_files(&mesh, &cage) else {
        return;
    };
    let handles = harness.state().document().pose().len();
    harness.state_mut().pose_tool_settings_mut().symmetry = Some(2);
    // Exact matching finds no partner on such a cage.
    harness
        .state_mut()
        .pose_tool_settings_mut()
        .mirror_tolerance = 0.0;
    assert_eq!(harness.state().handles_without_partner(), handles);
    // The default tolerance, a tenth of the mean edge, pairs every handle.
    harness
        .state_mut()
        .pose_tool_settings_mut()
        .mirror_tolerance = pmvc::app::pose_tools::PoseToolSettings::default().mirror_tolerance;
    assert_eq!(harness.state().handles_without_partner(), 0);
    harness.run_steps(2);
    use egui_kittest::kittest::Queryable;
    let report = format!("{handles} of {handles} handles have a mirror partner");
    assert!(
        harness.query_by_label(&report).is_some(),
        "the panel says how many handles are paired"
    );

    // An edit of one handle moves its partner the mirrored way.
    let start = harness.state().document().pose().to_vec();
    let back = 0;
    let pose = move_along_z(&mut harness, back, "-0.25");
    let moved: Vec<usize> = (0..handles)
        .filter(|&i| !close(pose[i], start[i]))
        .collect();
    assert_eq!(moved.len(), 2, "the handle and its partner: {moved:?}");
    let front = moved.into_iter().find(|&i| i != back).unwrap();
    assert!(close(pose[back], start[back] + DVec3::new(0.0, 0.0, -0.25)));
    assert!(close(
        pose[front],
        start[front] + DVec3::new(0.0, 0.0, 0.25)
    ));
}

/// One turn of the wheel upwards, and the frames its smoothing takes.
fn wheel_up(harness: &mut Harness<'static, EditorApp>) {
    harness.event(Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: egui::vec2(0.0, 120.0),
        phase: egui::TouchPhase::Move,
        modifiers: Modifiers::NONE,
        source: egui::MouseWheelSource::Wheel,
    });
    harness.run_steps(10);
}

#[test]
fn the_wheel_during_a_transform_sets_the_soft_selection_radius() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().pose_tool_settings_mut().soft_selection = true;
    let radius = harness.state().pose_tool_settings().soft_radius;
    let camera = harness.state().camera();
    harness.state_mut().select_only([10]);
    hover_view(&mut harness);
    press(&mut harness, Key::G);
    assert!(harness.state().transform_under_way().is_some());
    wheel_up(&mut harness);
    let wider = harness.state().pose_tool_settings().soft_radius;
    assert!(wider > radius, "the wheel up widens: {radius} -> {wider}");
    assert_eq!(
        harness.state().camera().distance,
        camera.distance,
        "no zoom"
    );
    assert!(harness.state().transform_under_way().is_some());
    press(&mut harness, Key::Escape);
    // Without soft selection the wheel leaves it alone.
    harness.state_mut().pose_tool_settings_mut().soft_selection = false;
    press(&mut harness, Key::G);
    wheel_up(&mut harness);
    assert_eq!(harness.state().pose_tool_settings().soft_radius, wider);
    press(&mut harness, Key::Escape);
}

#[test]
fn the_mirror_plane_picked_at_the_3d_cursor_pairs_a_cage_whose_extent_is_not_symmetric() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, _, cage, _) = common::comb_scene(dir.path(), 200);
    let rest = cage.positions();
    let (lo, hi) = pmvc::geometry::bounds_of(rest);
    let plane = (lo.z + hi.z) / 2.0;
    // One handle pulled out along -z (a tail): the box's centre moves off the
    // plane the rest of the cage is symmetric about.
    let tail = (0..rest.len())
        .min_by(|&a, &b| rest[a].z.total_cmp(&rest[b].z))
        .unwrap();
    let mut moved = rest.to_vec();
    moved[tail].z -= hi.z - lo.z;
    let cage_path = common::write(
        dir.path(),
        "tailed_cage.obj",
        &common::cage_obj(&cage.with_positions(moved)),
    );
    let Some(mut harness) = editor_on_files(&mesh, &cage_path) else {
        return;
    };
    let handles = harness.state().document().pose().len();
    let tools = harness.state_mut().pose_tool_settings_mut();
    tools.symmetry = Some(2);
    let off_centre = harness.state().handles_without_partner();
    assert!(
        off_centre > handles / 3,
        "about the box's centre many handles are unpaired: {off_centre} of {handles}"
    );
    let tools = harness.state_mut().pose_tool_settings_mut();
    tools.cursor = DVec3::new(0.0, 0.0, plane);
    tools.mirror_plane = pmvc::app::pose_tools::MirrorPlane::Cursor;
    assert_eq!(
        harness.state().handles_without_partner(),
        2,
        "only the tail and the handle it left"
    );
    harness.run_steps(2);
    use egui_kittest::kittest::Queryable;
    harness.get_by_label(&format!("Mirror plane: z = {plane:.4}"));

    // Fitted instead, from the box centre: the same plane, found by the editor.
    harness.state_mut().pose_tool_settings_mut().mirror_plane =
        pmvc::app::pose_tools::MirrorPlane::CageCentre;
    harness.run_steps(2);
    harness.get_by_label("fitted").scroll_to_me();
    harness.run_steps(2);
    harness.get_by_label("fitted").click_accesskit();
    harness.run_steps(2);
    assert_eq!(harness.state().handles_without_partner(), 2);
    match harness.state().pose_tool_settings().mirror_plane {
        pmvc::app::pose_tools::MirrorPlane::Fitted(offset) => {
            assert!((offset - plane).abs() < 1e-9, "{offset} against {plane}")
        }
        other => panic!("not fitted: {other:?}"),
    }
    harness.get_by_label_contains(&format!("{} of {handles} handles paired", handles - 2));
}
