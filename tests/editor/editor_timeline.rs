//! The timeline: named poses placed at times play in the viewport, blended
//! linearly between neighbours; Stop brings back the pose from before Play;
//! placing a pose is one undo step, and sessions keep the times.

use crate::common;

use common::editor::*;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use glam::DVec3;
use pmvc::app::actions::Action;
use pmvc::app::timeline::pose_at;
use pmvc::app::EditorApp;

/// The editor in a window tall enough that the side panel shows the timeline
/// without scrolling (a click lands where the button is drawn), at 60 frames
/// a second, so that playback reaches times of more than two decimals.
fn tall_editor() -> Option<Harness<'static, EditorApp>> {
    let state = render_state()?;
    let size = egui::vec2(1100.0, 1500.0);
    let mut harness = editor_sized(state, Default::default(), size, 1.0 / 60.0);
    run_until_bound(&mut harness);
    Some(harness)
}

/// Store the rest pose and two moves of handle 3 as "rest", "up" and "far",
/// and put them on the timeline with the key toggles: 0, 1 and 2 s.
fn three_keys(harness: &mut Harness<'static, EditorApp>) {
    let rest = harness.state().document().pose()[3];
    for (name, offset) in [("rest", 0.0), ("up", 0.5), ("far", 1.0)] {
        harness
            .state_mut()
            .set_handle_position(3, rest + DVec3::new(0.0, offset, 0.0));
        harness.run_steps(2);
        harness
            .state_mut()
            .queue_action(Action::StoreNamedPose(name.into()));
        harness.run_steps(2);
    }
    for row in 0..3 {
        harness.query_all_by_label("key").nth(row).unwrap().click();
        harness.run_steps(2);
    }
}

#[test]
fn keys_placed_with_the_clock_play_as_linear_blends_and_stop_restores_the_pose() {
    let Some(mut harness) = tall_editor() else {
        return;
    };
    three_keys(&mut harness);
    let named = harness.state().document().named_poses().to_vec();
    let times: Vec<Option<f64>> = named.iter().map(|p| p.time).collect();
    assert_eq!(times, [Some(0.0), Some(1.0), Some(2.0)]);
    assert_eq!(
        harness.state().undo_label().as_deref(),
        Some("place pose far at 2 s")
    );
    let before = harness.state().document().pose().to_vec();

    harness.get_by_label("Play").click();
    harness.run_steps(20);
    assert!(harness.state().timeline_playing());
    assert_eq!(
        harness.state().undo_label().as_deref(),
        Some("place pose far at 2 s"),
        "playing makes no undo step"
    );
    let seconds = harness.state().timeline_seconds();
    assert!(seconds > 0.0, "time moves while playing: {seconds}");
    let expected = pose_at(&named, seconds).unwrap();
    let shown = harness.state().document().pose();
    let worst = shown
        .iter()
        .zip(&expected)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-12,
        "the pose shown is the timeline's at {seconds} s"
    );

    harness.get_by_label("Stop").click();
    harness.run_steps(2);
    assert_eq!(harness.state().document().pose(), before.as_slice());
    assert_eq!(
        harness.state().undo_label().as_deref(),
        Some("place pose far at 2 s"),
        "playing made no undo step"
    );

    // Undo takes the last key off again.
    harness.state_mut().queue_action(Action::Undo);
    harness.run_steps(2);
    assert_eq!(harness.state().document().named_poses()[2].time, None);
}

