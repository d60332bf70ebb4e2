//! WGSL composition. A shader names shared WGSL with `#import <name>` lines, as
//! re_renderer's shaders do; each import is replaced by its text, once per shader
//! however often it is named (imports may import). Shared structs that Rust also
//! defines (`Frame`, `Params`) and tables that Rust owns (the cube faces) are thus
//! written once; `tests/gpu/shader_layouts.rs` checks the structs against Rust.

use super::kernels::{BAND_TEXELS, FALLBACK, TILES_MAX_VERTICES, WORKGROUP_SIZE};
use crate::coords::cubemap::CUBE_FACES;
use std::collections::HashSet;

/// Where an importable piece of WGSL comes from.
enum Shared {
    /// A file in `shaders/shared/`.
    File(&'static str),
    /// Generated from the Rust definition, which stays the only one.
    Generated(fn() -> String),
}

/// Every importable name and its text.
const SHARED: [(&str, Shared); 10] = [
    (
        "frame",
        Shared::File(include_str!("../../shaders/shared/frame.wgsl")),
    ),
    (
        "bind_params",
        Shared::File(include_str!("../../shaders/shared/bind_params.wgsl")),
    ),
    (
        "angles",
        Shared::File(include_str!("../../shaders/shared/angles.wgsl")),
    ),
    (
        "closed_form_bindings",
        Shared::File(include_str!(
            "../../shaders/shared/closed_form_bindings.wgsl"
        )),
    ),
    (
        "pmvc_patches",
        Shared::File(include_str!("../../shaders/shared/pmvc_patches.wgsl")),
    ),
    (
        "pmvc_bindings",
        Shared::File(include_str!("../../shaders/shared/pmvc_bindings.wgsl")),
    ),
    (
        "pmvc_face",
        Shared::File(include_str!("../../shaders/shared/pmvc_face.wgsl")),
    ),
    (
        "pmvc_no_patches",
        Shared::File(include_str!("../../shaders/shared/pmvc_no_patches.wgsl")),
    ),
    ("cube_faces", Shared::Generated(cube_faces_wgsl)),
    ("bind_constants", Shared::Generated(bind_constants_wgsl)),
];

/// A shader's `#import` could not be resolved.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ShaderSourceError {
    #[error("{shader}:{line}: unknown import `{name}` (known: {known})")]
    UnknownImport {
        shader: String,
        line: usize,
        name: String,
        known: String,
    },
    #[error("{shader}:{line}: `#import` needs a name")]
    MissingName { shader: String, line: usize },
}

/// `source` (named `shader` in messages) with every `#import` line replaced.
pub fn compose(shader: &str, source: &str) -> Result<String, ShaderSourceError> {
    let mut out = String::with_capacity(source.len() * 2);
    let mut included = HashSet::new();
    append(shader, source, &mut included, &mut out)?;
    Ok(out)
}

fn append(
    shader: &str,
    source: &str,
    included: &mut HashSet<&'static str>,
    out: &mut String,
) -> Result<(), ShaderSourceError> {
    for (index, line) in source.lines().enumerate() {
        let Some(rest) = line.trim_start().strip_prefix("#import") else {
            out.push_str(line);
            out.push('\n');
            continue;
        };
        let name = rest.trim();
        if name.is_empty() {
            return Err(ShaderSourceError::MissingName {
                shader: shader.to_owned(),
                line: index + 1,
            });
        }
        let Some((known_name, shared)) = SHARED.iter().find(|(known, _)| *known == name) else {
            return Err(ShaderSourceError::UnknownImport {
                shader: shader.to_owned(),
                line: index + 1,
                name: name.to_owned(),
                known: SHARED.map(|(known, _)| known).join(", "),
            });
        };
        if !included.insert(known_name) {
            continue;
        }
        match shared {
            Shared::File(text) => append(known_name, text, included, out)?,
            Shared::Generated(generate) => append(known_name, &generate(), included, out)?,
        }
    }
    Ok(())
}

/// The binding kernels' constants, from their Rust definitions.
fn bind_constants_wgsl() -> String {
    format!(
        "// Generated from gpu::kernels.\n\
         const WORKGROUP_SIZE: u32 = {WORKGROUP_SIZE}u;\n\
         const BAND_TEXELS: u32 = {BAND_TEXELS}u;\n\
         // Cage vertices the tile kernel's workgroup sums can hold.\n\
         const TILES_MAX_VERTICES: u32 = {TILES_MAX_VERTICES}u;\n\
         // Status bit the kernels set for rows the CPU must redo.\n\
         const FALLBACK: u32 = {FALLBACK}u;\n"
    )
}

/// `face_axes(face)`: (right, up, normal) of each cube face, from [`CUBE_FACES`].
fn cube_faces_wgsl() -> String {
    let vector = |v: glam::DVec3| format!("vec3({:.1}, {:.1}, {:.1})", v.x, v.y, v.z);
    let mut text = String::from(
        "// Generated from coords::cubemap::CUBE_FACES: (right, up, normal) of each face.\n\
         fn face_axes(face: u32) -> mat3x3<f32> {\n    switch face {\n",
    );
    for (index, face) in CUBE_FACES.iter().enumerate() {
        let case = if index + 1 == CUBE_FACES.len() {
            "default".to_owned()
        } else {
            format!("case {index}u")
        };
        text.push_str(&format!(
            "        {case}: {{ return mat3x3<f32>({}, {}, {}); }}\n",
            vector(face.right),
            vector(face.up),
            vector(face.normal)
        ));
    }
    text.push_str("    }\n}\n");
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn imports_are_replaced_once_and_other_lines_kept() {
        let composed = compose(
            "test.wgsl",
            "// top\n#import frame\n  #import frame\nfn f() {}\n",
        )
        .unwrap();
        assert!(composed.starts_with("// top\n"));
        assert_eq!(composed.matches("struct Frame").count(), 1);
        assert!(composed.ends_with("fn f() {}\n"));
        assert!(!composed.contains("#import"));
    }

    #[test]
    fn an_unknown_or_empty_import_names_the_shader_and_line() {
        let error = compose("a.wgsl", "\n#import nope\n").unwrap_err();
        assert!(
            matches!(&error, ShaderSourceError::UnknownImport { line: 2, name, .. } if name == "nope"),
            "{error}"
        );
        assert!(error
            .to_string()
            .starts_with("a.wgsl:2: unknown import `nope`"));
        let error = compose("b.wgsl", "#import\n").unwrap_err();
        assert_eq!(
            error,
            ShaderSourceError::MissingName {
                shader: "b.wgsl".into(),
                line: 1
            }
        );
    }

    #[test]
    fn generated_cube_faces_follow_the_rust_table() {
        let text = cube_faces_wgsl();
        assert_eq!(text.matches("return mat3x3").count(), 6);
        assert!(text.contains(
            "case 1u: { return mat3x3<f32>(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(-1.0, 0.0, 0.0)); }"
        ));
    }
}
