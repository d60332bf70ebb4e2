//! File > Generate cage…: a cage generated in the background is proposed, then
//! used as one undo step that binds; Cancel and Discard change nothing; a failing
//! mesh says why in the window; `pmvc edit MESH` with no cage opens the window.

use crate::common;

use common::editor::*;
use egui::{Key, Modifiers};
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use glam::DVec3;
use pmvc::app::{EditorApp, EditorOptions};
use pmvc::geometry::classify_points;
use std::path::PathBuf;
use std::time::{Duration, Instant};

fn choose_in_file_menu(harness: &mut Harness<'static, EditorApp>, entry: &str) {
    harness.get_by_label("File").click();
    harness.run_steps(2);
    harness.get_by_label(entry).click();
    harness.run_steps(2);
}

fn click_button(harness: &mut Harness<'static, EditorApp>, label: &str) {
    harness.get_by_label(label).click();
    harness.run_steps(2);
}

/// Step until the generation job has ended.
fn run_until_generated(harness: &mut Harness<'static, EditorApp>) {
    let deadline = Instant::now() + Duration::from_secs(300);
    while harness.state().cage_generation().is_running() {
        assert!(
            Instant::now() < deadline,
            "the cage was not generated in time"
        );
        harness.step();
        std::thread::sleep(Duration::from_millis(20));
    }
    harness.run_steps(3);
}

/// File > Generate cage… with `target` vertices, waiting for the proposal.
fn propose_cage(harness: &mut Harness<'static, EditorApp>, target: usize) {
    choose_in_file_menu(harness, "Generate cage…");
    harness.state_mut().cage_generation_mut().target_vertices = target;
    click_button(harness, "Generate");
    run_until_generated(harness);
}

fn cage_positions(app: &EditorApp) -> Vec<DVec3> {
    app.document().cage().positions().to_vec()
}

fn assets(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("assets")
        .join(name)
}

#[test]
fn a_generated_cage_is_proposed_then_used_as_one_undo_step_that_binds() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let old_cage = cage_positions(harness.state());
    let method = harness.state().active_method();

    choose_in_file_menu(&mut harness, "Generate cage…");
    assert!(harness.state().cage_generation().is_open());
    // The window offers the current cage's vertex count.
    assert_eq!(
        harness.state().cage_generation().target_vertices,
        old_cage.len()
    );
    harness.state_mut().cage_generation_mut().target_vertices = 24;
    click_button(&mut harness, "Generate");
    run_until_generated(&mut harness);

    let proposed = {
        let proposal = harness
            .state()
            .cage_generation()
            .proposal()
            .expect("a proposal once generated");
        assert_eq!(proposal.generated.stats.target_vertices, 24);
        proposal.generated.cage.positions().to_vec()
    };
    harness.get_by_label_contains("(target 24)");
    harness.get_by_label_contains("minimum clearance: ");
    harness.get_by_label_contains("volume ratio (cage / mesh): ");
    harness.get_by_label_contains("minimum angle: ");
    // Proposed, not used: the document keeps its cage until the user says so.
    assert_eq!(cage_positions(harness.state()), old_cage);
    assert!(!harness.state().is_binding());

    let binds = harness.state().bind_count();
    click_button(&mut harness, "Use this cage");
    assert_eq!(cage_positions(harness.state()), proposed);
    assert_eq!(harness.state().document().pose(), proposed.as_slice());
    assert!(harness.state().cage_generation().proposal().is_none());
    assert!(!harness.state().cage_generation().is_open());
    assert!(harness.state().bind_count() > binds, "no bind started");
    run_until_bound(&mut harness);
    let weights = harness
        .state()
        .document()
        .weights(method)
        .expect("bound to the new cage");
    assert_eq!(weights.cols, proposed.len());
    assert!(harness
        .state()
        .undo_label()
        .is_some_and(|label| label.contains("generated")));

    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(cage_positions(harness.state()), old_cage);
    let restored = harness
        .state()
        .document()
        .weights(method)
        .expect("the old cage's weights come back with it");
    assert_eq!(restored.cols, old_cage.len());
    assert!(!harness.state().is_binding(), "undo must not bind again");
}

