//! File actions through the in-window dialog, the one used where the system's
//! dialog cannot appear (no desktop portal): browsing, loading a pose, saving it,
//! exporting, and a bad file that keeps the dialog and the scene.

use crate::common;

use common::editor::*;
use egui::{Key, Modifiers};
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use glam::DVec3;
use pmvc::app::ui::file_dialog::FileAction;
use pmvc::app::EditorApp;
use pmvc::formats::load_mesh;

fn choose_in_file_menu(harness: &mut Harness<'static, EditorApp>, entry: &str) {
    harness.get_by_label("File").click();
    harness.run_steps(2);
    harness.get_by_label(entry).click();
    harness.run_steps(2);
}

/// Replace the text of the dialog's field labelled `label` with `text`, typed.
fn type_into(harness: &mut Harness<'static, EditorApp>, label: &str, text: &str) {
    harness.get_by_label(label).focus();
    harness.step();
    harness.key_press_modifiers(Modifiers::COMMAND, Key::A);
    harness.step();
    harness.get_by_label(label).type_text(text);
    harness.step();
}

fn press_enter(harness: &mut Harness<'static, EditorApp>) {
    harness.key_press(Key::Enter);
    harness.run_steps(2);
}

#[test]
fn the_in_window_dialog_browses_loads_saves_and_exports() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().set_in_window_file_dialog(true);
    let dir = tempfile::tempdir().unwrap();
    let poses = dir.path().join("poses");
    std::fs::create_dir(&poses).unwrap();
    let cage = harness.state().document().cage().clone();
    let posed: Vec<DVec3> = cage
        .positions()
        .iter()
        .map(|&p| p + DVec3::new(0.05 * p.y, 0.0, 0.0))
        .collect();
    common::write(
        &poses,
        "lean.obj",
        &common::triangles_obj(&posed, cage.triangles()),
    );
    common::write(&poses, "notes.txt", "not a mesh");

    // Load pose: go to the folder by typing it, then pick the file from the list.
    choose_in_file_menu(&mut harness, "Load pose…");
    assert_eq!(
        harness.state().open_file_dialog(),
        Some(FileAction::LoadPose)
    );
    harness.get_by_label_contains("(in-window dialog)");
    let method = harness.state().active_method();
    type_into(&mut harness, "File name:", poses.to_str().unwrap());
    press_enter(&mut harness);
    assert!(
        harness.query_by_label("notes.txt").is_none(),
        "only meshes are listed"
    );
    let entry = harness.get_by_label("lean.obj").rect().center();
    click(&mut harness, entry);
    harness.get_by_label("Load").click();
    harness.run_steps(2);
    let app = harness.state();
    assert_eq!(
        app.open_file_dialog(),
        None,
        "the dialog closes once loaded"
    );
    assert_eq!(app.document().pose(), posed.as_slice());
    assert_eq!(
        app.active_method(),
        method,
        "keys typed into the dialog do not reach the viewport (M)"
    );
    assert!(!app.pose_is_unsaved(), "a loaded pose is on disk");

    // Save pose: the dialog starts in the folder used last; an existing name asks
    // for a second Save; a name without an extension gets .obj.
    harness
        .state_mut()
        .set_handle_position(0, posed[0] + DVec3::X);
    assert!(harness.state().pose_is_unsaved());
    choose_in_file_menu(&mut harness, "Save pose…");
    type_into(&mut harness, "File name:", "lean.obj");
    harness.get_by_label("Save").click();
    harness.run_steps(2);
    harness.get_by_label_contains("exists: Save again to replace it");
    type_into(&mut harness, "File name:", "moved");
    press_enter(&mut harness);
    let saved = load_mesh(&poses.join("moved.obj")).expect("the pose was saved");
    let app = harness.state();
    assert_eq!(app.open_file_dialog(), None);
    assert_eq!(saved.mesh.positions, app.document().pose());
    assert!(!app.pose_is_unsaved());
    let untouched = load_mesh(&poses.join("lean.obj")).unwrap();
    assert_eq!(
        untouched.mesh.positions, posed,
        "one Save did not replace it"
    );

    // Export, typed as an absolute path.
    choose_in_file_menu(&mut harness, "Export deformed mesh…");
    let exported = dir.path().join("deformed.obj");
    type_into(&mut harness, "File name:", exported.to_str().unwrap());
    harness.get_by_label("Export").click();
    harness.run_steps(2);
    let mesh = load_mesh(&exported).expect("the mesh was exported");
    assert_eq!(
        mesh.mesh.positions.len(),
        harness.state().document().mesh().positions.len()
    );
}

