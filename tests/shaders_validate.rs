//! Every shader, with its `#import`s resolved, parses and validates with naga; needs
//! no GPU. Every `shaders/*.wgsl` file must be among them.

use std::path::Path;

fn composed_shaders() -> Vec<(String, String)> {
    let mut shaders: Vec<(String, String)> = pmvc::gpu::kernels::kernel_sources()
        .into_iter()
        .map(|(name, source)| (name.to_owned(), source))
        .collect();
    shaders.push((
        "render_mesh.wgsl".into(),
        pmvc::render::mesh::shader_source(),
    ));
    shaders.push((
        "render_cage.wgsl".into(),
        pmvc::render::cage::shader_source(),
    ));
    shaders.push((
        "render_normals.wgsl".into(),
        pmvc::render::normals::shader_source(),
    ));
    shaders.push((
        "render_composite.wgsl".into(),
        include_str!("../shaders/render_composite.wgsl").into(),
    ));
    shaders
}

#[test]
fn every_shader_parses_and_validates() {
    let directory = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut on_disk: Vec<String> = std::fs::read_dir(&directory)
        .expect("shaders/ is readable")
        .map(|entry| entry.expect("directory entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "wgsl"))
        .map(|path| path.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    on_disk.sort();
    let shaders = composed_shaders();
    let mut checked: Vec<String> = shaders.iter().map(|(name, _)| name.clone()).collect();
    checked.sort();
    assert_eq!(
        checked, on_disk,
        "every shader file is composed and checked"
    );
    let mut failures = Vec::new();
    for (name, source) in &shaders {
        assert!(!source.contains("#import"), "{name}: an import was left");
        let module = match naga::front::wgsl::parse_str(source) {
            Ok(module) => module,
            Err(error) => {
                failures.push(error.emit_to_string_with_path(source, name));
                continue;
            }
        };
        // Default capabilities: what WebGPU guarantees, so the shaders run anywhere.
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        );
        if let Err(error) = validator.validate(&module) {
            failures.push(error.emit_to_string_with_path(source, name));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
