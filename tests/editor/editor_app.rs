//! The editor driven through egui_kittest with the real app state and the wgpu
//! renderer (lavapipe on CI). Without a GPU adapter these tests print "not run"
//! and pass, unless `PMVC_REQUIRE_GPU=1`, which turns a missing adapter into a
//! failure.

use crate::common;

use common::editor::*;
use egui::{Event, Key, Modifiers, PointerButton, Pos2};
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use pmvc::app::editor::FileRole;
use pmvc::app::{BindOn, EditorApp};
use pmvc::coords::Method;

/// The mesh the GPU draws has moved away from `rest_gpu`, to where the CPU-side
/// weights put it.
fn assert_gpu_mesh_moved_as_on_the_cpu(app: &EditorApp, rest_gpu: &[glam::Vec3]) {
    let moved_gpu = app.read_back_deformed().unwrap().unwrap();
    assert!(
        max_distance(&moved_gpu, rest_gpu) > 1e-3,
        "the GPU mesh moved"
    );
    let cpu: Vec<glam::Vec3> = app
        .document()
        .deformed_positions(app.active_method())
        .iter()
        .map(|p| p.as_vec3())
        .collect();
    assert!(
        max_distance(&moved_gpu, &cpu) < 1e-3,
        "GPU and CPU deformations agree"
    );
}

/// The rendered viewport (left of the side panel) is mostly not background: the
/// paint callback drew the mesh.
fn assert_viewport_shows_the_mesh(harness: &mut Harness<'static, EditorApp>) {
    let image = harness.render().expect("the harness renders");
    let (width, height) = image.dimensions();
    let mut mesh_pixels = 0;
    let mut total = 0;
    for y in (40..height - 10).step_by(4) {
        for x in (10..width * 2 / 3).step_by(4) {
            let [r, g, b, _] = image.get_pixel(x, y).0.map(i32::from);
            total += 1;
            // The mesh is a warm beige, the background a dark blue-grey.
            if r > 90 && r > b + 15 && g > 60 {
                mesh_pixels += 1;
            }
        }
    }
    assert!(
        mesh_pixels * 20 > total,
        "only {mesh_pixels} of {total} viewport samples show the mesh"
    );
}

#[test]
fn default_scene_binds_with_progress_to_completion() {
    let Some(mut harness) = editor() else { return };
    assert!(harness.state().is_binding(), "binding starts at once");
    let (_, total) = harness.state().bind_progress().unwrap();
    assert!(
        total >= 5000,
        "the default scene has several thousand vertices"
    );
    run_until_bound(&mut harness);
    let app = harness.state();
    assert_eq!(
        app.last_bind_progress(),
        Some((total, total)),
        "progress reached 100%"
    );
    let weights = app
        .document()
        .weights(Method::Pmvc)
        .expect("weights exist after the bind");
    assert_eq!(weights.rows, total);
    // Both methods are bound, each once.
    assert_eq!(app.document().weights(Method::Mvc).unwrap().rows, total);
    assert_eq!(app.bind_count(), 2);
    assert!(app.document().outside().is_empty());
    // At rest the GPU deformation reproduces the mesh (linear precision).
    let deformed = app.read_back_deformed().unwrap().unwrap();
    let rest = rest_positions(app);
    assert!(max_distance(&deformed, &rest) < 1e-3);
    assert_viewport_shows_the_mesh(&mut harness);
    harness.snapshot_options("editor_default_scene", &snapshot_options());
}

#[test]
fn click_selects_drag_moves_and_undo_restores() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let rest_gpu = harness.state().read_back_deformed().unwrap().unwrap();
    let (handle, at) = isolated_handle(&harness);

    // Click selects.
    click(&mut harness, at);
    assert_eq!(
        harness
            .state()
            .document()
            .selection()
            .iter()
            .copied()
            .collect::<Vec<_>>(),
        vec![handle]
    );

    // Drag moves the handle and the mesh on the GPU with it.
    let before = harness.state().document().pose()[handle];
    drag(
        &mut harness,
        at,
        at + egui::vec2(60.0, -30.0),
        Modifiers::NONE,
    );
    let app = harness.state();
    let after = app.document().pose()[handle];
    assert!(after.distance(before) > 1e-3, "the handle moved");
    let others_still = app
        .document()
        .pose()
        .iter()
        .zip(app.document().cage().positions())
        .enumerate()
        .all(|(i, (p, r))| i == handle || p == r);
    assert!(others_still, "only the selected handle moved");
    assert_gpu_mesh_moved_as_on_the_cpu(app, &rest_gpu);
    assert_viewport_shows_the_mesh(&mut harness);
    harness.snapshot_options("editor_after_drag", &snapshot_options());

    // Undo restores the rest pose, on the CPU and on the GPU.
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    let app = harness.state();
    assert_eq!(app.document().pose(), app.document().cage().positions());
    let undone_gpu = app.read_back_deformed().unwrap().unwrap();
    assert!(max_distance(&undone_gpu, &rest_gpu) < 1e-6);

    // Redo brings the drag back.
    harness.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    harness.run_steps(2);
    assert_eq!(harness.state().document().pose()[handle], after);

    // Escape clears the selection.
    harness.key_press(Key::Escape);
    harness.run_steps(2);
    assert!(harness.state().document().selection().is_empty());
}

