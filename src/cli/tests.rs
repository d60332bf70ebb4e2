//! The command line's own unit tests.

use super::*;
use crate::app::compare::{Layout, Overlay};
use crate::coords::Method;

#[test]
fn an_error_line_quotes_each_cause_once() {
    let io = std::io::Error::other("No space left on device");
    let error = anyhow::Error::from(crate::formats::WriteError {
        path: "w.npy".into(),
        source: io,
    })
    .context("--out");
    assert_eq!(
        error_line(&error),
        "--out: w.npy: cannot write: No space left on device"
    );
}

#[test]
fn parameter_flags_take_their_range_from_the_spec_and_their_help_says_it() {
    use crate::coords::Parameter;
    use clap::CommandFactory;
    let mut cli = Cli::command();
    cli.build();
    for (subcommand, parameter) in [
        ("bind", Parameter::Resolution),
        ("bind", Parameter::Grid),
        ("edit", Parameter::Resolution),
        ("edit", Parameter::Grid),
        ("check", Parameter::Grid),
        ("bind", Parameter::PoissonRatio),
        ("deform", Parameter::PoissonRatio),
        ("deform", Parameter::Bulging),
        ("deform", Parameter::LocalBlend),
        ("edit", Parameter::Bulging),
        ("edit", Parameter::LocalBlend),
    ] {
        let spec = parameter.spec();
        let flag = spec.flag.trim_start_matches('-').replace('-', "_");
        let help = cli
            .find_subcommand(subcommand)
            .and_then(|command| {
                command
                    .get_arguments()
                    .find(|a| a.get_id() == flag.as_str())
            })
            .and_then(|argument| argument.get_help())
            .map(|help| help.to_string())
            .unwrap_or_default();
        let shown = |value: u32| spec.text(value);
        let range = format!("({}–{})", shown(spec.min), shown(spec.max));
        assert!(help.contains(&range), "{subcommand} {}: {help}", spec.flag);
        let too_large = shown(spec.max + 1);
        let error = Cli::try_parse_from(["pmvc", subcommand, spec.flag, &too_large])
            .unwrap_err()
            .to_string();
        assert!(
            error.contains(&format!("{} to {}", shown(spec.min), shown(spec.max))),
            "{error}"
        );
    }
}

fn edit_options(args: &[&str]) -> crate::app::EditorOptions {
    let cli = Cli::try_parse_from(["pmvc", "edit"].iter().chain(args)).expect("parses");
    match cli.command {
        Some(Command::Edit(args)) => args.editor_options(),
        other => panic!("not an edit command: {other:?}"),
    }
}

#[test]
fn edit_applies_the_deformation_settings_given_and_keeps_the_others() {
    use crate::coords::Parameter;
    let options = edit_options(&["--local-blend", "0.5", "--bulging", "2"]);
    assert_eq!(
        options.deform,
        [(Parameter::Bulging, 200), (Parameter::LocalBlend, 50)]
    );
    assert!(edit_options(&[]).deform.is_empty());
}

#[test]
fn demo_opens_the_posed_comb_side_by_side_unless_a_view_is_given() {
    let options = edit_options(&["--demo"]);
    assert!(options.demo_pose);
    assert_eq!(options.view.layout, Layout::SideBySide);
    assert!(options.view.difference_pane);
    let options = edit_options(&["--demo", "--view", "difference"]);
    assert!(options.demo_pose);
    assert_eq!(options.view.layout, Layout::Difference);
    assert!(!edit_options(&[]).demo_pose);
    assert!(Cli::try_parse_from(["pmvc", "edit", "--demo", "m.obj", "c.obj"]).is_err());
}

#[test]
fn view_flags_set_the_editors_views() {
    let options = edit_options(&["--view", "side-by-side", "--heatmap", "7", "--log-scale"]);
    assert_eq!(options.view.layout, Layout::SideBySide);
    assert_eq!(options.view.overlay, Overlay::Heatmap);
    assert_eq!(options.view.heat_vertex, 7);
    assert_eq!(
        options.view.scale,
        crate::render::colormap::Scale::LogMagnitude
    );
    let options = edit_options(&["--compare", "mvc,pmvc,harmonic,green"]);
    assert_eq!(options.view.layout, Layout::SideBySide);
    assert_eq!(
        options.view.compared.iter().collect::<Vec<_>>(),
        [Method::Mvc, Method::Pmvc, Method::Harmonic, Method::Green]
    );
    let options = edit_options(&["--view", "mvc", "--negativity"]);
    assert_eq!(options.view.layout, Layout::Single);
    assert_eq!(options.method, Some(Method::Mvc));
    assert_eq!(options.view.overlay, Overlay::Negativity);
    use crate::render::colormap::Scale;
    assert_eq!(options.view.negativity_scale, Scale::LogMagnitude);
    let linear = edit_options(&["--negativity", "--linear-negativity"]);
    assert_eq!(linear.view.negativity_scale, Scale::Linear);
    assert_eq!(
        edit_options(&["--view", "difference"]).view.layout,
        Layout::Difference
    );
    let fixed = edit_options(&["--view", "difference", "--difference-limit", "0.5%"]);
    assert_eq!(fixed.view.difference_limit, Some(0.005));
    assert_eq!(edit_options(&[]).view.difference_limit, None);
    for bad in ["0", "-1", "101", "lots"] {
        let parsed = Cli::try_parse_from(["pmvc", "edit", "--difference-limit", bad]);
        assert!(parsed.is_err(), "--difference-limit {bad} was accepted");
    }
}

#[test]
fn a_mesh_opens_alone_or_with_its_cage_but_a_cage_needs_a_mesh() {
    let alone = edit_options(&["m.obj"]);
    assert_eq!(alone.mesh.as_deref(), Some(std::path::Path::new("m.obj")));
    assert_eq!(alone.cage, None);
    let pair = edit_options(&["m.obj", "c.obj"]);
    assert_eq!(pair.cage.as_deref(), Some(std::path::Path::new("c.obj")));
    assert!(Cli::try_parse_from(["pmvc", "edit", "--session", "s.json", "m.obj"]).is_err());
}

#[test]
fn heatmap_and_negativity_exclude_each_other() {
    let parsed = Cli::try_parse_from(["pmvc", "edit", "--heatmap", "1", "--negativity"]);
    assert!(parsed.is_err());
    let parsed = Cli::try_parse_from(["pmvc", "edit", "--view", "sideways"]);
    assert!(parsed.is_err());
}