#[test]
fn a_bad_file_in_the_in_window_dialog_keeps_the_dialog_and_the_scene() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().set_in_window_file_dialog(true);
    let dir = tempfile::tempdir().unwrap();
    let broken = common::write(dir.path(), "broken.obj", "v 0 0 0\nv 1 x 0\n");
    let vertices = harness.state().document().mesh().positions.len();

    choose_in_file_menu(&mut harness, "Open mesh…");
    type_into(
        &mut harness,
        "File name:",
        dir.path().join("missing.obj").to_str().unwrap(),
    );
    harness.get_by_label("Open").click();
    harness.run_steps(2);
    harness.get_by_label_contains("missing.obj does not exist");

    type_into(&mut harness, "File name:", broken.to_str().unwrap());
    harness.get_by_label("Open").click();
    harness.run_steps(2);
    // The reader's message, with the file and its line, in the dialog (and in
    // the side panel's notices).
    assert_eq!(
        harness.query_all_by_label_contains("broken.obj:2").count(),
        2
    );
    let app = harness.state();
    assert_eq!(app.open_file_dialog(), Some(FileAction::OpenMesh));
    assert_eq!(app.document().mesh().positions.len(), vertices);

    // Escape, like Cancel, closes it and changes nothing.
    harness.key_press(Key::Escape);
    harness.run_steps(2);
    assert_eq!(harness.state().open_file_dialog(), None);
    assert!(!harness.state().is_binding());
}

#[test]
fn save_image_writes_the_views_as_drawn() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("view.png");
    assert!(harness.state_mut().save_image(&path));
    harness.run_steps(3);
    assert_eq!(harness.state().last_error(), None);
    let image = image::open(&path).unwrap().to_rgba8();
    // The panes only: no menu, toolbar or side panel.
    let panes = harness
        .state()
        .pane_rects()
        .into_iter()
        .map(|(_, rect)| rect)
        .reduce(|a, b| a.union(b))
        .unwrap();
    let scale = harness.ctx.pixels_per_point();
    assert_eq!(image.width(), (panes.width() * scale).round() as u32);
    assert_eq!(image.height(), (panes.height() * scale).round() as u32);
    // The mesh is in it: a good share of pixels differ from the background.
    let background = *image.get_pixel(2, image.height() - 2);
    let drawn = image.pixels().filter(|p| **p != background).count();
    assert!(
        drawn > image.pixels().len() / 20,
        "{drawn} drawn pixels of {}",
        image.pixels().len()
    );
    harness.get_by_label_contains("saved image");
}