#[test]
fn a_session_keeps_the_timeline() {
    let Some(mut harness) = tall_editor() else {
        return;
    };
    three_keys(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("timed.session.json");
    assert!(harness.state_mut().save_session(&path));
    let Some(mut reopened) = editor() else { return };
    run_until_bound(&mut reopened);
    assert!(reopened.state_mut().open_session(&path));
    reopened.run_steps(2);
    let times: Vec<Option<f64>> = reopened
        .state()
        .document()
        .named_poses()
        .iter()
        .map(|p| p.time)
        .collect();
    assert_eq!(times, [Some(0.0), Some(1.0), Some(2.0)]);
}

#[test]
fn two_keys_cannot_share_a_time() {
    let Some(mut harness) = tall_editor() else {
        return;
    };
    three_keys(&mut harness);
    harness
        .state_mut()
        .queue_action(Action::Apply(pmvc::app::model::Command::SetPoseTime {
            index: 0,
            time: Some(1.0),
        }));
    harness.run_steps(2);
    assert_eq!(harness.state().document().named_poses()[0].time, Some(0.0));
    let error = harness.state().last_error().unwrap_or_default().to_owned();
    assert!(error.contains("\"up\" is already at 1 s"), "{error}");
}

#[test]
fn export_gltf_writes_named_poses_as_shape_keys_and_the_timeline_as_the_animation() {
    use common::gltf_reader::{read_gltf, validator_report, vec3};
    let Some(mut harness) = tall_editor() else {
        return;
    };
    three_keys(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("comb.glb");
    assert!(harness.state_mut().export_gltf(&path));
    if let Some(report) = validator_report(&path) {
        assert_eq!(report["issues"]["numErrors"], 0, "{report:#}");
    }
    let gltf = read_gltf(&path);
    let mesh = &gltf.json["meshes"][0];
    assert_eq!(gltf.target_names(), ["rest", "up", "far"]);

    // Each shape key is the mesh as the editor deforms it with that pose.
    let app = harness.state();
    let document = app.document();
    let method = app.active_method();
    let scale = document.mesh().diagonal();
    let primitive = &mesh["primitives"][0];
    let origin = gltf.translation();
    let base = gltf.accessor(&primitive["attributes"]["POSITION"]);
    for (target, named) in document.named_poses().iter().enumerate() {
        let expected = document.deformed_positions_at(method, &named.positions);
        let deltas = gltf.accessor(&primitive["targets"][target]["POSITION"]);
        let worst = base
            .iter()
            .zip(&deltas)
            .map(|(b, d)| {
                let at = origin + vec3(b) + vec3(d);
                expected
                    .iter()
                    .map(|e| e.distance(at))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max);
        assert!(worst < 1e-5 * scale, "{}: {worst}", named.name);
    }

    // One weights channel keyed at the timeline's times.
    let animation = &gltf.json["animations"][0];
    let sampler = &animation["samplers"][0];
    let times: Vec<f64> = gltf
        .accessor(&sampler["input"])
        .into_iter()
        .map(|t| t[0])
        .collect();
    assert_eq!(times, [0.0, 1.0, 2.0]);
    assert_eq!(animation["channels"][0]["target"]["path"], "weights");

    // The export opens again as a mesh (File > Open mesh lists .glb).
    let triangles = harness.state().document().mesh().triangles.len();
    assert!(harness
        .state_mut()
        .open_file(pmvc::app::editor::FileRole::Mesh, &path));
    open_without_saving(&mut harness);
    assert_eq!(harness.state().last_error(), None);
    assert_eq!(harness.state().document().mesh().triangles.len(), triangles);
}

/// The largest distance from a point of `points` to the nearest of `to`.
fn farthest_from(points: &[DVec3], to: &[DVec3]) -> f64 {
    points
        .iter()
        .map(|p| {
            to.iter()
                .map(|q| q.distance(*p))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// The base shape of the glTF at `path`: mesh 0's POSITION, moved by the node.
fn gltf_base(path: &std::path::Path) -> Vec<DVec3> {
    use common::gltf_reader::{read_gltf, vec3};
    let gltf = read_gltf(path);
    let origin = gltf.translation();
    let mut base = Vec::new();
    for primitive in gltf.json["meshes"][0]["primitives"].as_array().unwrap() {
        let positions = gltf.accessor(&primitive["attributes"]["POSITION"]);
        base.extend(positions.iter().map(|p| origin + vec3(p)));
    }
    base
}

#[test]
fn export_gltf_has_the_rest_mesh_as_its_base_and_its_animation_starts_at_rest() {
    let Some(mut harness) = tall_editor() else {
        return;
    };
    three_keys(&mut harness);
    // The timeline starts at 0.5 s, and a pose is applied when exporting.
    harness
        .state_mut()
        .queue_action(Action::Apply(pmvc::app::model::Command::SetPoseTime {
            index: 0,
            time: Some(0.5),
        }));
    harness.run_steps(2);
    let rest_handle = harness.state().document().cage().positions()[3];
    harness
        .state_mut()
        .set_handle_position(3, rest_handle + DVec3::new(0.0, 0.8, 0.0));
    harness.run_steps(2);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rest_base.glb");
    assert!(harness.state_mut().export_gltf(&path));
    let notices = harness.state().notices().all();
    let notice = &notices.last().unwrap().text;
    assert!(notice.contains("the rest mesh as its base"), "{notice}");

    let document = harness.state().document();
    let rest = document.mesh().positions.clone();
    let posed = document.deformed_positions(harness.state().active_method());
    let scale = document.mesh().diagonal();
    let base = gltf_base(&path);
    assert!(farthest_from(&base, &rest) < 1e-5 * scale);
    assert!(farthest_from(&rest, &base) < 1e-5 * scale);
    assert!(
        farthest_from(&base, &posed) > 1e-2 * scale,
        "the pose moved the mesh, and the base is not it"
    );
    // pmvc's own reader reads the same base back.
    let read = pmvc::formats::load_mesh(&path).unwrap().mesh.positions;
    assert!(farthest_from(&read, &rest) < 1e-5 * scale);

    // A key at 0 s with every weight 0 (the base), then the timeline's keys.
    let gltf = common::gltf_reader::read_gltf(&path);
    let sampler = &gltf.json["animations"][0]["samplers"][0];
    let times: Vec<f64> = gltf
        .accessor(&sampler["input"])
        .into_iter()
        .map(|t| t[0])
        .collect();
    assert_eq!(times, [0.0, 0.5, 1.0, 2.0]);
    let weights = gltf.accessor(&sampler["output"]);
    assert!(weights[..3].iter().all(|w| w[0] == 0.0), "{weights:?}");
    assert_eq!(weights[3][0], 1.0, "the first pose at 0.5 s");

    // Asked for, the base is the current pose.
    let posed_path = dir.path().join("posed_base.glb");
    assert!(harness.state_mut().export_gltf_posed_base(&posed_path));
    let base = gltf_base(&posed_path);
    assert!(farthest_from(&base, &posed) < 1e-5 * scale);
}
