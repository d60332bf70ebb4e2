//! Autosave when its folder cannot take the file: a folder made read-only, and a
//! file system that fills up during the write. The editor says so, keeps its work
//! (still unsaved), the last good recovery file stays whole, no half-written file
//! is left beside it, and the next autosave once the folder recovers succeeds.

use crate::common;

use common::editor::*;
use egui_kittest::Harness;
use pmvc::app::actions::Action;
use pmvc::app::{EditorApp, EditorOptions};
use std::path::{Path, PathBuf};
use std::process::Command;

fn editor_recovering_in(dir: &Path) -> Option<Harness<'static, EditorApp>> {
    let mut harness = editor_with(EditorOptions {
        recovery_dir: Some(dir.to_owned()),
        ..Default::default()
    })?;
    run_until_bound(&mut harness);
    Some(harness)
}

/// Every file in `dir` with its bytes, sorted by name.
fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|entry| {
            let name = entry.file_name().to_string_lossy().into_owned();
            (name, std::fs::read(entry.path()).unwrap())
        })
        .collect();
    files.sort();
    files
}

fn can_create_in(dir: &Path) -> bool {
    let probe = dir.join("probe");
    let created = std::fs::write(&probe, b"x").is_ok();
    let _ = std::fs::remove_file(&probe);
    created
}

/// A folder no file can be created in until dropped: its write permission taken
/// away or, for root (who ignores permissions), the immutable attribute set.
struct ReadOnlyFolder {
    dir: PathBuf,
    immutable: bool,
}

impl ReadOnlyFolder {
    fn make(dir: &Path) -> Result<Self, String> {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o555))
            .map_err(|e| format!("chmod: {e}"))?;
        let mut folder = ReadOnlyFolder {
            dir: dir.to_owned(),
            immutable: false,
        };
        if can_create_in(dir) {
            let status = Command::new("chattr").arg("+i").arg(dir).status();
            folder.immutable = matches!(status, Ok(s) if s.success());
        }
        if can_create_in(dir) {
            return Err("neither permissions nor chattr +i stop writes here".into());
        }
        Ok(folder)
    }
}

impl Drop for ReadOnlyFolder {
    fn drop(&mut self) {
        use std::os::unix::fs::PermissionsExt;
        if self.immutable {
            let _ = Command::new("chattr").arg("-i").arg(&self.dir).status();
        }
        let _ = std::fs::set_permissions(&self.dir, std::fs::Permissions::from_mode(0o755));
    }
}

/// Moves a cage handle, so that there is new unsaved work to autosave.
fn change_work(harness: &mut Harness<'static, EditorApp>, by: f64) {
    let position = harness.state().document().pose()[3] + glam::DVec3::new(0.0, by, 0.0);
    harness.state_mut().set_handle_position(3, position);
    harness.run_steps(2);
}

#[test]
fn autosave_into_a_folder_made_read_only_reports_and_keeps_the_last_recovery_file() {
    let dir = tempfile::tempdir().unwrap();
    let recovery_dir = dir.path().join("recovery");
    let Some(mut harness) = editor_recovering_in(&recovery_dir) else {
        return;
    };
    change_work(&mut harness, 0.5);
    harness.state_mut().autosave().expect("first autosave");
    let before = contents(&recovery_dir);
    assert!(!before.is_empty());

    change_work(&mut harness, 0.25);
    let pose_now = harness.state().document().pose().to_vec();
    let read_only = match ReadOnlyFolder::make(&recovery_dir) {
        Ok(folder) => folder,
        Err(why) => {
            println!("not run: cannot make a folder read-only here ({why})");
            return;
        }
    };
    let error = harness
        .state_mut()
        .autosave()
        .expect_err("a read-only folder takes no file");
    assert!(error.contains("autosave failed"), "{error}");
    drop(read_only);

    assert_eq!(
        contents(&recovery_dir),
        before,
        "the last recovery file stays whole"
    );
    assert_eq!(
        harness.state().document().pose(),
        pose_now,
        "the work is kept"
    );
    assert!(harness.state().unsaved().any(), "and is still unsaved");
    harness.state_mut().autosave().expect("writable again");
    assert_ne!(contents(&recovery_dir), before);
}

/// A 256 KiB tmpfs mounted on `dir`, unmounted when dropped.
struct SmallFileSystem(PathBuf);

impl SmallFileSystem {
    fn mount(dir: &Path) -> Result<Self, String> {
        std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
        let output = Command::new("mount")
            .args(["-t", "tmpfs", "-o", "size=256k", "tmpfs"])
            .arg(dir)
            .output()
            .map_err(|e| format!("mount: {e}"))?;
        if !output.status.success() {
            return Err(String::from_utf8_lossy(&output.stderr).trim().to_owned());
        }
        Ok(SmallFileSystem(dir.to_owned()))
    }

    /// Fills the file system but for `spare` bytes, with `filler`.
    fn fill_leaving(&self, filler: &Path, spare: u64) {
        use std::io::Write;
        let mut file = std::fs::File::create(filler).unwrap();
        let block = [0u8; 4096];
        while file.write_all(&block).is_ok() {}
        let written = std::fs::metadata(filler).unwrap().len();
        file.set_len(written.saturating_sub(spare)).unwrap();
    }
}

impl Drop for SmallFileSystem {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

#[test]
fn autosave_on_a_disk_that_fills_during_the_write_reports_and_leaves_no_partial_file() {
    let dir = tempfile::tempdir().unwrap();
    let recovery_dir = dir.path().join("recovery");
    let small = match SmallFileSystem::mount(&recovery_dir) {
        Ok(small) => small,
        Err(why) => {
            println!("not run: cannot mount a small tmpfs here ({why})");
            return;
        }
    };
    let Some(mut harness) = editor_recovering_in(&recovery_dir) else {
        return;
    };
    // Named poses until the session is a few pages long, so that the write
    // below starts and then runs out of space.
    let mut before = Vec::new();
    for pose in 0..64 {
        change_work(&mut harness, 0.01);
        harness
            .state_mut()
            .queue_action(Action::StoreNamedPose(format!("pose {pose}")));
        harness.run_steps(2);
        harness.state_mut().autosave().expect("autosave");
        before = contents(&recovery_dir);
        if before.iter().map(|(_, bytes)| bytes.len()).sum::<usize>() > 16384 {
            break;
        }
    }
    let written: usize = before.iter().map(|(_, bytes)| bytes.len()).sum();
    assert!(
        written > 16384,
        "the session is larger than what is left free"
    );

    // One page left: the next write starts, then runs out of space.
    let filler = recovery_dir.join("filler");
    small.fill_leaving(&filler, 4096);
    change_work(&mut harness, 0.25);
    let error = harness
        .state_mut()
        .autosave()
        .expect_err("the disk is full");
    assert!(error.contains("autosave failed"), "{error}");
    assert!(
        error.to_lowercase().contains("space"),
        "says the disk is full: {error}"
    );
    std::fs::remove_file(&filler).unwrap();
    assert_eq!(
        contents(&recovery_dir),
        before,
        "the last recovery file stays whole and nothing half-written is left"
    );
    assert!(harness.state().unsaved().any(), "the work is still unsaved");

    harness.state_mut().autosave().expect("room again");
    assert_ne!(contents(&recovery_dir), before);
    drop(harness);
    drop(small);
}
