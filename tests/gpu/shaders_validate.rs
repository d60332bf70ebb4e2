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
        include_str!("../../shaders/render_composite.wgsl").into(),
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
    let failures: Vec<String> = shaders
        .iter()
        .filter_map(|(name, source)| validate(name, source).err())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Parse and validate `source`; the error names `name` and the place.
fn validate(name: &str, source: &str) -> Result<naga::Module, String> {
    assert!(!source.contains("#import"), "{name}: an import was left");
    let module = naga::front::wgsl::parse_str(source)
        .map_err(|error| error.emit_to_string_with_path(source, name))?;
    // Default capabilities: what WebGPU guarantees, so the shaders run anywhere.
    let mut validator = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    );
    validator
        .validate(&module)
        .map_err(|error| error.emit_to_string_with_path(source, name))?;
    Ok(module)
}

#[test]
fn the_mesh_shader_reading_weights_as_vertex_attributes_validates() {
    use pmvc::render::weight_attributes::AttributeBlend;
    let limits = wgpu::Limits {
        max_vertex_attributes: 32,
        ..Default::default()
    };
    // Ogre's 118 columns, all in attributes; a 162-vertex cage's, past them; one
    // column; and a family whose columns carry matrices (Somigliana's 72 on a
    // tetrahedron), all in attributes.
    for (columns, matrices) in [(118, false), (162, false), (1, false), (72, true)] {
        let blend = AttributeBlend::new(&limits, columns, 1, matrices).expect("fits");
        let source = pmvc::render::mesh::shader_source_for(16, Some(&blend));
        let name = format!("render_mesh.wgsl with {columns} columns as attributes");
        let module = validate(&name, &source).unwrap_or_else(|error| panic!("{error}"));
        let entries: Vec<&str> = module
            .entry_points
            .iter()
            .map(|e| e.name.as_str())
            .collect();
        for entry in [
            "vs_mesh_attributes",
            "vs_wire_attributes",
            "vs_probe_attributes",
        ] {
            assert!(entries.contains(&entry), "{name}: no {entry}");
        }
    }
}
