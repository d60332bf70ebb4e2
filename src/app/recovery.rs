//! Autosave and recovery, as Blender has: while work is unsaved, the session
//! goes to a recovery file every [`AUTOSAVE_SECONDS`]; a clean exit, or a save
//! that leaves nothing unsaved, removes it. A file left behind by an editor that
//! is no longer running (it crashed, or was killed) is offered at the next start.
//!
//! Each running editor writes its own file, `autosave-PID-N.session.json`. A
//! file is left behind when its process is gone, or, within this process, when
//! the editor that wrote it is (tests end one editor and start another).

use super::document::Document;
use super::session::{save_session, SessionSettings};
use crate::formats::shown_path;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::SystemTime;

/// Seconds between autosaves while work is unsaved (Blender's default is two
/// minutes; a bind-and-pose session changes faster).
pub const AUTOSAVE_SECONDS: f64 = 60.0;

const PREFIX: &str = "autosave-";
const SUFFIX: &str = ".session.json";

/// Recovery files written by editors alive in this process.
static IN_USE: Mutex<BTreeSet<PathBuf>> = Mutex::new(BTreeSet::new());
static NEXT: AtomicU64 = AtomicU64::new(0);

/// What identifies the work autosaved: a change to any of it means a new write.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Stamp {
    pose_revision: u64,
    edits: u64,
    mesh: usize,
    cage: usize,
    named_poses: Vec<String>,
}

impl Stamp {
    fn of(document: &Document) -> Self {
        Self {
            pose_revision: document.pose_revision(),
            edits: document.edits(),
            mesh: std::sync::Arc::as_ptr(document.mesh()) as usize,
            cage: std::sync::Arc::as_ptr(document.cage()) as usize,
            named_poses: document
                .named_poses()
                .iter()
                .map(|n| n.name.clone())
                .collect(),
        }
    }
}

/// A recovery file left behind, offered at start-up.
#[derive(Clone, Debug, PartialEq)]
pub struct LeftBehind {
    pub path: PathBuf,
    pub written: SystemTime,
}

/// This editor's recovery file and when it was last written.
#[derive(Debug)]
pub struct Recovery {
    file: PathBuf,
    /// egui's clock at the last write, or when the work first became unsaved.
    last_write: Option<f64>,
    written: Option<Stamp>,
}

impl Recovery {
    /// Autosave into `dir` (created when first written).
    pub fn new(dir: &Path) -> Self {
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let file = dir.join(format!("{PREFIX}{}-{n}{SUFFIX}", std::process::id()));
        if let Ok(mut in_use) = IN_USE.lock() {
            in_use.insert(file.clone());
        }
        Self {
            file,
            last_write: None,
            written: None,
        }
    }

    pub fn file(&self) -> &Path {
        &self.file
    }

    /// Seconds until the next autosave is due at `now`, with work unsaved;
    /// `None` when the work on file is the work shown.
    pub fn due_in(&mut self, now: f64, document: &Document) -> Option<f64> {
        if self.written.as_ref() == Some(&Stamp::of(document)) {
            return None;
        }
        let since = *self.last_write.get_or_insert(now);
        Some((since + AUTOSAVE_SECONDS - now).max(0.0))
    }

    /// Write `document` to the recovery file now.
    pub fn write(
        &mut self,
        now: f64,
        document: &Document,
        settings: &SessionSettings,
    ) -> Result<(), String> {
        if let Some(dir) = self.file.parent() {
            std::fs::create_dir_all(dir)
                .map_err(|e| format!("autosave: cannot create {}: {e}", shown_path(dir)))?;
        }
        self.last_write = Some(now);
        save_session(&self.file, document, settings)
            .map_err(|error| format!("autosave failed: {error}"))?;
        self.written = Some(Stamp::of(document));
        Ok(())
    }

    /// Nothing is unsaved (saved, or quitting): the file goes, with the rest
    /// mesh a session writes beside it.
    pub fn remove(&mut self) {
        if self.written.is_none() && self.last_write.is_none() {
            return;
        }
        for path in [
            self.file.clone(),
            super::session::rest_mesh_path(&self.file),
        ] {
            let _ = std::fs::remove_file(path);
        }
        self.written = None;
        self.last_write = None;
    }
}

