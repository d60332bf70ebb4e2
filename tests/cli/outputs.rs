//! Outputs never destroy what they should not: an input, a link, a device, or a
//! folder; a signal leaves no temporary file; a bind that cannot fit is refused
//! before the work.

use crate::common;
use common::*;
use std::path::Path;
use std::process::Output;

fn bind(mesh: &Path, cage: &Path, out: &Path) -> Output {
    bind_on_cpu(mesh, cage, out, &[])
}

fn temporary_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".tmp"))
        .collect()
}

const NPY_MAGIC: &[u8] = b"\x93NUMPY";

#[test]
fn an_output_that_is_an_input_is_refused_and_the_input_kept() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = comb_scene(dir.path(), 20);
    let before = std::fs::read(&mesh).unwrap();
    let output = deform_with(&mesh, &cage, &cage, &mesh, &[]);
    assert_clean_failure(&output, path_str(&mesh), "never overwrites");
    assert_eq!(std::fs::read(&mesh).unwrap(), before);
    // Through a link to the cage, too.
    let link = dir.path().join("link.npy");
    std::os::unix::fs::symlink(&cage, &link).unwrap();
    let cage_before = std::fs::read(&cage).unwrap();
    assert_clean_failure(&bind(&mesh, &cage, &link), "link.npy", "never overwrites");
    assert_eq!(std::fs::read(&cage).unwrap(), cage_before);
}

#[test]
fn a_symbolic_link_is_written_through_and_stays_a_link() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = comb_scene(dir.path(), 20);
    let results = dir.path().join("results");
    std::fs::create_dir(&results).unwrap();
    let target = results.join("w.npy");
    std::fs::write(&target, "old").unwrap();
    let link = dir.path().join("latest.npy");
    std::os::unix::fs::symlink("results/w.npy", &link).unwrap();
    let output = bind(&mesh, &cage, &link);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(std::fs::read(&target).unwrap().starts_with(NPY_MAGIC));
    assert!(temporary_files(dir.path()).is_empty() && temporary_files(&results).is_empty());
}

#[test]
fn devices_are_written_in_place_and_folders_refused() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = comb_scene(dir.path(), 20);
    let output = bind(&mesh, &cage, Path::new("/dev/null"));
    assert!(output.status.success(), "{}", stderr(&output));
    // No extension warning for a device.
    assert!(!stderr(&output).contains("warning"), "{}", stderr(&output));
    // A full device fails cleanly, and stays a device whoever runs the test.
    let output = bind(&mesh, &cage, Path::new("/dev/full"));
    assert_clean_failure(&output, "/dev/full", "cannot write");
    let full = std::fs::metadata("/dev/full").unwrap();
    assert!(full.file_type().is_char_device());
    let folder = dir.path().join("folder");
    std::fs::create_dir(&folder).unwrap();
    assert_clean_failure(&bind(&mesh, &cage, &folder), "folder", "directory");
    assert!(folder.is_dir());
}

#[test]
fn a_misleading_extension_is_written_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = comb_scene(dir.path(), 20);
    let out = dir.path().join("weights.obj");
    let output = bind(&mesh, &cage, &out);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = stderr(&output);
    assert!(
        text.contains("weights.obj: warning:") && text.contains("does not end in .npy"),
        "{text}"
    );
    assert!(std::fs::read(&out).unwrap().starts_with(NPY_MAGIC));
}

#[test]
fn a_bind_that_cannot_fit_in_memory_is_refused_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    // 2,000,000 points × 10,242 cage vertices × 4 bytes = 76 GiB.
    let points = "v 0 0 0\n".repeat(2_000_000);
    let mesh = write(dir.path(), "mesh.obj", &points);
    let sphere = pmvc::geometry::procedural::icosphere(1.0, 5);
    let cage = write(dir.path(), "cage.obj", &cage_obj(&sphere));
    let out = dir.path().join("w.npy");
    // Harmonic coordinates hold every row (one solve for the whole cage).
    let output = bind_on_cpu(&mesh, &cage, &out, &["--method", "harmonic"]);
    assert_clean_failure(&output, "mesh.obj", "memory");
    let text = stderr(&output);
    assert!(
        text.contains("76.3 GiB") && text.contains("2000000 vertices × 10242 columns"),
        "{text}"
    );
    assert!(!out.exists() && temporary_files(dir.path()).is_empty());
}

