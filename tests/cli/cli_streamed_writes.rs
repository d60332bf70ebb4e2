//! `pmvc bind` in blocks of rows writes each block while the next is bound: the
//! bytes are the whole bind's, a write that fails ends the bind with the whole
//! bind's message, and nothing partial is left behind.

use crate::common;
use common::*;
use std::path::Path;
use std::process::Output;

/// Files pmvc leaves in `dir` besides the inputs.
fn written(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name != "mesh.obj" && name != "cage.obj")
        .collect();
    names.sort();
    names
}

#[test]
fn blocks_of_any_size_write_the_whole_binds_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = comb_scene(dir.path(), 300);
    for method in ["mvc", "pmvc"] {
        let whole = dir.path().join(format!("{method}.npy"));
        let output = bind_on_cpu(&mesh, &cage, &whole, &["--method", method]);
        assert!(output.status.success(), "{}", stderr(&output));
        let expected = std::fs::read(&whole).unwrap();
        for rows in ["1", "2", "7", "150", "299"] {
            let out = dir.path().join(format!("{method}-{rows}.npy"));
            let output = bind_on_cpu(
                &mesh,
                &cage,
                &out,
                &["--method", method, "--block-rows", rows],
            );
            assert!(output.status.success(), "{}", stderr(&output));
            let bytes = std::fs::read(&out).unwrap();
            assert!(
                bytes == expected,
                "{method}, blocks of {rows}: the bytes differ"
            );
        }
    }
}

/// `pmvc bind` with `extra`, writing `out`, in a shell that lets files grow to
/// 16 KiB: the write past it fails (EFBIG) as a full disk would.
fn bind_with_small_files(mesh: &Path, cage: &Path, out: &Path, extra: &str) -> Output {
    let command = format!(
        "trap '' XFSZ; ulimit -f 32 && exec '{}' bind --backend cpu --method mvc --mesh '{}' --cage '{}' --out '{}' {extra}",
        env!("CARGO_BIN_EXE_pmvc"),
        mesh.display(),
        cage.display(),
        out.display()
    );
    std::process::Command::new("sh")
        .args(["-c", &command])
        .output()
        .expect("run sh")
}

#[test]
fn a_write_that_fails_between_blocks_fails_as_the_whole_bind_does() {
    let dir = tempfile::tempdir().unwrap();
    // 2,000 rows of weights, far past the 16 KiB allowed.
    let (mesh, cage, _, _) = comb_scene(dir.path(), 2000);
    let out = dir.path().join("w.npy");
    let whole = bind_with_small_files(&mesh, &cage, &out, "");
    assert_clean_failure(&whole, "w.npy", "cannot write");
    assert_eq!(written(dir.path()), Vec::<String>::new());
    let streamed = bind_with_small_files(&mesh, &cage, &out, "--block-rows 100");
    assert_clean_failure(&streamed, "w.npy", "cannot write");
    assert_eq!(stderr(&streamed), stderr(&whole));
    assert_eq!(written(dir.path()), Vec::<String>::new());
    // An earlier result stays as it was.
    std::fs::write(&out, "earlier weights").unwrap();
    let streamed = bind_with_small_files(&mesh, &cage, &out, "--block-rows 100");
    assert_clean_failure(&streamed, "w.npy", "cannot write");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "earlier weights");
    assert_eq!(written(dir.path()), vec!["w.npy".to_owned()]);
}

#[test]
fn a_full_device_fails_between_blocks_as_in_a_whole_bind() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = comb_scene(dir.path(), 300);
    let full = Path::new("/dev/full");
    let whole = bind_on_cpu(&mesh, &cage, full, &["--method", "mvc"]);
    assert_clean_failure(&whole, "/dev/full", "cannot write");
    let streamed = bind_on_cpu(
        &mesh,
        &cage,
        full,
        &["--method", "mvc", "--block-rows", "7"],
    );
    assert_clean_failure(&streamed, "/dev/full", "cannot write");
    assert_eq!(stderr(&streamed), stderr(&whole));
}

#[test]
fn a_signal_between_blocks_leaves_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    // Long enough on the CPU that the signal comes while blocks are bound.
    let (mesh, cage, _, _) = comb_scene(dir.path(), 100_000);
    let out = dir.path().join("w.npy");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_pmvc"))
        .args(["bind", "--method", "pmvc", "--backend", "cpu"])
        .args(["--block-rows", "2000", "--mesh"])
        .args([&mesh, Path::new("--cage"), &cage, Path::new("--out"), &out])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Wait until the first blocks are in the temporary file.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    loop {
        let grown = std::fs::read_dir(dir.path()).unwrap().any(|entry| {
            let entry = entry.unwrap();
            entry.file_name().to_string_lossy().ends_with(".tmp")
                && entry.metadata().unwrap().len() > 100_000
        });
        if grown {
            break;
        }
        assert!(std::time::Instant::now() < deadline, "no block written");
        assert!(child.try_wait().unwrap().is_none(), "the bind ended early");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let killed = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    assert_eq!(child.wait().unwrap().code(), Some(130));
    assert_eq!(written(dir.path()), Vec::<String>::new());
}
