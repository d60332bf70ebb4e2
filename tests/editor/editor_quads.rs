//! A cage of quads in the editor: its quads are bound as bilinear patches, the
//! Quads setting splits them along a diagonal and rebinds (and a session keeps
//! it), and the difference view compares a family with its triangulated twin
//! on the same labelled scale as any other difference.

use crate::common;

use common::editor::*;
use egui_kittest::kittest::Queryable;
use glam::DVec3;
use pmvc::app::actions::Action;
use pmvc::app::compare::Layout;
use pmvc::app::EditorOptions;
use pmvc::coords::{Method, QuadSplit, WeightsId};
use pmvc::geometry::procedural_quads::twisted_box;
use pmvc::render::Colouring;
use std::path::{Path, PathBuf};

/// A ball inside a box of six quads whose top is turned 0.6 rad (four bent
/// sides), written as mesh.obj and cage.obj (the quads as quads).
fn quad_scene(dir: &Path) -> (PathBuf, PathBuf) {
    let cage = twisted_box(2.0, 0.6);
    let mut cage_text = common::points_obj(cage.positions());
    for quad in cage.quads() {
        let [a, b, c, d] = quad.corners.map(|i| i + 1);
        cage_text.push_str(&format!("f {a} {b} {c} {d}\n"));
    }
    let ball = pmvc::geometry::procedural::icosphere(0.7, 3);
    let centre = DVec3::new(0.0, 0.0, 1.0);
    let points: Vec<DVec3> = ball.positions().iter().map(|&p| p + centre).collect();
    (
        common::write(
            dir,
            "mesh.obj",
            &common::triangles_obj(&points, ball.triangles()),
        ),
        common::write(dir, "cage.obj", &cage_text),
    )
}

fn open(
    mesh: &Path,
    cage: &Path,
    options: EditorOptions,
) -> Option<egui_kittest::Harness<'static, pmvc::app::EditorApp>> {
    let mut harness = editor_sized(
        render_state()?,
        EditorOptions {
            mesh: Some(mesh.to_owned()),
            cage: Some(cage.to_owned()),
            resolution: Some(TEST_RESOLUTION),
            ..options
        },
        egui::vec2(1100.0, 1100.0),
        0.25,
    );
    run_until_bound(&mut harness);
    Some(harness)
}

/// The top four corners turned a further 0.4 rad: a pose no family reproduces
/// exactly, so the split shows.
fn twist_top(harness: &mut egui_kittest::Harness<'static, pmvc::app::EditorApp>) {
    let pose = harness.state().document().pose().to_vec();
    let turn = glam::DQuat::from_rotation_z(0.4);
    for (handle, position) in pose.iter().enumerate().skip(4) {
        harness
            .state_mut()
            .set_handle_position(handle, turn * *position);
    }
    harness.run_steps(3);
}

#[test]
fn the_quads_setting_splits_them_rebinds_and_is_kept_by_a_session() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage) = quad_scene(dir.path());
    let Some(mut harness) = open(&mesh, &cage, EditorOptions::default()) else {
        return;
    };
    assert_eq!(harness.state().document().cage().quads().len(), 6);
    let patches = harness.state().document().bound(Method::Pmvc).unwrap();
    assert_eq!(patches.options.quads, QuadSplit::None);
    let patch_weights = patches.weights.clone();
    // The setting is in the side panel, only for a cage with quads.
    harness.get_by_label("Quads");
    // The quality table names what was bound: MVC on quads is QMVC.
    assert!(harness.state().document().bound(Method::Mvc).is_some());
    assert!(harness.query_all_by_label("QMVC").next().is_some());

    harness
        .state_mut()
        .queue_action(Action::SetQuadSplit(QuadSplit::Longer));
    harness.run_steps(2);
    run_until_bound(&mut harness);
    let split = harness.state().document().bound(Method::Pmvc).unwrap();
    assert_eq!(split.options.quads, QuadSplit::Longer);
    let largest_change = split
        .weights
        .values
        .iter()
        .zip(&patch_weights.values)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f32::max);
    assert!(
        largest_change > 1e-3,
        "the split changed the weights by {largest_change}"
    );
    // The quality table names the split; the side panel says how quads are bound.
    assert!(harness
        .query_all_by_label("PMVC (longer split)")
        .next()
        .is_some());
    let quads = harness.get_by_label("Quads").value();
    assert_eq!(quads.as_deref(), Some("split: longer diagonal"));

    let session = dir.path().join("quads.session.json");
    assert!(harness.state_mut().save_session(&session));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&session).unwrap()).unwrap();
    assert_eq!(json["triangulate"], "longer");
    let Some(mut reopened) = editor_with(EditorOptions {
        session: Some(session.clone()),
        ..Default::default()
    }) else {
        return;
    };
    run_until_bound(&mut reopened);
    assert_eq!(reopened.state().bind_options().quads, QuadSplit::Longer);
    let bound = reopened.state().document().bound(Method::Pmvc).unwrap();
    assert_eq!(bound.options.quads, QuadSplit::Longer);
}