#[test]
fn a_signal_during_a_bind_removes_its_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    // Long enough on the CPU that the signal comes during the bind.
    let (mesh, cage, _, _) = comb_scene(dir.path(), 200_000);
    for (signal, name) in [(15, "TERM"), (2, "INT"), (1, "HUP")] {
        let out = dir.path().join(format!("w-{name}.npy"));
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_pmvc"))
            .args(["bind", "--method", "pmvc", "--backend", "cpu", "--mesh"])
            .args([&mesh, Path::new("--cage"), &cage, Path::new("--out"), &out])
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // The output's temporary file exists from the start of the bind.
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
        while temporary_files(dir.path()).is_empty() {
            assert!(std::time::Instant::now() < deadline, "no temporary file");
            assert!(child.try_wait().unwrap().is_none(), "the bind ended early");
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        let killed = std::process::Command::new("kill")
            .args([format!("-{name}"), child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(128 + signal), "SIG{name}");
        assert_eq!(
            temporary_files(dir.path()),
            Vec::<String>::new(),
            "SIG{name}"
        );
        assert!(!out.exists());
    }
}

#[test]
fn a_bind_in_blocks_of_rows_writes_what_the_whole_bind_writes() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = comb_scene(dir.path(), 300);
    for method in ["pmvc", "mvc", "harmonic"] {
        let whole = dir.path().join(format!("{method}-whole.npy"));
        let blocks = dir.path().join(format!("{method}-blocks.npy"));
        let output = bind_on_cpu(&mesh, &cage, &whole, &["--method", method]);
        assert!(output.status.success(), "{}", stderr(&output));
        let args = [
            "--method",
            method,
            "--resolution",
            "32",
            "--block-rows",
            "7",
        ];
        let output = bind_on_cpu(&mesh, &cage, &blocks, &args);
        assert!(output.status.success(), "{}", stderr(&output));
        let (whole, blocks) = (
            std::fs::read(&whole).unwrap(),
            std::fs::read(&blocks).unwrap(),
        );
        assert_eq!(whole.len(), blocks.len(), "{method}");
        assert!(whole == blocks, "{method}: the weights differ");
    }
}

/// pmvc's temporary files (and kept earlier versions) left in `dir`.
fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.starts_with(".pmvc-"))
        .collect()
}

fn read_only(path: &Path) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o444)).unwrap();
}

#[test]
fn a_read_only_output_is_refused_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = comb_scene(dir.path(), 20);
    let weights = write(dir.path(), "w.npy", "old weights");
    read_only(&weights);
    assert_clean_failure(&bind(&mesh, &cage, &weights), "w.npy", "read-only");
    assert_eq!(std::fs::read_to_string(&weights).unwrap(), "old weights");
    // Through a link, the file it names decides.
    let link = dir.path().join("latest.npy");
    std::os::unix::fs::symlink("w.npy", &link).unwrap();
    assert_clean_failure(&bind(&mesh, &cage, &link), "latest.npy", "read-only");
    assert_eq!(std::fs::read_to_string(&weights).unwrap(), "old weights");

    let cage_out = write(dir.path(), "new-cage.obj", "old cage");
    read_only(&cage_out);
    let output = pmvc(&[
        "cage",
        "--mesh",
        path_str(&mesh),
        "--vertices",
        "8",
        "--out",
        path_str(&cage_out),
    ]);
    assert_clean_failure(&output, "new-cage.obj", "read-only");
    assert_eq!(std::fs::read_to_string(&cage_out).unwrap(), "old cage");

    let generated = write(dir.path(), "bar.obj", "old mesh");
    read_only(&generated);
    let bar_cage = dir.path().join("bar-cage.obj");
    let output = pmvc(&[
        "generate",
        "twisted-bar",
        "--mesh",
        path_str(&generated),
        "--cage",
        path_str(&bar_cage),
    ]);
    assert_clean_failure(&output, "bar.obj", "read-only");
    assert_eq!(std::fs::read_to_string(&generated).unwrap(), "old mesh");
    assert!(!bar_cage.exists());
    assert!(
        leftovers(dir.path()).is_empty(),
        "{:?}",
        leftovers(dir.path())
    );

    // A file its user may write is replaced as before.
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&weights, std::fs::Permissions::from_mode(0o644)).unwrap();
    let output = bind(&mesh, &cage, &weights);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(std::fs::read(&weights).unwrap().starts_with(NPY_MAGIC));
}

/// Run as root, a normal user (`nobody`) is tried: a file it may not write, in a
/// folder it may write, would be replaced by a rename.
#[test]
fn a_file_its_user_may_not_write_is_refused() {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    use std::os::unix::process::CommandExt;
    if std::fs::metadata("/proc/self").map(|m| m.uid()).ok() != Some(0) {
        // As a normal user, a read-only file of one's own is the same case
        // (a_read_only_output_is_refused_and_kept).
        eprintln!("not run: needs root to run pmvc as another user");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o777)).unwrap();
    let theirs = dir.path().join("theirs.obj");
    let cage = dir.path().join("cage.obj");
    let run_as_nobody = || {
        std::process::Command::new(env!("CARGO_BIN_EXE_pmvc"))
            .args(["generate", "twisted-bar", "--mesh"])
            .args([&theirs, Path::new("--cage"), &cage])
            .uid(65534)
            .gid(65534)
            .output()
    };
    // The binary and the folder must be within that user's reach.
    match run_as_nobody() {
        Ok(output) if output.status.success() => {}
        Ok(output) => {
            eprintln!(
                "not run: nobody cannot write a new file here: {}",
                stderr(&output)
            );
            return;
        }
        Err(error) => {
            eprintln!(
                "not run: nobody cannot run {}: {error}",
                env!("CARGO_BIN_EXE_pmvc")
            );
            return;
        }
    }
    // Now root's, with the usual mode 0644.
    std::fs::remove_file(&cage).unwrap();
    std::fs::remove_file(&theirs).unwrap();
    std::fs::write(&theirs, "root's mesh").unwrap();
    std::fs::set_permissions(&theirs, std::fs::Permissions::from_mode(0o644)).unwrap();
    let run_as_nobody = || run_as_nobody().unwrap();
    let output = run_as_nobody();
    assert_clean_failure(&output, "theirs.obj", "may not write");
    assert_eq!(std::fs::read_to_string(&theirs).unwrap(), "root's mesh");
    assert!(!cage.exists() && leftovers(dir.path()).is_empty());
    // Once it may write it, it is replaced.
    std::fs::set_permissions(&theirs, std::fs::Permissions::from_mode(0o666)).unwrap();
    let output = run_as_nobody();
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(std::fs::read_to_string(&theirs).unwrap().starts_with("# "));
}

