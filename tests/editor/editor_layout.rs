//! The editor's state has owners: the shell (`src/app/editor/`) is the only
//! place that holds `EditorApp`'s parts, panels and panes never see it, and the
//! shell itself stays small. Read from the sources, so a regression fails here
//! rather than in review.

use std::path::{Path, PathBuf};

fn sources(folder: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(folder).expect("the source folder") {
        let path = entry.expect("a folder entry").path();
        if path.is_dir() {
            found.extend(sources(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            found.push(path);
        }
    }
    found.sort();
    found
}

fn app_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src/app")
}

fn text(path: &Path) -> String {
    std::fs::read_to_string(path).expect("a source file")
}

/// Where `impl EditorApp` (or `impl eframe::App for EditorApp`) appears.
fn files_implementing_the_editor() -> Vec<PathBuf> {
    sources(&app_folder())
        .into_iter()
        .filter(|path| {
            let source = text(path);
            source.contains("impl EditorApp") || source.contains("for EditorApp")
        })
        .collect()
}

#[test]
fn only_the_shell_implements_the_editor() {
    let shell = app_folder().join("editor");
    let files = files_implementing_the_editor();
    let outside: Vec<_> = files.iter().filter(|p| !p.starts_with(&shell)).collect();
    assert!(
        outside.is_empty(),
        "impl EditorApp outside src/app/editor: {outside:?}"
    );
    assert!(
        (1..=6).contains(&files.len()),
        "a handful of shell files implement the editor, not {}: {files:?}",
        files.len()
    );
}

#[test]
fn panels_and_panes_never_name_the_editor() {
    let app = app_folder();
    let mut offenders = Vec::new();
    for folder in ["ui", "viewport"] {
        for path in sources(&app.join(folder)) {
            if text(&path).contains("EditorApp") {
                offenders.push(path);
            }
        }
    }
    for file in ["views.rs", "ctx.rs", "actions.rs", "files.rs", "binding.rs"] {
        let path = app.join(file);
        if text(&path).contains("EditorApp") {
            offenders.push(path);
        }
    }
    assert!(
        offenders.is_empty(),
        "these see the whole editor: {offenders:?}"
    );
}

#[test]
fn the_editor_has_a_few_private_fields() {
    let source = text(&app_folder().join("editor/mod.rs"));
    let start = source
        .find("pub struct EditorApp {")
        .expect("EditorApp is defined in the shell");
    let body = &source[start..];
    let body = &body[..body.find("\n}").expect("the struct's end")];
    let fields: Vec<&str> = body
        .lines()
        .skip(1)
        .map(str::trim)
        .filter(|line| !line.starts_with("//") && line.contains(':'))
        .collect();
    assert!(
        (1..=10).contains(&fields.len()),
        "at most about 10 fields: {fields:?}"
    );
    let public: Vec<_> = fields.iter().filter(|f| f.starts_with("pub")).collect();
    assert!(
        public.is_empty(),
        "fields reachable from outside the shell: {public:?}"
    );
}