#[test]
fn the_difference_view_compares_a_family_with_its_triangulated_twin() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage) = quad_scene(dir.path());
    let Some(mut harness) = open(&mesh, &cage, EditorOptions::default()) else {
        return;
    };
    {
        let view = harness.state_mut().view_mut();
        view.layout = Layout::Difference;
        view.difference = [Method::Mvc, Method::Pmvc];
    }
    harness.run_steps(2);
    // Chosen as a user would: the "vs" list offers the shown family split.
    harness.get_by_label("vs").click();
    harness.run_steps(2);
    harness
        .get_by_label("itself, split: longer diagonal")
        .click();
    harness.run_steps(2);
    assert_eq!(
        harness.state().view().difference_split,
        Some(QuadSplit::Longer)
    );
    run_until_bound(&mut harness);
    let twin = WeightsId::split(Method::Pmvc, QuadSplit::Longer);
    let twin_set = harness
        .state()
        .document()
        .bound_id(twin)
        .expect("the twin is bound");
    assert_eq!(twin_set.options.quads, QuadSplit::Longer);
    assert_eq!(
        harness
            .state()
            .document()
            .bound(Method::Pmvc)
            .unwrap()
            .options
            .quads,
        QuadSplit::None
    );

    // At rest both reproduce the mesh; posed, the split moves it.
    let pane = harness.state().view().difference_pane_kind();
    twist_top(&mut harness);
    let range = harness
        .state_mut()
        .value_range(Colouring::MethodDistance, pane)
        .expect("a range");
    let diagonal = harness.state().document().cage().diagonal() as f32;
    assert!(
        range.max > 1e-4,
        "the split moves the ball by {} of the cage diagonal {diagonal}",
        range.max
    );

    harness.run_steps(4);
    harness.snapshot_options("editor_quads_twin_difference", &snapshot_options());

    // Setting the quads to that split leaves nothing to compare: the view
    // goes back to comparing families.
    harness
        .state_mut()
        .queue_action(Action::SetQuadSplit(QuadSplit::Longer));
    harness.run_steps(3);
    assert_eq!(harness.state().view().difference_split, None);
}

/// The `f` lines of an OBJ text, as written (corner lists only).
fn face_lines(text: &str) -> Vec<Vec<u32>> {
    text.lines()
        .filter_map(|line| line.strip_prefix("f "))
        .map(|corners| {
            corners
                .split_whitespace()
                .map(|c| c.split('/').next().unwrap().parse().unwrap())
                .collect()
        })
        .collect()
}

#[test]
fn save_pose_keeps_the_cages_faces_quads_and_triangles_as_read() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, _) = quad_scene(dir.path());
    // Five quads and the sixth side as two triangles.
    let box_cage = twisted_box(2.0, 0.6);
    let mut cage_text = common::points_obj(box_cage.positions());
    for (k, quad) in box_cage.quads().iter().enumerate() {
        let [a, b, c, d] = quad.corners.map(|i| i + 1);
        if k == 0 {
            cage_text.push_str(&format!("f {a} {b} {c}\nf {a} {c} {d}\n"));
        } else {
            cage_text.push_str(&format!("f {a} {b} {c} {d}\n"));
        }
    }
    let cage = common::write(dir.path(), "mixed_cage.obj", &cage_text);
    let Some(mut harness) = open(&mesh, &cage, EditorOptions::default()) else {
        return;
    };
    twist_top(&mut harness);
    let pose_path = dir.path().join("pose.obj");
    assert!(harness.state_mut().save_pose(&pose_path));
    let saved = std::fs::read_to_string(&pose_path).unwrap();
    let faces = face_lines(&saved);
    assert_eq!(faces, face_lines(&cage_text));
    assert_eq!(faces.iter().filter(|f| f.len() == 4).count(), 5);
    // The positions are the pose, and it loads back as one.
    let read = pmvc::formats::load_mesh(&pose_path).unwrap();
    assert_eq!(read.mesh.positions, harness.state().document().pose());
    assert!(harness.state_mut().load_pose(&pose_path));
    assert_eq!(harness.state().last_error(), None);
}