#[test]
fn cancel_and_discard_leave_the_scene_as_it_was() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let old_cage = cage_positions(harness.state());
    let undo_before = harness.state().undo_label();
    let binds = harness.state().bind_count();

    choose_in_file_menu(&mut harness, "Generate cage…");
    click_button(&mut harness, "Generate");
    assert!(harness.state().cage_generation().is_running());
    harness.get_by_label("Cancel").click();
    harness.run_steps(2);
    assert!(!harness.state().cage_generation().is_running());
    assert_eq!(
        harness.state().cage_generation().message(),
        Some("cancelled")
    );
    harness.get_by_label("cancelled");

    click_button(&mut harness, "Generate");
    run_until_generated(&mut harness);
    assert!(harness.state().cage_generation().proposal().is_some());
    click_button(&mut harness, "Discard");
    assert!(harness.state().cage_generation().proposal().is_none());
    assert!(harness.state().cage_generation().is_open());

    assert_eq!(cage_positions(harness.state()), old_cage);
    assert_eq!(harness.state().undo_label(), undo_before);
    assert_eq!(harness.state().bind_count(), binds);
}

#[test]
fn a_mesh_opened_alone_sits_in_a_box_with_the_window_open() {
    // What `pmvc edit MESH` passes to the editor.
    let mesh = assets("comb_mesh.obj");
    let Some(mut harness) = editor_with(EditorOptions {
        mesh: Some(mesh.clone()),
        ..Default::default()
    }) else {
        return;
    };
    harness.run_steps(3);
    let app = harness.state();
    assert_eq!(app.last_error(), None);
    assert!(app.cage_generation().is_open());
    assert_eq!(
        app.cage_generation().target_vertices,
        pmvc::app::cage_generation::DEFAULT_TARGET_VERTICES
    );
    let loaded = pmvc::formats::load_mesh(&mesh).unwrap();
    assert_eq!(app.document().mesh().positions, loaded.mesh.positions);
    assert_eq!(app.document().cage().vertex_count(), 8);
    let classes = classify_points(app.document().cage(), &loaded.mesh.positions);
    assert!(classes.outside.is_empty(), "the box must enclose the mesh");
    harness.get_by_label("Generate");
    run_until_bound(&mut harness);

    click_button(&mut harness, "Generate");
    run_until_generated(&mut harness);
    let vertices = harness
        .state()
        .cage_generation()
        .proposal()
        .expect("a proposal")
        .generated
        .cage
        .vertex_count();
    click_button(&mut harness, "Use this cage");
    assert_eq!(harness.state().document().cage().vertex_count(), vertices);
    run_until_bound(&mut harness);
    assert!(harness.state().last_error().is_none());
}

#[test]
fn a_mesh_with_no_triangles_says_why_in_the_window_and_keeps_the_scene() {
    let dir = tempfile::tempdir().unwrap();
    let (points, _, _, _) = common::comb_scene(dir.path(), 30);
    let Some(mut harness) = editor_with(EditorOptions {
        mesh: Some(points),
        ..Default::default()
    }) else {
        return;
    };
    run_until_bound(&mut harness);
    let cage = cage_positions(harness.state());
    click_button(&mut harness, "Generate");
    run_until_generated(&mut harness);
    harness.get_by_label_contains("no triangles");
    assert!(harness.state().cage_generation().proposal().is_none());
    assert_eq!(cage_positions(harness.state()), cage);
    assert!(harness.state().cage_generation().is_open());
}