#[test]
fn the_coloured_export_has_the_colours_the_gpu_draws() {
    use pmvc::app::compare::{Overlay, Pane};
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("heat.ply");
    // Plain shading has no colours to export.
    assert!(!harness.state_mut().export_coloured_mesh(&path));
    assert!(harness
        .state()
        .last_error()
        .unwrap()
        .contains("plainly shaded"));
    assert!(!path.exists());

    let app = harness.state_mut();
    app.view_mut().overlay = Overlay::Heatmap;
    app.view_mut().heat_vertex = 3;
    harness.run_steps(3);
    let app = harness.state_mut();
    assert!(app.export_coloured_mesh(&path), "{:?}", app.last_error());
    let pane = Pane::Method(app.active_method());
    let shading = app.shading_of(pane);
    let drawn = app.read_back(&shading).unwrap().unwrap().colours;
    let vertex_count = app.document().mesh().positions.len();
    let triangle_count = app.document().mesh().triangles.len();

    let text = std::fs::read_to_string(&path).unwrap();
    let (header, body) = text.split_once("end_header\n").unwrap();
    assert!(header.contains(&format!("element vertex {vertex_count}")));
    assert!(header.contains(&format!("element face {triangle_count}")));
    assert!(header.contains("coordinate of cage vertex 3"), "{header}");
    assert!(header.contains("linear scale"), "{header}");
    let rows: Vec<Vec<f64>> = body
        .lines()
        .take(vertex_count)
        .map(|line| line.split(' ').map(|v| v.parse().unwrap()).collect())
        .collect();
    let mut coloured = 0;
    for (row, gpu) in rows.iter().zip(&drawn) {
        for k in 0..3 {
            let expected = f64::from(gpu[k].clamp(0.0, 1.0)) * 255.0;
            assert!(
                (row[3 + k] - expected).abs() <= 1.01,
                "PLY {:?} GPU {gpu:?}",
                &row[3..]
            );
        }
        coloured += usize::from(row[3] != row[5]);
    }
    assert!(
        coloured > vertex_count / 10,
        "the heatmap is in the colours"
    );
}

/// A cube of six quads from -1 to 1, faces outward, as an artist's cage file.
const QUAD_CUBE: &str =
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

/// A face's corners from its `f` line, rotated to start at the smallest.
fn face_key(line: &str) -> Vec<u32> {
    let corners: Vec<u32> = line
        .split_whitespace()
        .skip(1)
        .map(|c| c.parse().unwrap())
        .collect();
    let first = (0..corners.len()).min_by_key(|&i| corners[i]).unwrap();
    corners[first..]
        .iter()
        .chain(&corners[..first])
        .copied()
        .collect()
}

fn faces_of(text: &str) -> Vec<Vec<u32>> {
    let mut faces: Vec<Vec<u32>> = text
        .lines()
        .filter(|l| l.starts_with("f "))
        .map(face_key)
        .collect();
    faces.sort();
    faces
}

#[test]
fn save_cage_keeps_the_quads_and_writes_the_pose_beside_it_never_over_the_cage_read() {
    let dir = tempfile::tempdir().unwrap();
    let cage = common::write(dir.path(), "cube_cage.obj", QUAD_CUBE);
    let mesh = common::write(
        dir.path(),
        "inner.obj",
        "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0 0.5 -0.5\nv 0 0 0.5\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n",
    );
    let Some(mut harness) = editor_on_files(&mesh, &cage) else {
        return;
    };
    let moved = glam::DVec3::new(1.5, 1.25, 1.0);
    harness.state_mut().set_handle_position(6, moved);

    // The cage read is an input: never written over.
    assert!(!harness.state_mut().save_cage(&cage));
    assert_eq!(std::fs::read_to_string(&cage).unwrap(), QUAD_CUBE);

    let out = dir.path().join("cube_cage-edited.obj");
    assert!(
        harness.state_mut().save_cage(&out),
        "{:?}",
        harness.state().last_error()
    );
    let rest = std::fs::read_to_string(&out).unwrap();
    assert_eq!(faces_of(&rest), faces_of(QUAD_CUBE), "the quads as read");
    let posed_path = dir.path().join("cube_cage-edited.posed.obj");
    let posed = std::fs::read_to_string(&posed_path).unwrap();
    assert_eq!(faces_of(&posed), faces_of(QUAD_CUBE));
    let rest_cage = pmvc::formats::load_mesh(&out).unwrap().mesh;
    let posed_cage = pmvc::formats::load_mesh(&posed_path).unwrap().mesh;
    assert_eq!(rest_cage.positions[6], glam::DVec3::new(1.0, 1.0, 1.0));
    assert_eq!(posed_cage.positions[6], moved);
    assert_eq!(
        posed_cage.positions.as_slice(),
        harness.state().document().pose()
    );
}
