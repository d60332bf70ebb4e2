//! Families whose parameters are of one kind (harmonic coordinates' and BBW's
//! grids) keep a value each: BBW does not bind at harmonic coordinates' grid
//! of 64, and changing one family's grid leaves the other's weights alone.

use common::editor::*;
use egui_kittest::Harness;
use pmvc::app::actions::Action;
use pmvc::app::{EditorApp, EditorOptions};
use pmvc::coords::{Method, Parameter};

use crate::common;

#[test]
fn harmonic_coordinates_and_bbw_keep_a_grid_each() {
    let Some(mut harness) = editor_with(EditorOptions {
        method: Some(Method::Harmonic),
        ..Default::default()
    }) else {
        return;
    };
    let grid =
        |harness: &Harness<'static, EditorApp>, method| harness.state().options_for(method).grid;
    assert_eq!(grid(&harness, Method::Harmonic), 64);
    assert_eq!(grid(&harness, Method::Bbw), 32, "BBW's own default");

    harness.state_mut().set_parameter(Parameter::Grid, 24);
    assert_eq!(grid(&harness, Method::Harmonic), 24);
    assert_eq!(grid(&harness, Method::Bbw), 32, "BBW's grid is its own");

    harness.state_mut().set_active_method(Method::Bbw);
    assert_eq!(
        harness.state().bind_options().grid,
        32,
        "the control shows BBW's"
    );
    harness.state_mut().set_parameter(Parameter::Grid, 16);
    harness.state_mut().set_active_method(Method::Harmonic);
    assert_eq!(harness.state().bind_options().grid, 24);
    assert_eq!(grid(&harness, Method::Bbw), 16);

    // The side panel's BBW grid, chosen while harmonic coordinates are shown.
    harness
        .state_mut()
        .queue_action(Action::SetFamilyParameter(Method::Bbw, 48));
    harness.run_steps(2);
    assert_eq!(grid(&harness, Method::Bbw), 48);
    assert_eq!(grid(&harness, Method::Harmonic), 24);
    assert_eq!(harness.state().bind_options().grid, 24);
}

/// `pmvc edit --grid N` is for every family with a grid.
#[test]
fn a_grid_given_on_the_command_line_is_every_grid_familys() {
    let Some(harness) = editor_with(EditorOptions {
        grid: Some(20),
        ..Default::default()
    }) else {
        return;
    };
    for method in [Method::Harmonic, Method::Bbw] {
        assert_eq!(harness.state().options_for(method).grid, 20, "{method:?}");
    }
}