#[test]
fn a_mesh_opened_away_from_the_cage_gets_a_box_and_the_window_and_undo_returns() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let old_cage = cage_positions(harness.state());
    let comb = pmvc::formats::load_mesh(&assets("comb_mesh.obj"))
        .unwrap()
        .mesh;
    let far: Vec<DVec3> = comb
        .positions
        .iter()
        .map(|p| *p + DVec3::new(100.0, 0.0, 0.0))
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let path = common::write(
        dir.path(),
        "far.obj",
        &common::triangles_obj(&far, &comb.triangles),
    );
    assert!(harness
        .state_mut()
        .open_file(pmvc::app::FileRole::Mesh, &path));
    harness.run_steps(2);
    let app = harness.state();
    assert!(app.cage_generation().is_open());
    assert_eq!(app.document().cage().vertex_count(), 8);
    let classes = classify_points(app.document().cage(), &far);
    assert!(classes.outside.is_empty(), "the box must enclose the mesh");
    run_until_bound(&mut harness);
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Z);
    harness.run_steps(2);
    assert_eq!(cage_positions(harness.state()), old_cage);
    assert_eq!(
        harness.state().document().mesh().positions.len(),
        comb.positions.len()
    );
    assert_ne!(harness.state().document().mesh().positions, far);
}

#[test]
fn the_voxel_size_box_sets_the_voxels_the_proposal_is_made_from() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    choose_in_file_menu(&mut harness, "Generate cage…");
    harness.state_mut().cage_generation_mut().cell_size_percent = 5.0;
    assert_eq!(harness.state().cage_generation().options().cell_size, None);
    harness.get_by_label("Voxel size").click();
    harness.run_steps(2);
    assert_eq!(
        harness.state().cage_generation().options().cell_size,
        Some(0.05)
    );
    click_button(&mut harness, "Generate");
    run_until_generated(&mut harness);
    let proposal = harness
        .state()
        .cage_generation()
        .proposal()
        .expect("a proposal");
    let stats = &proposal.generated.stats;
    let share = stats.cell_size / stats.mesh_diagonal;
    assert!(
        (share - 0.05).abs() < 1e-9,
        "voxel size {share} of the diagonal"
    );
    // At the comb's 40 vertices a prism may replace the voxels' cage, which the
    // line then adds after "as asked".
    harness.get_by_label_contains("(5.00% of the mesh diagonal, as asked");
}

/// Bound to a generated cage, the handles drag the mesh as with any other cage.
#[test]
fn a_generated_cage_binds_and_its_handles_drag_the_mesh() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    propose_cage(&mut harness, 24);
    click_button(&mut harness, "Use this cage");
    run_until_bound(&mut harness);
    let method = harness.state().active_method();
    let weights = harness.state().document().weights(method).expect("bound");
    assert_eq!(
        weights.cols,
        harness.state().document().cage().vertex_count()
    );
    let (handle, rest_drawn) = drag_an_isolated_handle(&mut harness);
    let app = harness.state();
    let moved_handle =
        app.document().pose()[handle].distance(app.document().cage().positions()[handle]);
    assert!(moved_handle > 1e-3, "the handle moved by {moved_handle}");
    let drawn = app.read_back_deformed().unwrap().unwrap();
    let moved = max_distance(&drawn, &rest_drawn);
    assert!(moved > 1e-3, "the drawn mesh moved by {moved}");
}

#[test]
fn a_mesh_inside_the_cages_box_but_outside_the_cage_gets_a_box_and_the_window() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let cage = harness.state().document().cage().clone();
    // A point in the cage's bounding box but outside the cage: between fingers.
    let (lo, hi) = pmvc::geometry::bounds_of(cage.positions());
    let steps = 64;
    let grid: Vec<DVec3> = (1..steps)
        .flat_map(|i| (1..steps).map(move |j| (i, j)))
        .map(|(i, j)| {
            let t = DVec3::new(i as f64, j as f64, steps as f64 / 2.0) / steps as f64;
            lo + (hi - lo) * t
        })
        .collect();
    let classes = classify_points(&cage, &grid);
    let gap = grid[*classes.outside.first().expect("the comb has gaps") as usize];
    let size = 1e-3 * cage.diagonal();
    let tetra = [
        gap,
        gap + DVec3::X * size,
        gap + DVec3::Y * size,
        gap + DVec3::Z * size,
    ];
    assert_eq!(
        classify_points(&cage, &tetra).outside.len(),
        4,
        "the test mesh is wholly outside the cage"
    );
    let dir = tempfile::tempdir().unwrap();
    let path = common::write(
        dir.path(),
        "between.obj",
        &common::triangles_obj(&tetra, &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
    );
    assert!(harness
        .state_mut()
        .open_file(pmvc::app::FileRole::Mesh, &path));
    harness.run_steps(2);
    let app = harness.state();
    assert!(
        app.cage_generation().is_open(),
        "a mesh the cage holds none of is offered a cage"
    );
    assert_eq!(app.document().cage().vertex_count(), 8);
    assert!(classify_points(app.document().cage(), &tetra)
        .outside
        .is_empty());
}

