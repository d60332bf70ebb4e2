//! `pmvc edit --screenshot … --offscreen`: the real binary, with no display, draws
//! the editor's frames on the GPU adapter, saves the picture, runs a scripted drag,
//! and exits with status 1 when anything the command asked for failed. Without an
//! adapter these print "not run" and pass, unless `PMVC_REQUIRE_GPU=1`.

use crate::common;

use common::{path_str, stderr};
use std::process::{Command, Output};

/// `pmvc edit ARGS --offscreen` with no display in its environment, or `None`
/// when there is no adapter to draw on.
fn offscreen(args: &[&str]) -> Option<Output> {
    let output = Command::new(env!("CARGO_BIN_EXE_pmvc"))
        .arg("edit")
        .args(args)
        .arg("--offscreen")
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("run pmvc");
    let text = stderr(&output);
    if text.contains("no GPU adapter to draw on") {
        assert_ne!(
            std::env::var("PMVC_REQUIRE_GPU").as_deref(),
            Ok("1"),
            "PMVC_REQUIRE_GPU=1 but no wgpu adapter: {text}"
        );
        eprintln!("not run: {text}");
        return None;
    }
    Some(output)
}

#[test]
fn a_scripted_drag_without_a_display_saves_the_window_with_the_model_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("window.png");
    let Some(output) = offscreen(&["--screenshot", path_str(&png), "--drag", "0"]) else {
        return;
    };
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(0), "{text}");
    let moved: f64 = text
        .split("dragged cage vertex 0 by ")
        .nth(1)
        .and_then(|rest| rest.split(" %").next())
        .and_then(|number| number.parse().ok())
        .unwrap_or_else(|| panic!("no drag report: {text}"));
    assert!(moved > 1.0, "the handle moved {moved} % of the diagonal");

    let image = image::open(&png).unwrap().to_rgba8();
    assert_eq!(image.dimensions(), (1280, 800));
    // The viewport is drawn by paint callbacks, apart from egui's shapes: the
    // comb in the middle of the view differs from the view's background there.
    let background = *image.get_pixel(20, 780);
    let differs = |pixel: &image::Rgba<u8>| {
        pixel
            .0
            .iter()
            .zip(background.0)
            .any(|(a, b)| a.abs_diff(b) > 40)
    };
    let model_pixels = (200..800)
        .flat_map(|x| (200..700).map(move |y| (x, y)))
        .filter(|&(x, y)| differs(image.get_pixel(x, y)))
        .count();
    assert!(
        model_pixels > 20_000,
        "only {model_pixels} pixels of the view differ from its background"
    );
}

#[test]
fn every_failure_of_a_run_without_a_display_is_reported_with_status_1() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("window.png");
    let missing = dir.path().join("no-such-pose.obj");
    let Some(output) = offscreen(&[
        "--screenshot",
        path_str(&png),
        "--pose",
        path_str(&missing),
        "--drag",
        "9999",
    ]) else {
        return;
    };
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(!text.contains("panicked"), "{text}");
    let error = text
        .lines()
        .find(|line| line.starts_with("pmvc: error:"))
        .unwrap_or_else(|| panic!("no error line: {text}"));
    assert!(error.contains("2 error(s)"), "{error}");
    assert!(error.contains("no-such-pose.obj"), "{error}");
    assert!(error.contains("--drag 9999"), "{error}");
}

#[test]
fn offscreen_without_a_screenshot_is_refused() {
    let output = Command::new(env!("CARGO_BIN_EXE_pmvc"))
        .args(["edit", "--offscreen"])
        .output()
        .expect("run pmvc");
    assert_eq!(output.status.code(), Some(1));
    assert!(
        stderr(&output).contains("--screenshot"),
        "{}",
        stderr(&output)
    );
}

#[test]
fn a_screenshot_never_replaces_an_input() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, cage_shape, _) = common::comb_scene(dir.path(), 50);
    let session = dir.path().join("s.json");
    let mut text = common::comb_session();
    text["mesh"] = serde_json::json!({"file": "mesh.obj"});
    text["cage"] = serde_json::json!({"file": "cage.obj"});
    let rest: Vec<[f64; 3]> = cage_shape
        .positions()
        .iter()
        .map(|p| p.to_array())
        .collect();
    text["pose"] = serde_json::json!(rest);
    text["named_poses"] = serde_json::json!([]);
    std::fs::write(&session, serde_json::to_string(&text).unwrap()).unwrap();
    let before: Vec<Vec<u8>> = [&mesh, &cage, &session]
        .map(|path| std::fs::read(path).unwrap())
        .into();
    let unchanged = || {
        for (path, bytes) in [&mesh, &cage, &session].into_iter().zip(&before) {
            assert_eq!(
                &std::fs::read(path).unwrap(),
                bytes,
                "{} changed",
                path.display()
            );
        }
    };
    // Refused before any window opens: what the command line names.
    for (args, out) in [
        (vec!["edit", path_str(&mesh), path_str(&cage)], &cage),
        (vec!["edit", path_str(&mesh), path_str(&cage)], &mesh),
        (vec!["edit", "--session", path_str(&session)], &session),
    ] {
        let mut args = args.clone();
        args.extend(["--screenshot", path_str(out), "--offscreen"]);
        let output = common::pmvc(&args);
        let text = stderr(&output);
        assert_eq!(output.status.code(), Some(1), "{args:?}: {text}");
        assert!(text.contains("never overwrites"), "{text}");
        unchanged();
    }
    // The mesh a session names is the scene's input too: refused before the
    // window opens, even when the session would not open.
    let broken = dir.path().join("broken.json");
    let mut text_broken = text.clone();
    text_broken["pose"] = serde_json::json!([]);
    std::fs::write(&broken, serde_json::to_string(&text_broken).unwrap()).unwrap();
    let output = common::pmvc(&[
        "edit",
        "--session",
        path_str(&broken),
        "--screenshot",
        path_str(&mesh),
        "--offscreen",
    ]);
    let said = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{said}");
    assert!(said.contains("never overwrites"), "{said}");
    unchanged();
    // And checked again when the picture is written, against the scene's files.
    let Some(output) = offscreen(&[
        "--session",
        path_str(&session),
        "--screenshot",
        path_str(&mesh),
    ]) else {
        return;
    };
    let text = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{text}");
    assert!(text.contains("never overwrites"), "{text}");
    unchanged();
}
