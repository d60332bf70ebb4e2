//! Panels see a narrow, read-only context and queue actions; the editor changes
//! only when it runs that queue, after the panels have drawn.

use crate::common;

use common::editor::*;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use glam::DVec3;
use pmvc::app::actions::Action;
use pmvc::app::ctx::{PanelContext, Shown};
use pmvc::app::document::Document;
use pmvc::app::model::{Command, Model};
use pmvc::app::scenes;
use pmvc::app::ui::file_dialog::FileAction;
use pmvc::app::ui::unsaved_dialog::{UnsavedAnswer, UnsavedDialog};

/// The unsaved-work question alone, over a model whose pose is not saved.
struct QuitScene {
    dialog: UnsavedDialog,
    model: Model,
    actions: Vec<Action>,
}

fn quit_scene() -> QuitScene {
    let mut model = Model::new(Document::new(
        "comb",
        scenes::comb_mesh(),
        scenes::comb_cage(),
    ));
    let pose = scenes::comb_demo_pose(model.document().cage());
    model.apply(Command::edit_pose(pose));
    assert!(model.unsaved().only_pose());
    let mut dialog = UnsavedDialog::default();
    assert!(
        !dialog.request_quit(model.unsaved()),
        "an unsaved pose asks"
    );
    QuitScene {
        dialog,
        model,
        actions: Vec::new(),
    }
}

fn quit_harness(scene: QuitScene) -> Harness<'static, QuitScene> {
    Harness::new_ui_state(
        |ui, scene: &mut QuitScene| {
            let ctx = ui.ctx().clone();
            let shown = Shown::default();
            let mut context = PanelContext::new(&scene.model, &shown, &mut scene.actions);
            scene.dialog.ui(&ctx, &mut context);
        },
        scene,
    )
}

#[test]
fn the_questions_answers_are_queued_actions_not_changes() {
    for (button, answer) in [
        ("Save session…", UnsavedAnswer::SaveSession),
        ("Save pose…", UnsavedAnswer::SavePose),
        ("Quit without saving", UnsavedAnswer::Discard),
        ("Cancel", UnsavedAnswer::Cancel),
    ] {
        let mut harness = quit_harness(quit_scene());
        harness.run();
        harness.get_by_label(button).click();
        harness.run();
        let scene = harness.state();
        assert!(
            matches!(scene.actions.as_slice(), [Action::Unsaved(a)] if *a == answer),
            "{button} queues its answer, and only that: {:?}",
            scene.actions
        );
        assert!(
            scene.model.pose_unsaved(),
            "{button}: the save point stays until the editor runs the answer"
        );
        assert!(!scene.dialog.is_asking());
        assert!(
            !scene.dialog.confirmed(),
            "{button}: quitting is the editor's to confirm"
        );
    }
}

#[test]
fn a_question_about_more_than_the_pose_offers_no_pose_file() {
    let mut scene = quit_scene();
    scene.model.apply(Command::StoreNamedPose("raised".into()));
    scene.dialog.request_quit(scene.model.unsaved());
    let mut harness = quit_harness(scene);
    harness.run();
    harness.get_by_label("Save session…");
    harness.get_by_label_contains("the pose, the named poses");
    assert!(harness.query_by_label("Save pose…").is_none());
}

#[test]
fn the_save_point_moves_only_when_the_editor_runs_the_queued_actions() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.state_mut().set_in_window_file_dialog(true);
    let rest = harness.state().document().pose()[3];
    harness
        .state_mut()
        .set_handle_position(3, rest + DVec3::new(0.0, 0.5, 0.0));
    assert!(harness.state().pose_is_unsaved());

    harness
        .state_mut()
        .queue_action(Action::Apply(Command::MarkSaved));
    assert!(
        harness.state().pose_is_unsaved(),
        "a queued action changes nothing by itself"
    );
    harness.step();
    assert!(
        !harness.state().pose_is_unsaved(),
        "the frame's runner applied it"
    );

    // The question's Save pose… reaches the file dialog through the runner, in
    // the frame it was clicked, and leaves the save point alone.
    harness
        .state_mut()
        .set_handle_position(3, rest + DVec3::new(0.0, 0.7, 0.0));
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Q);
    harness.run_steps(2);
    assert!(harness.state().is_asking_to_quit());
    harness.get_by_label("Save pose…").click();
    harness.step();
    assert_eq!(
        harness.state().open_file_dialog(),
        Some(FileAction::SavePose)
    );
    assert!(harness.state().pose_is_unsaved());
    assert!(!harness.state().quit_confirmed());
}

/// The notices panel with its own list, over the comb.
struct NoticesScene {
    notices: pmvc::app::ui::notices::Notices,
    model: Model,
    actions: Vec<Action>,
}

#[test]
fn dismissing_a_notice_is_queued_and_removes_that_notice_when_run() {
    let mut notices = pmvc::app::ui::notices::Notices::default();
    notices.info("first");
    notices.error("second");
    let scene = NoticesScene {
        notices,
        model: Model::new(Document::new(
            "comb",
            scenes::comb_mesh(),
            scenes::comb_cage(),
        )),
        actions: Vec::new(),
    };
    let mut harness = Harness::new_ui_state(
        |ui, scene: &mut NoticesScene| {
            let shown = Shown::default();
            let mut context = PanelContext::new(&scene.model, &shown, &mut scene.actions);
            scene.notices.ui(ui, &mut context);
        },
        scene,
    );
    harness.run();
    // Newest first: the first "x" dismisses "second", at index 1 of the list.
    harness.get_all_by_label("x").next().unwrap().click();
    harness.run();
    let scene = harness.state_mut();
    assert_eq!(scene.notices.all().len(), 2, "the panel only asks");
    let index = match scene.actions.as_slice() {
        [Action::DismissNotice(index)] => *index,
        other => panic!("expected one DismissNotice, got {other:?}"),
    };
    scene.notices.dismiss(index);
    let left: Vec<&str> = scene
        .notices
        .all()
        .iter()
        .map(|n| n.text.as_str())
        .collect();
    assert_eq!(left, ["first"]);
}

