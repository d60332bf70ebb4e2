//! The compiled binding kernels kept on disk: a second `pmvc bind` finds them,
//! and a damaged, foreign or unwritable cache is a one-line notice, never a
//! failure. Runs `--backend gpu` (lavapipe on CI); without an adapter, or on one
//! that keeps no pipeline cache, it prints "not run".

use crate::common;
use common::*;
use std::path::{Path, PathBuf};
use std::process::Output;

fn bind(cache: &Path, mesh: &Path, cage: &Path, out: &Path) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_pmvc"))
        .env("PMVC_CACHE_DIR", cache)
        .args([
            "bind",
            "--mesh",
            path_str(mesh),
            "--cage",
            path_str(cage),
            "--method",
            "mvc",
            "--backend",
            "gpu",
            "--verbose",
            "--out",
            path_str(out),
        ])
        .output()
        .expect("run pmvc")
}

/// The one `.bin` file in `cache`.
fn cache_file(cache: &Path) -> PathBuf {
    let files: Vec<PathBuf> = std::fs::read_dir(cache)
        .expect("the cache folder")
        .map(|entry| entry.expect("an entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "bin"))
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    files.into_iter().next().expect("one file")
}

/// Exit 0, no panic, and the stderr lines that mention the pipeline cache.
fn succeeded(output: &Output) -> String {
    let text = stderr(output);
    assert_eq!(output.status.code(), Some(0), "stderr: {text}");
    assert!(!text.contains("panicked"), "{text}");
    text
}

fn notices(text: &str) -> Vec<&str> {
    text.lines()
        .filter(|line| line.starts_with("pmvc: GPU pipeline cache"))
        .collect()
}

struct Scene {
    _dir: tempfile::TempDir,
    cache: PathBuf,
    mesh: PathBuf,
    cage: PathBuf,
    out: PathBuf,
}

impl Scene {
    fn new() -> Self {
        let dir = tempfile::tempdir().expect("a temporary folder");
        let (mesh, cage, _, _) = comb_scene(dir.path(), 40);
        Self {
            cache: dir.path().join("cache"),
            out: dir.path().join("w.npy"),
            mesh,
            cage,
            _dir: dir,
        }
    }

    fn bind(&self) -> Output {
        bind(&self.cache, &self.mesh, &self.cage, &self.out)
    }

    /// The first bind, which writes the cache; `None` where the GPU part cannot run.
    fn first(&self) -> Option<String> {
        let output = self.bind();
        if !ran_on_gpu(&output) {
            return None;
        }
        let text = succeeded(&output);
        if text.contains("pipeline cache: not kept") {
            println!("not run: the adapter keeps no pipeline cache: {text}");
            return None;
        }
        assert!(text.contains("none yet"), "{text}");
        assert!(notices(&text).is_empty(), "{text}");
        Some(text)
    }
}

#[test]
fn a_second_bind_finds_the_kernels_in_the_cache() {
    let scene = Scene::new();
    if scene.first().is_none() {
        return;
    }
    let file = cache_file(&scene.cache);
    let written = std::fs::read(&file).expect("the cache file");
    let second = succeeded(&scene.bind());
    assert!(second.contains("hit ("), "{second}");
    assert!(notices(&second).is_empty(), "{second}");
    assert_eq!(
        std::fs::read(&file).expect("still there"),
        written,
        "a hit rewrites nothing"
    );

    let info = std::process::Command::new(env!("CARGO_BIN_EXE_pmvc"))
        .env("PMVC_CACHE_DIR", &scene.cache)
        .arg("info")
        .output()
        .expect("run pmvc info");
    let report = String::from_utf8_lossy(&info.stdout);
    assert!(
        report.contains("pipeline cache:") && report.contains("hit ("),
        "{report}"
    );
}

#[test]
fn a_damaged_or_foreign_cache_is_ignored_with_a_notice_and_rewritten() {
    let scene = Scene::new();
    if scene.first().is_none() {
        return;
    }
    let file = cache_file(&scene.cache);
    let good = std::fs::read(&file).expect("the cache file");
    let mut flipped = good.clone();
    *flipped.last_mut().expect("data") ^= 0x55;
    let foreign = pmvc::gpu::pipeline_cache::encode("another adapter; wgpu 29", &good[40..]);
    let cases: [(&str, Vec<u8>, &str); 4] = [
        ("corrupt", flipped, "checksum"),
        ("truncated", good[..good.len() / 2].to_vec(), "truncated"),
        ("foreign", foreign, "another adapter or wgpu version"),
        (
            "not ours",
            b"P3\n1 1\n255\n0 0 0\n".to_vec(),
            "not a pmvc pipeline cache",
        ),
    ];
    for (case, bytes, reason) in cases {
        std::fs::write(&file, &bytes).expect("damage the cache");
        let text = succeeded(&scene.bind());
        let lines = notices(&text);
        assert_eq!(lines.len(), 1, "{case}: {text}");
        assert!(
            lines[0].contains("ignored") && lines[0].contains(reason),
            "{case}: {text}"
        );
        let again = succeeded(&scene.bind());
        assert!(
            again.contains("hit ("),
            "{case}: rewritten, then found: {again}"
        );
    }
}

#[test]
fn an_unwritable_cache_folder_or_a_link_in_its_place_is_a_notice() {
    let scene = Scene::new();
    if scene.first().is_none() {
        return;
    }
    // A folder that cannot be made: its parent is a file.
    let blocker = scene.cache.with_file_name("a-file");
    std::fs::write(&blocker, b"not a folder").expect("a file");
    let output = bind(&blocker.join("cache"), &scene.mesh, &scene.cage, &scene.out);
    let text = succeeded(&output);
    let lines = notices(&text);
    assert_eq!(lines.len(), 1, "{text}");
    assert!(lines[0].contains("not written"), "{text}");

    // A symbolic link where the cache file goes is left alone, and so is its target.
    #[cfg(unix)]
    {
        let file = cache_file(&scene.cache);
        let victim = scene.cache.with_file_name("victim.txt");
        std::fs::write(&victim, b"keep me").expect("a file");
        std::fs::remove_file(&file).expect("removed");
        std::os::unix::fs::symlink(&victim, &file).expect("a link");
        let text = succeeded(&scene.bind());
        let lines = notices(&text);
        assert!(!lines.is_empty(), "{text}");
        assert!(
            lines.iter().all(|line| line.contains("not a regular file")),
            "{text}"
        );
        assert_eq!(std::fs::read(&victim).expect("the target"), b"keep me");
        assert!(std::fs::symlink_metadata(&file)
            .expect("the link")
            .is_symlink());
    }
}

#[test]
fn auto_says_where_it_binds_and_why() {
    let scene = Scene::new();
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_pmvc"))
        .env("PMVC_CACHE_DIR", &scene.cache)
        .args([
            "bind",
            "--mesh",
            path_str(&scene.mesh),
            "--cage",
            path_str(&scene.cage),
            "--verbose",
            "--out",
            path_str(&scene.out),
        ])
        .output()
        .expect("run pmvc");
    let text = succeeded(&output);
    let line = text
        .lines()
        .find(|line| line.starts_with("pmvc: binding on the "))
        .unwrap_or_else(|| panic!("no verbose line: {text}"));
    // 40 points: the CPU wins whatever the machine; with a GPU device the
    // line gives both predictions.
    assert!(line.starts_with("pmvc: binding on the CPU"), "{line}");
}