impl Drop for Recovery {
    /// The file stays: an editor that ends without removing it did not exit
    /// cleanly, and its work is offered at the next start.
    fn drop(&mut self) {
        if let Ok(mut in_use) = IN_USE.lock() {
            in_use.remove(&self.file);
        }
    }
}

/// The process id in a recovery file's name.
fn pid_of(name: &str) -> Option<u32> {
    let middle = name.strip_prefix(PREFIX)?.strip_suffix(SUFFIX)?;
    middle.split('-').next()?.parse().ok()
}

/// Whether process `pid` is running (Linux: it has a /proc entry; elsewhere only
/// this process is known to run).
fn running(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    if cfg!(target_os = "linux") {
        Path::new(&format!("/proc/{pid}")).exists()
    } else {
        false
    }
}

/// Recovery files in `dir` whose editor is gone, newest first.
pub fn left_behind(dir: &Path) -> Vec<LeftBehind> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let in_use = IN_USE.lock().map(|s| s.clone()).unwrap_or_default();
    let mut found: Vec<LeftBehind> = entries
        .flatten()
        .filter_map(|entry| {
            let path = entry.path();
            let pid = pid_of(&entry.file_name().to_string_lossy())?;
            let gone = !running(pid) || (pid == std::process::id() && !in_use.contains(&path));
            let written = entry.metadata().ok()?.modified().ok()?;
            gone.then_some(LeftBehind { path, written })
        })
        .collect();
    found.sort_by_key(|file| std::cmp::Reverse(file.written));
    found
}

/// Discard a recovery file the user does not want (and its rest mesh).
pub fn discard(path: &Path) {
    for path in [path.to_owned(), super::session::rest_mesh_path(path)] {
        let _ = std::fs::remove_file(path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_files_process_id_is_read_from_its_name_only() {
        assert_eq!(pid_of("autosave-1234-0.session.json"), Some(1234));
        assert_eq!(pid_of("autosave-x-0.session.json"), None);
        assert_eq!(pid_of("hydrant.session.json"), None);
        assert_eq!(pid_of("autosave-1234-0.session.json.tmp"), None);
    }

    #[test]
    fn a_file_of_a_live_editor_is_not_left_behind_and_is_once_it_is_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let recovery = Recovery::new(dir.path());
        std::fs::write(recovery.file(), "{}").unwrap();
        assert!(left_behind(dir.path()).is_empty());
        let file = recovery.file().to_owned();
        drop(recovery);
        let found = left_behind(dir.path());
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].path, file);
    }

    #[test]
    fn an_autosave_is_due_a_minute_after_work_changed_and_not_again_until_it_changes() {
        use crate::app::commands::Command;
        use crate::app::model::Model;
        use crate::app::scenes;
        let dir = tempfile::tempdir().unwrap();
        let mut recovery = Recovery::new(dir.path());
        let mut model = Model::new(Document::new(
            "comb",
            scenes::comb_mesh(),
            scenes::comb_cage(),
        ));
        let pose = scenes::comb_demo_pose(model.document().cage());
        model.apply(Command::edit_pose(pose));
        assert_eq!(
            recovery.due_in(10.0, model.document()),
            Some(AUTOSAVE_SECONDS)
        );
        assert_eq!(
            recovery.due_in(40.0, model.document()),
            Some(AUTOSAVE_SECONDS - 30.0)
        );
        assert_eq!(recovery.due_in(75.0, model.document()), Some(0.0));
        let settings = SessionSettings {
            bind_options: crate::coords::BindOptions::for_method(crate::coords::Method::Pmvc),
            view: Default::default(),
            cameras: Vec::new(),
        };
        recovery.write(75.0, model.document(), &settings).unwrap();
        assert!(recovery.file().exists());
        assert_eq!(recovery.due_in(500.0, model.document()), None, "unchanged");
        model.apply(Command::StoreNamedPose("up".into()));
        assert_eq!(recovery.due_in(100.0, model.document()), Some(35.0));
        recovery.remove();
        assert!(!recovery.file().exists());
    }
}