fn generate(mesh: &Path, cage: &Path) -> Output {
    pmvc(&[
        "generate",
        "twisted-bar",
        "--mesh",
        path_str(mesh),
        "--cage",
        path_str(cage),
    ])
}

#[test]
fn two_outputs_naming_one_file_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    let same = dir.path().join("same.obj");
    // A new name, spelled the same and differently.
    assert_clean_failure(&generate(&same, &same), "same.obj", "same file");
    let other_spelling = sub.join("..").join(".").join("same.obj");
    assert_clean_failure(&generate(&same, &other_spelling), "same.obj", "same file");
    assert!(!same.exists() && leftovers(dir.path()).is_empty());
    // An existing file, through a symbolic link and a hard link.
    std::fs::write(&same, "old").unwrap();
    let link = dir.path().join("link.obj");
    std::os::unix::fs::symlink("same.obj", &link).unwrap();
    assert_clean_failure(&generate(&link, &same), "same.obj", "same file");
    let hard = dir.path().join("hard.obj");
    std::fs::hard_link(&same, &hard).unwrap();
    assert_clean_failure(&generate(&same, &hard), "hard.obj", "same file");
    assert_eq!(std::fs::read_to_string(&same).unwrap(), "old");
    // Two links to a device are no file to lose.
    let output = generate(Path::new("/dev/null"), Path::new("/dev/null"));
    assert!(output.status.success(), "{}", stderr(&output));
}

#[test]
fn a_generate_that_fails_on_the_cage_keeps_the_old_pair() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "bar.obj", "old mesh");
    // The disk holding the cage is full.
    let kept = || std::fs::read_to_string(&mesh).unwrap() == "old mesh";
    let output = generate(&mesh, Path::new("/dev/full"));
    assert_clean_failure(&output, "/dev/full", "cannot write");
    assert!(kept(), "the mesh was replaced, its cage was not");
    // The cage's folder does not exist.
    let output = generate(&mesh, &dir.path().join("missing/bar-cage.obj"));
    assert_clean_failure(&output, "bar-cage.obj", "cannot write");
    assert!(kept(), "the mesh was replaced, its cage was not");
    assert!(
        leftovers(dir.path()).is_empty(),
        "{:?}",
        leftovers(dir.path())
    );
    // Both written when both can be.
    let cage = write(dir.path(), "bar-cage.obj", "old cage");
    let output = generate(&mesh, &cage);
    assert!(output.status.success(), "{}", stderr(&output));
    for written in [&mesh, &cage] {
        let text = std::fs::read_to_string(written).unwrap();
        assert!(text.contains("\nv ") && text.contains("\nf "), "{text}");
    }
    assert!(
        leftovers(dir.path()).is_empty(),
        "{:?}",
        leftovers(dir.path())
    );
}

#[test]
fn a_named_pipe_with_no_reader_is_waited_for_with_a_word() {
    use std::io::{BufRead, Read};
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage, _, _) = comb_scene(dir.path(), 20);
    let fifo = dir.path().join("deformed.obj");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|status| status.success()) {
        eprintln!("not run: no mkfifo");
        return;
    }
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_pmvc"))
        .args([
            "deform",
            "--mesh",
            path_str(&mesh),
            "--cage",
            path_str(&cage),
        ])
        .args(["--deformed-cage", path_str(&cage), "--method", "mvc"])
        .args(["--out", path_str(&fifo)])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // The first line it writes says what it waits for; only then is there a reader.
    let mut errors = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    errors.read_line(&mut line).unwrap();
    assert!(
        line.contains("waiting for a program to read the named pipe")
            && line.contains("deformed.obj"),
        "{line}"
    );
    let mut written = String::new();
    std::fs::File::open(&fifo)
        .unwrap()
        .read_to_string(&mut written)
        .unwrap();
    assert_eq!(written.lines().filter(|l| l.starts_with("v ")).count(), 20);
    assert!(child.wait().unwrap().success());
}
