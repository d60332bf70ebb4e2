//! The difference view of PMVC at a cube-map resolution against exact PMVC:
//! what the cube map's quantisation moves, chosen from the "vs" list.

use crate::common;

use common::editor::*;
use egui_kittest::kittest::Queryable;
use pmvc::app::compare::Layout;
use pmvc::app::EditorOptions;
use pmvc::coords::{Method, Twin, WeightsId, EXACT_RESOLUTION};
use pmvc::render::Colouring;

#[test]
fn the_difference_view_shows_pmvc_against_exact_pmvc() {
    // The comb in its demonstration pose (the middle finger pulled up), PMVC
    // at 8², coarse enough for its quantisation to show.
    let Some(mut harness) = editor_with(EditorOptions {
        demo_pose: true,
        resolution: Some(8),
        ..Default::default()
    }) else {
        return;
    };
    {
        let view = harness.state_mut().view_mut();
        view.layout = Layout::Difference;
        view.difference = [Method::Mvc, Method::Pmvc];
    }
    run_until_bound(&mut harness);
    let families = harness.state().view().difference_pane_kind();
    let between_families = harness
        .state_mut()
        .value_range(Colouring::MethodDistance, families)
        .expect("a range")
        .max;

    // Chosen as a user would.
    harness.get_by_label("vs").click();
    harness.run_steps(2);
    harness.get_by_label("itself, exact").click();
    harness.run_steps(2);
    assert!(harness.state().view().difference_reference);
    run_until_bound(&mut harness);
    let exact = WeightsId::twin(Method::Pmvc, Twin::Reference);
    let document = harness.state().document();
    let twin = document.bound_id(exact).expect("exact PMVC is bound");
    assert_eq!(twin.options.resolution, EXACT_RESOLUTION);
    assert_eq!(
        document.bound(Method::Pmvc).unwrap().options.resolution,
        8,
        "the shown family keeps its resolution"
    );
    assert_eq!(exact.to_string(), "PMVC (exact)");

    let pane = harness.state().view().difference_pane_kind();
    let quantisation = harness
        .state_mut()
        .value_range(Colouring::MethodDistance, pane)
        .expect("a range")
        .max;
    // The cube map moves the posed comb, visibly but far less than choosing
    // MVC instead of PMVC does.
    let diagonal = harness.state().document().cage().diagonal() as f32;
    assert!(
        quantisation > 1e-5 && quantisation < 0.5 * between_families,
        "8² against exact: {quantisation}, MVC against PMVC: {between_families} (diagonal {diagonal})"
    );

    harness.run_steps(4);
    harness.snapshot_options("editor_exact_twin_difference", &snapshot_options());

    // With exact as the setting there is nothing left to compare it with:
    // the view goes back to comparing families.
    harness
        .state_mut()
        .queue_action(pmvc::app::actions::Action::SetParameter(
            pmvc::coords::Parameter::Resolution,
            EXACT_RESOLUTION,
        ));
    harness.run_steps(3);
    assert!(!harness.state().view().difference_reference);
    assert_eq!(
        harness.state().view().difference_pane_kind(),
        pmvc::app::compare::Pane::Difference {
            against: WeightsId::of(Method::Mvc),
            shown: Method::Pmvc
        }
    );
}
