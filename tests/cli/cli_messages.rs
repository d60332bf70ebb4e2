//! The command line's messages: `bench` refuses what it cannot do before the
//! work, and a file name that would break a line is shown quoted, so that every
//! message stays on one line.

use crate::common;
use common::*;
use std::path::{Path, PathBuf};
use std::process::Output;

/// A folder of shared-data pairs holding one small model, `tiny`.
fn tiny_data(dir: &Path) -> PathBuf {
    let data = dir.join("data");
    std::fs::create_dir(&data).unwrap();
    let (mesh, cage, _, _) = comb_scene(dir, 20);
    std::fs::rename(mesh, data.join("tiny.obj")).unwrap();
    std::fs::rename(cage, data.join("tiny_Cage.obj")).unwrap();
    data
}

/// `pmvc bench` on `data`, one run per row unless `extra` says otherwise.
fn bench(data: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["bench", "--data", path_str(data)];
    if !extra.contains(&"--runs") {
        args.extend(["--runs", "1"]);
    }
    args.extend(extra);
    pmvc(&args)
}

#[test]
fn bench_refuses_unknown_scenes_and_lists_the_known_ones() {
    let dir = tempfile::tempdir().unwrap();
    let data = tiny_data(dir.path());
    let output = bench(&data, &["--scenes", "tiny,bogus"]);
    assert_clean_failure(&output, "bogus", "unknown scene");
    let text = stderr(&output);
    for known in [
        "armadillo-size",
        "horse-size",
        "hand-size",
        "table2",
        "tiny",
    ] {
        assert!(text.contains(known), "{known} is not listed: {text}");
    }
    assert!(output.stdout.is_empty(), "a table was printed");
    // With --no-data the shared models are not scenes.
    let output = bench(&data, &["--no-data", "--scenes", "tiny"]);
    assert_clean_failure(&output, "tiny", "unknown scene");
    // No runs would time nothing.
    let output = bench(&data, &["--scenes", "tiny", "--runs", "0"]);
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    assert!(
        stderr(&output).contains("'--runs <RUNS>'"),
        "{}",
        stderr(&output)
    );
    assert!(output.stdout.is_empty(), "a table was printed");
    // A known name runs.
    let output = bench(&data, &["--scenes", "tiny"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let table = String::from_utf8_lossy(&output.stdout);
    assert!(table.contains("| tiny | 20 |"), "{table}");
}

#[test]
fn bench_checks_its_json_output_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let data = tiny_data(dir.path());
    for (json, what) in [
        (dir.path().join("nodir/b.json"), "does not exist"),
        (data.clone(), "directory"),
    ] {
        let output = bench(&data, &["--scenes", "tiny", "--json", path_str(&json)]);
        assert_clean_failure(&output, path_str(&json), what);
        assert!(output.stdout.is_empty(), "the benchmark ran first");
        assert!(!stderr(&output).contains("tiny |"), "{}", stderr(&output));
    }
    let json = dir.path().join("b.json");
    let output = bench(&data, &["--scenes", "tiny", "--json", path_str(&json)]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = std::fs::read_to_string(&json).unwrap();
    assert!(text.contains("\"scene\": \"tiny\""), "{text}");
}

/// Every line on stderr is one of pmvc's messages, and `name` is shown escaped.
fn assert_one_line_per_message(output: &Output, name: &str) {
    let text = stderr(output);
    assert!(!text.is_empty(), "no message");
    for line in text.lines() {
        assert!(line.starts_with("pmvc"), "a message was split: {text:?}");
    }
    let escaped = format!("{name:?}");
    let escaped = &escaped[1..escaped.len() - 1];
    assert!(text.contains(escaped), "{escaped} not in {text:?}");
}

#[test]
fn a_file_name_with_a_newline_keeps_each_message_on_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = comb_scene(dir.path(), 20);
    let odd = "odd\nname.obj";
    // An input that is missing, one that does not parse, and one whose points
    // lie outside the cage (a warning, then success).
    let missing = dir.path().join(odd);
    let args = ["bind", "--cage", path_str(&cage), "--out", "/dev/null"];
    let with_mesh = |mesh: &Path| {
        let mut all = args.to_vec();
        all.extend(["--backend", "cpu", "--mesh", path_str(mesh)]);
        pmvc(&all)
    };
    let output = with_mesh(&missing);
    assert_eq!(output.status.code(), Some(1));
    assert_one_line_per_message(&output, odd);
    let broken = write(dir.path(), odd, "v 1 2\n");
    let output = with_mesh(&broken);
    assert_eq!(output.status.code(), Some(1));
    assert_one_line_per_message(&output, odd);
    std::fs::write(&broken, "v 0.5 0.5 0\nv 40 40 40\n").unwrap();
    let output = with_mesh(&broken);
    assert!(output.status.success(), "{}", stderr(&output));
    assert_one_line_per_message(&output, odd);

    // Outputs: a folder that is missing, an output that is an input.
    let folder = "new\nfolder";
    let out = dir.path().join(folder).join("w.npy");
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&mesh),
        "--cage",
        path_str(&cage),
        "--out",
        path_str(&out),
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert_one_line_per_message(&output, folder);
    let output = pmvc(&[
        "bind",
        "--mesh",
        path_str(&broken),
        "--cage",
        path_str(&cage),
        "--out",
        path_str(&broken),
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert_one_line_per_message(&output, odd);
    let output = pmvc(&[
        "generate",
        "twisted-bar",
        "--mesh",
        "/dev/null",
        "--cage",
        path_str(&out),
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert_one_line_per_message(&output, folder);

    // bench's data folder.
    let data = dir.path().join("no\ndata");
    let output = bench(&data, &["--scenes", "bogus"]);
    assert_eq!(output.status.code(), Some(1));
    assert_one_line_per_message(&output, "no\ndata");
}

#[test]
fn bench_times_only_the_families_asked_for_and_refuses_unknown_pmvc_kernels() {
    let dir = tempfile::tempdir().unwrap();
    let data = tiny_data(dir.path());
    let output = bench(&data, &["--scenes", "tiny", "--methods", "mvc"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let table = String::from_utf8_lossy(&output.stdout);
    assert!(table.contains("| tiny | 20 |"), "{table}");
    assert!(
        table.contains("| MVC |") && !table.contains("PMVC") && !table.contains("HC"),
        "{table}"
    );
    // Refused by the argument parser, as an unknown family is, before any work.
    let output = bench(&data, &["--scenes", "tiny", "--pmvc-kernels", "tiles,warp"]);
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    assert!(
        stderr(&output).contains("unknown PMVC kernel 'warp' (expected auto, tiles or bands)"),
        "{}",
        stderr(&output)
    );
    assert!(output.stdout.is_empty(), "a table was printed");
}

#[test]
fn the_tile_kernel_asked_for_on_a_quad_cage_is_refused_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, _, _, _) = comb_scene(dir.path(), 20);
    // A box of six quads around the comb's points.
    let cage = dir.path().join("box.obj");
    std::fs::write(
        &cage,
        "v -9 -9 -9\nv 9 -9 -9\nv 9 9 -9\nv -9 9 -9\nv -9 -9 9\nv 9 -9 9\nv 9 9 9\nv -9 9 9\n\
         f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
    )
    .unwrap();
    let out = dir.path().join("w.npy");
    let output = bind_with(
        &mesh,
        &cage,
        &out,
        &["--backend", "gpu", "--pmvc-kernel", "tiles"],
    );
    if !ran_on_gpu_or_refused(&output) {
        return;
    }
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    let text = stderr(&output);
    assert!(
        text.contains("tile kernel") && text.contains("bilinear patches"),
        "{text}"
    );
    assert!(!out.exists(), "weights written after a refusal");
    // An unknown kernel is refused before any work.
    let output = bind_with(&mesh, &cage, &out, &["--pmvc-kernel", "fast"]);
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    assert!(
        stderr(&output).contains("unknown PMVC kernel 'fast'"),
        "{}",
        stderr(&output)
    );
}

/// False (after saying so) when `--backend gpu` found no adapter, as
/// `ran_on_gpu` does, but a refusal of the input counts as having run.
fn ran_on_gpu_or_refused(output: &Output) -> bool {
    if stderr(output).contains("no GPU adapter") {
        return ran_on_gpu(output);
    }
    true
}
