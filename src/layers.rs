//! The module rules of docs/architecture.md, checked by reading the sources:
//! each module names only the crate modules below it, and the GPU-free core
//! never names wgpu or egui. A `use` that breaks a rule fails here, before a
//! cycle can form.

use std::path::{Path, PathBuf};

/// Each module and the crate modules it may name. Anything not listed here
/// (`app`, `cli`, `python`) sits on top and may name all of these.
const ALLOWED: &[(&str, &[&str])] = &[
    ("budget", &[]),
    ("geometry", &["budget"]),
    ("coords", &["budget", "geometry"]),
    ("cagegen", &["budget", "geometry"]),
    ("formats", &["budget", "geometry", "coords"]),
    ("gpu", &["budget", "geometry", "coords", "formats"]),
    (
        "render",
        &["budget", "geometry", "coords", "formats", "gpu"],
    ),
];

/// Modules that must build without the GPU and UI stacks.
const GPU_FREE: &[&str] = &["budget", "geometry", "coords", "cagegen", "formats"];

const MODULES: &[&str] = &[
    "budget", "geometry", "coords", "cagegen", "formats", "gpu", "render", "app", "cli", "python",
];

fn sources_of(module: &str) -> Vec<PathBuf> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let file = src.join(format!("{module}.rs"));
    let mut found = Vec::new();
    if file.is_file() {
        found.push(file);
    }
    let mut folders = vec![src.join(module)];
    while let Some(folder) = folders.pop() {
        let Ok(entries) = std::fs::read_dir(&folder) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                folders.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                found.push(path);
            }
        }
    }
    found
}

/// The crate modules a source names as `crate::<module>`, with the line.
fn named_modules(text: &str) -> Vec<(usize, &'static str)> {
    let mut named = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        for module in MODULES {
            if code.contains(&format!("crate::{module}::"))
                || code.contains(&format!("crate::{module};"))
                || code.contains(&format!("crate::{module}}}"))
                || code.contains(&format!("crate::{{{module}"))
            {
                named.push((index + 1, *module));
            }
        }
    }
    named
}

#[test]
fn each_module_names_only_the_modules_below_it() {
    let mut broken = Vec::new();
    for (module, allowed) in ALLOWED {
        let sources = sources_of(module);
        assert!(!sources.is_empty(), "no sources found for {module}");
        for path in sources {
            let text = std::fs::read_to_string(&path).unwrap();
            for (line, named) in named_modules(&text) {
                if named != *module && !allowed.contains(&named) {
                    broken.push(format!("{}:{line}: names {named}", path.display()));
                }
            }
        }
    }
    assert!(
        broken.is_empty(),
        "imports against the layers:\n{}",
        broken.join("\n")
    );
}

#[test]
fn the_core_never_names_the_gpu_or_the_ui() {
    let mut broken = Vec::new();
    for module in GPU_FREE {
        for path in sources_of(module) {
            let text = std::fs::read_to_string(&path).unwrap();
            for (index, line) in text.lines().enumerate() {
                let code = line.split("//").next().unwrap_or("");
                if ["wgpu", "egui", "eframe", "winit"]
                    .iter()
                    .any(|name| code.contains(&format!("{name}::")))
                {
                    broken.push(format!("{}:{}", path.display(), index + 1));
                }
            }
        }
    }
    for path in sources_of("gpu") {
        let text = std::fs::read_to_string(&path).unwrap();
        if text.contains("egui::") {
            broken.push(format!("{}: gpu names egui", path.display()));
        }
    }
    assert!(
        broken.is_empty(),
        "GPU or UI names in the core:\n{}",
        broken.join("\n")
    );
}

#[test]
fn the_check_sees_a_broken_rule() {
    let text = "use crate::geometry::Cage;\n// crate::app::x\nlet a = crate::formats::load_mesh;";
    assert_eq!(named_modules(text), vec![(1, "geometry"), (3, "formats")]);
}
