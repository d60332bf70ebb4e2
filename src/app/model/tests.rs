use super::document::{Changes, Document};
use super::*;
use crate::app::compare::ViewSettings;
use crate::coords::BindOptions;
use crate::geometry::procedural::cube_cage;
use crate::geometry::TriMesh;

fn document() -> Document {
    let mesh = TriMesh {
        positions: vec![DVec3::ZERO],
        ..TriMesh::default()
    };
    Document::new("test", mesh, cube_cage(1.0))
}

fn model() -> Model {
    let mut model = Model::new(document());
    model.take_changes();
    model
}

fn view() -> SessionView {
    SessionView {
        bind_options: BindOptions::default(),
        view: ViewSettings::default(),
        cameras: crate::app::viewport::ViewportState::default().cameras(),
    }
}

fn moved(pose: &[DVec3], handle: usize, by: f64) -> Vec<DVec3> {
    let mut pose = pose.to_vec();
    pose[handle].y += by;
    pose
}

#[test]
fn every_pose_change_is_reported_and_bumps_the_revision() {
    let mut model = model();
    let pose = moved(model.document().pose(), 0, 1.0);
    model.apply(Command::edit_pose(pose));
    assert!(model.take_changes().pose);
    assert_eq!(model.document().pose_revision(), 1);
    model.apply(Command::Undo(view()));
    assert!(model.take_changes().pose);
    assert_eq!(model.document().pose(), model.document().cage().positions());
    model.apply(Command::Redo(view()));
    assert_eq!(model.document().pose_revision(), 3);
    assert!(model.take_changes().pose);
    // A no-op edit changes nothing and records no undo step.
    let same = model.document().pose().to_vec();
    assert_eq!(
        model.apply(Command::edit_pose(same)).outcome,
        Outcome::Unchanged
    );
    assert_eq!(model.take_changes(), Changes::default());
}

#[test]
fn a_gesture_is_one_undo_step() {
    let mut model = model();
    let start = model.document().pose().to_vec();
    model.apply(Command::BeginGesture(GestureKind::Drag));
    for step in 1..=5 {
        model.apply(Command::PreviewGesture(moved(&start, 2, f64::from(step))));
    }
    model.apply(Command::EndGesture {
        action: POSE_EDIT.into(),
    });
    model.apply(Command::Undo(view()));
    assert_eq!(model.document().pose(), start.as_slice());
    assert_eq!(model.undo_label(), None);
}

#[test]
fn a_pose_of_another_length_is_refused() {
    let mut model = model();
    let short = model.document().pose()[1..].to_vec();
    let applied = model.apply(Command::edit_pose(short));
    assert!(matches!(applied.outcome, Outcome::Refused(_)));
    assert_eq!(model.undo_label(), None);
}

#[test]
fn replacing_the_document_cancels_the_gesture_under_way() {
    let mut model = model();
    let start = model.document().pose().to_vec();
    model.apply(Command::BeginGesture(GestureKind::Transform));
    model.apply(Command::PreviewGesture(moved(&start, 0, 1.0)));
    let other = Document::new("other", TriMesh::default(), cube_cage(2.0));
    model.apply(Command::ReplaceDocument {
        document: Box::new(other),
        action: "open other".into(),
        view: None,
    });
    assert_eq!(model.gesture_under_way(), None);
    let ended = model.apply(Command::EndGesture {
        action: POSE_EDIT.into(),
    });
    assert_eq!(ended.outcome, Outcome::Unchanged);
    let undone = model.apply(Command::Undo(view()));
    assert_eq!(
        undone.swapped.map(|s| s.action).as_deref(),
        Some("open other")
    );
    assert_eq!(model.document().pose(), start.as_slice());
}

#[test]
fn the_oldest_steps_go_first_so_no_pose_step_outlives_its_document() {
    let mut model = model();
    // A pose edit on the first document, then nine replacements by cages of
    // growing size: only the last eight documents are kept, and the pose edit
    // of the first one, which no longer can come back, is gone with it.
    let pose = moved(model.document().pose(), 0, 1.0);
    model.apply(Command::edit_pose(pose));
    for size in 2..=10 {
        let other = Document::new("other", TriMesh::default(), cube_cage(f64::from(size)));
        model.apply(Command::ReplaceDocument {
            document: Box::new(other),
            action: format!("open cube {size}"),
            view: None,
        });
    }
    let mut undone = Vec::new();
    while let Some(swapped) = model.apply(Command::Undo(view())).swapped {
        undone.push(swapped.action);
    }
    let expected: Vec<String> = (3..=10).rev().map(|s| format!("open cube {s}")).collect();
    assert_eq!(undone, expected);
    assert_eq!(model.undo_label(), None);
    assert_pose_fits(&model);
}

fn assert_pose_fits(model: &Model) {
    assert_eq!(
        model.document().pose().len(),
        model.document().cage().vertex_count()
    );
}
