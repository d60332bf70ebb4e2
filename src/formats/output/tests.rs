//! The output rules, each as it is seen from the file system.

use super::*;

#[test]
fn links_are_followed_to_the_file_they_name() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("real.npy");
    std::fs::write(&file, "old").unwrap();
    let link = dir.path().join("link.npy");
    std::os::unix::fs::symlink("real.npy", &link).unwrap();
    assert_eq!(
        resolve_output(&link).unwrap(),
        OutputTarget::File(dir.path().join("real.npy"))
    );
    let dangling = dir.path().join("dangling.npy");
    std::os::unix::fs::symlink(dir.path().join("new.npy"), &dangling).unwrap();
    assert_eq!(
        resolve_output(&dangling).unwrap(),
        OutputTarget::File(dir.path().join("new.npy"))
    );
    let looped = dir.path().join("loop");
    std::os::unix::fs::symlink("loop", &looped).unwrap();
    let error = resolve_output(&looped).unwrap_err();
    assert!(error.to_string().contains("symbolic links"), "{error}");
}

#[test]
fn devices_are_streams_and_directories_are_refused() {
    assert_eq!(
        resolve_output(Path::new("/dev/null")).unwrap(),
        OutputTarget::Stream("/dev/null".into())
    );
    let dir = tempfile::tempdir().unwrap();
    let error = resolve_output(dir.path()).unwrap_err();
    assert!(error.to_string().contains("directory"), "{error}");
}

#[test]
fn a_pending_output_is_listed_until_it_is_finished_or_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("w.npy");
    let pending = PendingOutput::create(&out).unwrap();
    let temporaries = || {
        std::fs::read_dir(dir.path())
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .ends_with(".tmp")
            })
            .count()
    };
    assert_eq!(temporaries(), 1);
    assert!(pending.check_space(u64::MAX).is_err());
    pending.check_space(1).unwrap();
    pending.finish(|w| w.write_all(b"done")).unwrap();
    assert_eq!(
        (temporaries(), std::fs::read(&out).unwrap()),
        (0, b"done".to_vec())
    );
    assert_eq!(human_bytes(3 << 29), "1.5 GiB");
}

#[test]
fn extension_warning_names_what_is_expected() {
    let warning = extension_warning(Path::new("mesh.obj"), &["npy"], "weights").unwrap();
    assert!(warning.contains("mesh.obj") && warning.contains(".npy"));
    assert_eq!(
        extension_warning(Path::new("W.NPY"), &["npy"], "weights"),
        None
    );
    assert_eq!(
        extension_warning(Path::new("/dev/null"), &["npy"], "weights"),
        None
    );
}

/// Names of pmvc's temporary files and kept earlier versions in `dir`.
fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.starts_with(".pmvc-"))
        .collect()
}

#[test]
fn a_set_whose_second_rename_fails_puts_the_first_back() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage) = (dir.path().join("m.obj"), dir.path().join("c.obj"));
    std::fs::write(&mesh, "old mesh").unwrap();
    let outputs = OutputSet::create(&[&mesh, &cage]).unwrap();
    // The cage's name is taken by a folder holding a file while the outputs
    // are computed: renaming a file over it fails.
    std::fs::create_dir(&cage).unwrap();
    std::fs::write(cage.join("keep"), "").unwrap();
    let error = outputs
        .finish(|index, out| write!(out, "new {index}"))
        .unwrap_err();
    let message = error.to_string();
    assert!(
        message.starts_with(&format!("{}: cannot write", cage.display())),
        "{message}"
    );
    assert!(message.contains("m.obj was put back"), "{message}");
    assert_eq!(std::fs::read_to_string(&mesh).unwrap(), "old mesh");
    assert!(
        leftovers(dir.path()).is_empty(),
        "{:?}",
        leftovers(dir.path())
    );

    // A first output that did not exist is removed again.
    std::fs::remove_file(&mesh).unwrap();
    std::fs::remove_dir_all(&cage).unwrap();
    let outputs = OutputSet::create(&[&mesh, &cage]).unwrap();
    std::fs::create_dir(&cage).unwrap();
    std::fs::write(cage.join("keep"), "").unwrap();
    let error = outputs.finish(|_, out| out.write_all(b"new")).unwrap_err();
    assert!(error.to_string().contains("was removed again"), "{error}");
    assert!(!mesh.exists() && leftovers(dir.path()).is_empty());
}

#[test]
fn a_set_replaces_every_output_and_keeps_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, cage) = (dir.path().join("m.obj"), dir.path().join("c.obj"));
    std::fs::write(&mesh, "old mesh").unwrap();
    let outputs = OutputSet::create(&[&mesh, &cage]).unwrap();
    outputs
        .finish(|index, out| write!(out, "new {index}"))
        .unwrap();
    assert_eq!(std::fs::read_to_string(&mesh).unwrap(), "new 0");
    assert_eq!(std::fs::read_to_string(&cage).unwrap(), "new 1");
    assert!(
        leftovers(dir.path()).is_empty(),
        "{:?}",
        leftovers(dir.path())
    );
    // A failure while writing the second leaves both as they were.
    let outputs = OutputSet::create(&[&mesh, &cage]).unwrap();
    let failed = outputs.finish(|index, out| match index {
        0 => out.write_all(b"newer"),
        _ => Err(std::io::Error::other("disk full")),
    });
    assert!(failed.unwrap_err().to_string().contains("disk full"));
    assert_eq!(std::fs::read_to_string(&mesh).unwrap(), "new 0");
    assert_eq!(std::fs::read_to_string(&cage).unwrap(), "new 1");
    assert!(
        leftovers(dir.path()).is_empty(),
        "{:?}",
        leftovers(dir.path())
    );
}

#[test]
fn outputs_that_are_one_file_make_no_set() {
    let dir = tempfile::tempdir().unwrap();
    let name = dir.path().join("x.obj");
    let spelled = dir.path().join(".").join("x.obj");
    let error = OutputSet::create(&[&name, &spelled]).err().unwrap();
    assert!(error.to_string().contains("same file"), "{error}");
    let other = dir.path().join("y.obj");
    assert!(OutputSet::create(&[&name, &other]).is_ok());
    let null = Path::new("/dev/null");
    assert!(OutputSet::create(&[null, null]).is_ok());
}

#[test]
fn a_file_without_write_permission_is_refused_for_every_user() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("w.npy");
    std::fs::write(&file, "old").unwrap();
    std::fs::set_permissions(&file, std::fs::Permissions::from_mode(0o444)).unwrap();
    let error = write_atomically(&file, |out| out.write_all(b"new")).unwrap_err();
    assert_eq!(error.source.kind(), std::io::ErrorKind::PermissionDenied);
    assert!(
        error.to_string().contains("read-only (mode 0444)"),
        "{error}"
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "old");
    std::fs::set_permissions(&file, std::fs::Permissions::from_mode(0o644)).unwrap();
    write_atomically(&file, |out| out.write_all(b"new")).unwrap();
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "new");
}