#[test]
fn box_select_with_ctrl_selects_handles_inside_the_band() {
    let Some(mut harness) = editor() else { return };
    harness.run_steps(2);
    let (handle, at) = isolated_handle(&harness);
    drag(
        &mut harness,
        at - egui::vec2(8.0, 8.0),
        at + egui::vec2(8.0, 8.0),
        Modifiers::COMMAND,
    );
    assert!(harness.state().document().selection().contains(&handle));
    assert_eq!(
        harness.state().document().pose(),
        harness.state().document().cage().positions()
    );
}

#[test]
fn malformed_files_show_an_error_and_keep_the_scene() {
    let Some(mut harness) = editor() else { return };
    let directory = tempfile::tempdir().unwrap();
    let bad_mesh = directory.path().join("broken.obj");
    std::fs::write(&bad_mesh, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    let open_cage = directory.path().join("open_cage.obj");
    std::fs::write(
        &open_cage,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n",
    )
    .unwrap();
    let title = harness.state().document().title().to_owned();
    let vertices = harness.state().document().mesh().positions.len();

    assert!(!harness.state_mut().open_file(FileRole::Mesh, &bad_mesh));
    let error = harness.state().last_error().unwrap().to_owned();
    assert!(
        error.contains("broken.obj") && error.contains("face"),
        "{error}"
    );

    assert!(!harness.state_mut().open_file(FileRole::Cage, &open_cage));
    let error = harness.state().last_error().unwrap().to_owned();
    assert!(
        error.contains("open_cage.obj") && error.contains("edge"),
        "{error}"
    );

    harness.run_steps(2);
    assert_eq!(harness.state().document().title(), title);
    assert_eq!(harness.state().document().mesh().positions.len(), vertices);
    run_until_bound(&mut harness);
    assert!(
        harness.state().document().weights(Method::Pmvc).is_some(),
        "the scene still binds"
    );
}

#[test]
fn cancelling_a_bind_keeps_the_previous_state_usable() {
    let Some(mut harness) = editor() else { return };
    // Cancel the very first bind: the mesh stays at rest and editable.
    harness.state_mut().cancel_bind();
    run_until_bound(&mut harness);
    assert!(harness.state().document().weights(Method::Pmvc).is_none());
    assert!(harness.state().document().weights(Method::Mvc).is_none());
    let rest = harness.state().read_back_deformed().unwrap().unwrap();
    assert_eq!(
        rest.len(),
        harness.state().document().mesh().positions.len()
    );

    // Bind, then cancel a rebind at another resolution: the old weights stay.
    harness.state_mut().start_bind();
    run_until_bound(&mut harness);
    let weights = harness
        .state()
        .document()
        .weights(Method::Pmvc)
        .cloned()
        .expect("bound");
    harness.state_mut().set_resolution(24);
    assert!(harness.state().is_binding());
    harness.step();
    harness.state_mut().cancel_bind();
    run_until_bound(&mut harness);
    let app = harness.state();
    assert!(std::sync::Arc::ptr_eq(
        app.document().weights(Method::Pmvc).unwrap(),
        &weights
    ));
    assert!(app.read_back_deformed().unwrap().is_ok());
}

#[test]
fn poses_save_load_reset_and_the_deformed_mesh_exports() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let directory = tempfile::tempdir().unwrap();
    let pose_path = directory.path().join("pose.obj");
    let export_path = directory.path().join("deformed.obj");
    let app = harness.state_mut();
    let rest = app.document().cage().positions().to_vec();
    let moved = rest[5] + glam::DVec3::new(0.5, 0.25, 0.0);
    app.set_handle_position(5, moved);
    app.save_pose(&pose_path);
    app.export_deformed(&export_path);
    assert!(app.last_error().is_none(), "{:?}", app.last_error());

    let exported = pmvc::formats::load_mesh(&export_path)
        .unwrap()
        .mesh
        .positions;
    let expected = app.document().deformed_positions(app.active_method());
    assert_eq!(exported.len(), expected.len());
    let worst = exported
        .iter()
        .zip(&expected)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    assert!(worst < 1e-5, "export matches the deformation ({worst})");

    app.reset_pose();
    assert_eq!(app.document().pose(), rest);
    assert!(app.load_pose(&pose_path));
    assert!(app.document().pose()[5].distance(moved) < 1e-5);
    app.undo();
    assert_eq!(app.document().pose(), rest);

    // A pose with the wrong vertex count is refused and changes nothing.
    let wrong = directory.path().join("wrong.obj");
    std::fs::write(&wrong, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    assert!(!app.load_pose(&wrong));
    assert!(app.last_error().unwrap().contains("wrong.obj"));
    assert_eq!(app.document().pose(), rest);

    // So is one far beyond the cage, which no session could hold: what is
    // loaded can be saved and opened again.
    let far = directory.path().join("far.obj");
    let mut far_pose = rest.clone();
    far_pose[0].x = 1e12;
    let text: String = far_pose
        .iter()
        .map(|p| format!("v {} {} {}\n", p.x, p.y, p.z))
        .collect();
    std::fs::write(&far, text).unwrap();
    assert!(!app.load_pose(&far));
    let error = app.last_error().unwrap();
    assert!(
        error.contains("far.obj") && error.contains("position 1"),
        "{error}"
    );
    assert_eq!(app.document().pose(), rest);
}

fn button_drag(
    harness: &mut Harness<'static, EditorApp>,
    button: PointerButton,
    from: Pos2,
    to: Pos2,
) {
    harness.hover_at(from);
    harness.step();
    harness.event(Event::PointerButton {
        pos: from,
        button,
        pressed: true,
        modifiers: Modifiers::NONE,
    });
    harness.step();
    for k in 1..=8 {
        harness.hover_at(from + (to - from) * (k as f32 / 8.0));
        harness.step();
    }
    harness.event(Event::PointerButton {
        pos: to,
        button,
        pressed: false,
        modifiers: Modifiers::NONE,
    });
    harness.run_steps(2);
}

#[test]
fn orbit_pan_zoom_and_frame_move_the_camera_not_the_cage() {
    let Some(mut harness) = editor() else { return };
    harness.run_steps(2);
    let empty = Pos2::new(40.0, 80.0);
    let framed = harness.state().camera();

    button_drag(
        &mut harness,
        PointerButton::Primary,
        empty,
        empty + egui::vec2(80.0, 20.0),
    );
    let orbited = harness.state().camera();
    assert_ne!(orbited.yaw, framed.yaw, "left-drag on empty space orbits");
    button_drag(
        &mut harness,
        PointerButton::Middle,
        empty,
        empty + egui::vec2(0.0, 40.0),
    );
    assert_ne!(
        harness.state().camera().pitch,
        orbited.pitch,
        "middle-drag orbits"
    );
    let orbited = harness.state().camera();

    button_drag(
        &mut harness,
        PointerButton::Secondary,
        empty,
        empty + egui::vec2(50.0, 0.0),
    );
    assert_ne!(
        harness.state().camera().target,
        orbited.target,
        "right-drag pans"
    );

    harness.hover_at(Pos2::new(300.0, 300.0));
    harness.event(Event::MouseWheel {
        unit: egui::MouseWheelUnit::Point,
        delta: egui::vec2(0.0, 120.0),
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Wheel,
        modifiers: Modifiers::NONE,
    });
    harness.run_steps(20);
    assert!(
        harness.state().camera().distance < framed.distance,
        "wheel up zooms in"
    );

    harness.key_press(Key::F);
    harness.run_steps(2);
    let refocused = harness.state().camera();
    assert_eq!(refocused.target, framed.target);
    assert_eq!(refocused.distance, framed.distance);
    let app = harness.state();
    assert_eq!(
        app.document().pose(),
        app.document().cage().positions(),
        "the cage never moved"
    );
    assert!(app.document().selection().is_empty());
}

#[test]
fn holding_x_constrains_a_drag_to_the_x_axis() {
    let Some(mut harness) = editor() else { return };
    harness.run_steps(2);
    let (handle, at) = isolated_handle(&harness);
    let before = harness.state().document().pose()[handle];
    harness.key_down(Key::X);
    harness.step();
    drag(
        &mut harness,
        at,
        at + egui::vec2(50.0, -40.0),
        Modifiers::NONE,
    );
    harness.key_up(Key::X);
    harness.step();
    let delta = harness.state().document().pose()[handle] - before;
    assert!(delta.x.abs() > 1e-3, "moved along x: {delta}");
    assert!(
        delta.y.abs() < 1e-9 && delta.z.abs() < 1e-9,
        "only along x: {delta}"
    );
}

#[test]
fn shift_click_toggles_and_the_scenes_menu_switches_scenes() {
    let Some(mut harness) = editor() else { return };
    harness.run_steps(2);
    let (handle, at) = isolated_handle(&harness);
    for expected in [true, false] {
        harness.event(Event::ModifiersChanged(Modifiers::SHIFT));
        harness.hover_at(at);
        harness.step();
        harness.event(Event::PointerButton {
            pos: at,
            button: PointerButton::Primary,
            pressed: true,
            modifiers: Modifiers::SHIFT,
        });
        harness.step();
        harness.event(Event::PointerButton {
            pos: at,
            button: PointerButton::Primary,
            pressed: false,
            modifiers: Modifiers::SHIFT,
        });
        harness.event(Event::ModifiersChanged(Modifiers::NONE));
        harness.run_steps(2);
        assert_eq!(
            harness.state().document().selection().contains(&handle),
            expected
        );
    }
    harness
        .state_mut()
        .open_bundled(pmvc::app::scenes::BundledScene::Scan);
    run_until_bound(&mut harness);
    let app = harness.state();
    assert_eq!(app.document().mesh().positions.len(), 2775);
    assert!(app.document().weights(Method::Pmvc).is_some());
    assert!(app.document().outside().is_empty());
}

/// Bound on the editor's own device, the vertex shader reads the weights where the
/// bind left them; a drag must still move the mesh exactly as the CPU weights say.
#[test]
fn weights_bound_on_the_editors_device_deform_the_mesh() {
    let Some(mut harness) = editor_binding_on(BindOn::Gpu) else {
        return;
    };
    run_until_bound(&mut harness);
    let device = harness
        .state()
        .document()
        .bound(Method::Pmvc)
        .expect("bound")
        .device
        .clone();
    assert!(!device.eq_ignore_ascii_case("cpu"), "bound on {device}");
    let rest_gpu = harness.state().read_back_deformed().unwrap().unwrap();
    let (_, at) = isolated_handle(&harness);
    click(&mut harness, at);
    drag(
        &mut harness,
        at,
        at + egui::vec2(50.0, 40.0),
        Modifiers::NONE,
    );
    assert_gpu_mesh_moved_as_on_the_cpu(harness.state(), &rest_gpu);
}

/// A device without storage buffers (what wgpu's GL backend gives by default)
/// cannot run the viewport's shaders: the editor says so and still binds on the
/// CPU, where wgpu would otherwise panic on the first pipeline.
#[test]
fn an_adapter_too_weak_for_the_viewport_gets_a_notice_not_a_panic() {
    let Some(state) = render_state_limited_to(wgpu::Limits::downlevel_webgl2_defaults()) else {
        return;
    };
    let mut harness = editor_on(state, Default::default());
    let error = harness.state().last_error().expect("a notice").to_owned();
    assert!(
        error.contains("cannot draw the viewport")
            && error.contains("storage buffers")
            && error.contains("mesa-vulkan-drivers"),
        "{error}"
    );
    run_until_bound(&mut harness);
    let app = harness.state();
    assert_eq!(
        app.document().bound(Method::Pmvc).expect("bound").device,
        "CPU"
    );
    assert!(app.read_back_deformed().is_none(), "no GPU mesh to read");
    // The window still draws its panels.
    harness.get_by_label("Side by side");
}

/// Notices name files by their full path; a long one wraps inside the side panel
/// instead of widening it (and squeezing the viewport).
#[test]
fn a_long_path_in_a_notice_does_not_widen_the_side_panel() {
    let pose = guide_pose();
    let directory = tempfile::tempdir().unwrap();
    let side_panel_left = |folder: &str| {
        let copy = directory.path().join(folder).join("pose.obj");
        std::fs::create_dir_all(copy.parent().unwrap()).unwrap();
        std::fs::copy(&pose, &copy).unwrap();
        let mut harness = editor_with(pmvc::app::EditorOptions {
            pose: Some(copy),
            ..Default::default()
        })?;
        harness.run_steps(3);
        assert!(harness.state().last_error().is_none());
        Some(harness.get_by_label("Reset pose").rect().left())
    };
    let Some(short) = side_panel_left("a") else {
        return;
    };
    // The notice reads "loaded pose <path>": lengths around the panel's width, and
    // far beyond it.
    for length in (2..60).step_by(3).chain([200]) {
        let long = side_panel_left(&"b".repeat(length));
        assert_eq!(long, Some(short), "a folder name of {length} characters");
    }
}