/// A panel drawn alone over the comb: what it shows, and what it sent.
struct PanelScene {
    model: Model,
    shown: Shown,
    actions: Vec<Action>,
}

fn panel_harness(
    draw: fn(&mut egui::Ui, &mut PanelContext),
    shown: Shown,
) -> Harness<'static, PanelScene> {
    let model = Model::new(Document::new(
        "comb",
        scenes::comb_mesh(),
        scenes::comb_cage(),
    ));
    let scene = PanelScene {
        model,
        shown,
        actions: Vec::new(),
    };
    let mut harness = Harness::new_ui_state(
        move |ui, scene: &mut PanelScene| {
            let mut context = PanelContext::new(&scene.model, &scene.shown, &mut scene.actions);
            draw(ui, &mut context);
        },
        scene,
    );
    harness.run();
    harness
}

#[test]
fn an_idle_toolbar_sends_nothing() {
    // With every control drawn: the difference with a fixed scale (a value
    // shown in % and read back), a heatmap of a triangle.
    let mut shown = Shown::default();
    shown.view.layout = pmvc::app::compare::Layout::Difference;
    shown.view.difference_limit = Some(0.0123);
    shown.view.overlay = pmvc::app::compare::Overlay::Heatmap;
    shown.view.heat_triangle = Some(2);
    let mut harness = panel_harness(pmvc::app::ui::toolbar::toolbar, shown);
    harness.run_steps(3);
    assert!(
        harness.state().actions.is_empty(),
        "{:?}",
        harness.state().actions
    );
}

#[test]
fn the_toolbar_sends_new_view_settings_and_the_method_and_changes_nothing() {
    let mut harness = panel_harness(pmvc::app::ui::toolbar::toolbar, Shown::default());
    harness.get_by_label("Difference").click();
    harness.run();
    let before = harness.state().shown.view;
    let sent = std::mem::take(&mut harness.state_mut().actions);
    match sent.as_slice() {
        [Action::SetView(view)] => {
            assert_eq!(view.layout, pmvc::app::compare::Layout::Difference);
            assert_eq!(
                pmvc::app::compare::ViewSettings {
                    layout: before.layout,
                    ..*view
                },
                before,
                "only the layout changes"
            );
        }
        other => panic!("expected one SetView, got {other:?}"),
    }
    assert_eq!(
        harness.state().shown.view,
        before,
        "the panel only asks: what it shows is the editor's"
    );

    harness.get_by_label("MVC").click();
    harness.run();
    assert!(
        matches!(
            harness.state().actions.as_slice(),
            [Action::SetMethod(pmvc::coords::Method::Mvc)]
        ),
        "{:?}",
        harness.state().actions
    );
}

#[test]
fn the_edit_menu_offers_undo_by_the_models_label_and_sends_it() {
    let mut harness = panel_harness(pmvc::app::ui::menu::menu_bar, Shown::default());
    let rest = harness.state().model.document().pose().to_vec();
    let mut pose = rest.clone();
    pose[3] += DVec3::new(0.0, 0.5, 0.0);
    harness
        .state_mut()
        .model
        .apply(Command::edit_pose(pose.clone()));
    harness.run();
    harness.get_by_label("Edit").click();
    harness.run();
    harness.get_by_label("Undo pose edit (Ctrl+Z)").click();
    harness.run();
    assert!(
        matches!(harness.state().actions.as_slice(), [Action::Undo]),
        "{:?}",
        harness.state().actions
    );
    assert_eq!(
        harness.state().model.document().pose(),
        pose.as_slice(),
        "the menu changes nothing itself"
    );
}

#[test]
fn side_by_side_offers_no_more_families_than_the_viewport_draws() {
    use egui::accesskit::Role;
    use egui_kittest::kittest::NodeT;
    use pmvc::app::compare::{Layout, MethodSet};
    use pmvc::coords::Method;
    let mut shown = Shown::default();
    shown.view.layout = Layout::SideBySide;
    let four = [Method::Mvc, Method::Pmvc, Method::Harmonic, Method::Green];
    shown.view.compared = MethodSet::of(&four);
    let mut harness = panel_harness(pmvc::app::ui::toolbar::toolbar, shown);
    harness.get_by_label("Compare…").click();
    harness.run();
    let mlc = harness.get_by_role_and_label(Role::CheckBox, "MLC");
    assert!(
        mlc.accesskit_node().is_disabled(),
        "a fifth family is not offered"
    );
    let green = harness.get_by_role_and_label(Role::CheckBox, "Green");
    assert!(
        !green.accesskit_node().is_disabled(),
        "a shown one can be cleared"
    );
    harness.get_by_role_and_label(Role::CheckBox, "MLC").click();
    harness.run();
    assert!(
        harness.state().actions.is_empty(),
        "{:?}",
        harness.state().actions
    );
    // Nor a difference pane that would push a family out.
    let difference = harness.get_by_role_and_label(Role::CheckBox, "+ difference");
    assert!(difference.accesskit_node().is_disabled());
}
