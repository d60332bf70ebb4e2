//! Every `shaders/*.wgsl` parses and validates with naga; needs no GPU.

use std::path::Path;

#[test]
fn every_shader_parses_and_validates() {
    let directory = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut paths: Vec<_> = std::fs::read_dir(&directory)
        .expect("shaders/ is readable")
        .map(|entry| entry.expect("directory entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "wgsl"))
        .collect();
    paths.sort();
    assert!(
        !paths.is_empty(),
        "no shaders found in {}",
        directory.display()
    );
    let mut failures = Vec::new();
    for path in &paths {
        let source = std::fs::read_to_string(path).expect("shader is readable");
        let shown = path.display().to_string();
        let module = match naga::front::wgsl::parse_str(&source) {
            Ok(module) => module,
            Err(error) => {
                failures.push(error.emit_to_string_with_path(&source, &shown));
                continue;
            }
        };
        // Default capabilities: what WebGPU guarantees, so the shaders run anywhere.
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        );
        if let Err(error) = validator.validate(&module) {
            failures.push(error.emit_to_string_with_path(&source, &shown));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