#[test]
fn a_generated_cage_is_unsaved_work_that_quitting_and_opening_ask_about() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().open_cage_generation();
    harness.state_mut().cage_generation_mut().target_vertices = 24;
    harness.state_mut().start_cage_generation();
    run_until_generated(&mut harness);
    assert!(harness.state_mut().use_generated_cage());
    run_until_bound(&mut harness);
    let unsaved = harness.state().unsaved();
    assert!(unsaved.cage && !unsaved.pose, "{unsaved:?}");

    // Opening another scene asks, and Cancel keeps the generated cage.
    let cage = cage_positions(harness.state());
    harness
        .state_mut()
        .open_bundled(pmvc::app::scenes::BundledScene::Scan);
    harness.run_steps(2);
    harness.get_by_label_contains("the edited or generated cage");
    harness.get_by_label("Cancel").click();
    harness.run_steps(2);
    assert_eq!(cage_positions(harness.state()), cage);

    // Quitting asks too; a saved session holds the cage, and then nothing is
    // unsaved.
    harness.key_press_modifiers(Modifiers::COMMAND, Key::Q);
    harness.run_steps(2);
    assert!(harness.state().is_asking_to_quit());
    harness.get_by_label("Cancel").click();
    harness.run_steps(2);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("generated.session.json");
    assert!(harness.state_mut().save_session(&path));
    assert!(!harness.state().unsaved().any());
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("\"inline\""), "the cage is in the session");
}

/// The Quads box pairs the proposal's triangles into quads, which the editor
/// then binds as bilinear patches.
#[test]
fn the_quads_box_proposes_a_cage_with_quads_that_binds_as_patches() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    choose_in_file_menu(&mut harness, "Generate cage…");
    harness.state_mut().cage_generation_mut().target_vertices = 60;
    assert!(!harness.state().cage_generation().options().quads);
    harness.get_by_label("where they fit").click();
    harness.run_steps(2);
    assert!(harness.state().cage_generation().options().quads);
    click_button(&mut harness, "Generate");
    run_until_generated(&mut harness);
    let quads = {
        let proposal = harness
            .state()
            .cage_generation()
            .proposal()
            .expect("a proposal");
        proposal.generated.cage.quads().len()
    };
    assert!(quads > 0, "no quads proposed");
    harness.get_by_label_contains(&format!("{quads} quads and "));
    click_button(&mut harness, "Use this cage");
    run_until_bound(&mut harness);
    let document = harness.state().document();
    assert_eq!(document.cage().quads().len(), quads);
    let method = harness.state().active_method();
    let bound = document.bound(method).expect("bound");
    assert_eq!(bound.options.quads, pmvc::coords::QuadSplit::None);
}

/// A proposal that bridges gaps says so in the window, with the key to the
/// orange dots that mark them in the view; the points it marks are inside the
/// proposed cage.
#[test]
fn a_proposal_that_bridges_gaps_marks_them() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    // Few vertices: the comb's prongs share one part of the cage.
    propose_cage(&mut harness, 16);
    let (bridged, cage) = {
        let proposal = harness
            .state()
            .cage_generation()
            .proposal()
            .expect("a proposal once generated");
        let gaps = &proposal.generated.stats.gaps;
        assert!(gaps.closed() > 0, "{gaps:?}");
        (gaps.bridged.clone(), proposal.generated.cage.clone())
    };
    let classes = classify_points(&cage, &bridged).classes;
    assert!(classes
        .iter()
        .all(|c| !matches!(c, pmvc::geometry::PointClass::Outside)));
    harness.get_by_label_contains(&format!(
        "Orange dots in the view: the {} points in the gaps this cage bridges",
        bridged.len()
    ));
}
