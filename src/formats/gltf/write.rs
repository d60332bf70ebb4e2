//! [`write_gltf`]: the buffers, the JSON (gltf-json's types) and the file.

use super::frame::Frame;
use super::layout::{layout_memory, Layout, Primitive};
use super::{AnimationKey, GltfScene, GltfWriteError};
use crate::budget::human_bytes;
use crate::budget::{bytes_for, check_memory, TooLarge};
use crate::formats::PendingOutput;
use crate::geometry::vertex_normals;
use base64::Engine as _;
use glam::{DVec3, Vec3};
use gltf::json;
use json::validation::{Checked::Valid, USize64};
use json::Index;
use std::io::Write;
use std::path::Path;

/// The most a `.glb` may hold: its lengths are 32-bit.
const GLB_LIMIT: u64 = u32::MAX as u64;

/// Write `scene` to `path` as glTF 2.0: `.gltf` as JSON with the buffer inside,
/// any other name as binary `.glb` (see the module documentation). Nothing is
/// written when an error is returned.
pub fn write_gltf(path: &Path, scene: &GltfScene) -> Result<(), GltfWriteError> {
    let invalid = |message: String| GltfWriteError::Invalid {
        path: path.to_owned(),
        message,
    };
    let too_large = |source: TooLarge| GltfWriteError::TooLarge {
        path: path.to_owned(),
        source,
    };
    check_scene(scene).map_err(invalid)?;
    let mesh = &scene.mesh.mesh;
    // The normals of two shapes at a time and a shape in the node's frame, in f64.
    let normals_bytes = bytes_for(mesh.positions.len() as u64, 3 * 24);
    check_memory(
        || {
            format!(
                "laying out its {} vertices and {} triangles",
                mesh.positions.len(),
                mesh.triangles.len()
            )
        },
        layout_memory(mesh.triangles.len()).saturating_add(normals_bytes),
    )
    .map_err(too_large)?;
    let layout = Layout::of(scene.mesh).map_err(too_large)?;
    let embedded = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf"));
    let buffer = buffer_bytes(&layout, scene);
    // The .gltf's JSON holds the buffer in base64 and is built in memory.
    let file_bytes = if embedded {
        bytes_for(buffer.div_ceil(3), 4 * 2)
    } else {
        buffer
    };
    check_memory(
        || {
            format!(
                "its glTF buffer ({} vertices, {} morph targets)",
                layout.source.len(),
                scene.poses.len()
            )
        },
        buffer.saturating_add(file_bytes),
    )
    .map_err(too_large)?;
    if !embedded && buffer > GLB_LIMIT {
        return Err(invalid(format!(
            "a .glb holds at most 4 GiB, and this one would need {}; write fewer poses",
            human_bytes(buffer)
        )));
    }
    let output = PendingOutput::create(path)?;
    let (mut root, mut bin) = build(&layout, scene);
    drop(layout);
    let serialize = |root: &json::Root| {
        json::serialize::to_vec(root).map_err(|e| invalid(format!("cannot write its JSON: {e}")))
    };
    if embedded {
        root.buffers[0].uri = Some(format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&bin)
        ));
        drop(bin);
        let text = serialize(&root)?;
        drop(root);
        output.check_space(text.len() as u64)?;
        output.finish(|out| out.write_all(&text))?;
    } else {
        let mut text = serialize(&root)?;
        drop(root);
        text.resize(text.len().next_multiple_of(4), b' ');
        bin.resize(bin.len().next_multiple_of(4), 0);
        let total = 12 + 8 + text.len() as u64 + 8 + bin.len() as u64;
        if total > GLB_LIMIT {
            return Err(invalid(format!(
                "a .glb holds at most 4 GiB, and this one would need {}; write fewer poses",
                human_bytes(total)
            )));
        }
        output.check_space(total)?;
        output.finish(|out| write_glb(out, total as u32, &text, &bin))?;
    }
    Ok(())
}

/// What the caller gave, checked: one position per vertex in every shape, all
/// finite; keys in increasing time, each naming a pose there is.
fn check_scene(scene: &GltfScene) -> Result<(), String> {
    let vertices = scene.mesh.mesh.positions.len();
    let shapes = std::iter::once(("the base", scene.base))
        .chain(scene.poses.iter().map(|p| (p.name, p.positions)));
    for (name, positions) in shapes {
        if positions.len() != vertices {
            return Err(format!(
                "pose '{name}' has {} positions, but the mesh has {vertices} vertices",
                positions.len()
            ));
        }
        if let Some(at) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!(
                "pose '{name}': vertex {} has a non-finite coordinate",
                at + 1
            ));
        }
    }
    let Some(keys) = scene.animation else {
        return Ok(());
    };
    if scene.poses.is_empty() {
        return Err("an animation through poses needs at least one pose".to_owned());
    }
    if keys.is_empty() {
        return Err("an animation needs at least one key".to_owned());
    }
    let mut previous: Option<f32> = None;
    for (k, key) in keys.iter().enumerate() {
        if !(key.seconds.is_finite() && key.seconds >= 0.0) {
            return Err(format!(
                "animation key {k} is at {} s; times must be finite and at least 0",
                key.seconds
            ));
        }
        if previous.is_some_and(|p| key.seconds <= p) {
            return Err(format!(
                "animation key {k} is at {} s, not after the key before it",
                key.seconds
            ));
        }
        previous = Some(key.seconds);
        if let Some(pose) = key.pose.filter(|&p| p >= scene.poses.len()) {
            return Err(format!(
                "animation key {k} names pose {pose}, but there are {} poses",
                scene.poses.len()
            ));
        }
    }
    Ok(())
}

/// Bytes of the binary buffer: per vertex a position, a normal (triangles
/// only) and a texture coordinate where its primitive has them, the same
/// deltas per target, the indices, and the animation's keys and weights.
fn buffer_bytes(layout: &Layout, scene: &GltfScene) -> u64 {
    let vertices = layout.source.len() as u64;
    let normal = if layout.points { 0 } else { 12 };
    let uvs: u64 = layout
        .primitives
        .iter()
        .filter(|p| p.has_uvs)
        .map(|p| p.vertices.len() as u64 * 8)
        .sum();
    let indices: u64 = layout
        .primitives
        .iter()
        .map(|p| p.indices.len() as u64 * 4)
        .sum();
    let targets = scene.poses.len() as u64;
    let keys = scene.animation.map_or(0, |k| k.len() as u64);
    let per_vertex = bytes_for(vertices, 12 + normal);
    [
        per_vertex,
        bytes_for(per_vertex, targets),
        uvs,
        indices,
        bytes_for(keys, 4 + 4 * targets),
        // Each view's padding to 4 bytes.
        bytes_for(layout.primitives.len() as u64, 4 * (3 + 2 * targets)),
    ]
    .into_iter()
    .fold(0, u64::saturating_add)
}

/// The JSON document and its binary buffer.
struct Builder {
    root: json::Root,
    bin: Vec<u8>,
}

impl Builder {
    /// A view of `bytes` appended to the buffer, and an accessor over it.
    fn accessor(
        &mut self,
        bytes: impl IntoIterator<Item = [u8; 4]>,
        count: usize,
        (component, kind): (json::accessor::ComponentType, json::accessor::Type),
        target: Option<json::buffer::Target>,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    ) -> Index<json::Accessor> {
        let start = self.bin.len();
        for word in bytes {
            self.bin.extend_from_slice(&word);
        }
        let length = self.bin.len() - start;
        let view = self.root.push(json::buffer::View {
            buffer: Index::new(0),
            byte_length: USize64(length as u64),
            byte_offset: Some(USize64(start as u64)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: None,
        });
        let value = |v: Vec<f32>| Some(serde_json::Value::from(v));
        let (min, max) = bounds.map_or((None, None), |(min, max)| (value(min), value(max)));
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64(count as u64),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            extensions: None,
            extras: None,
            type_: Valid(kind),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// An accessor of f32 vectors of `N` components, with their bounds when asked.
    fn floats<const N: usize>(
        &mut self,
        values: &[[f32; N]],
        kind: json::accessor::Type,
        target: Option<json::buffer::Target>,
        bounded: bool,
    ) -> Index<json::Accessor> {
        let bounds = bounded.then(|| {
            let mut min = [f32::INFINITY; N];
            let mut max = [f32::NEG_INFINITY; N];
            for value in values {
                for c in 0..N {
                    min[c] = min[c].min(value[c]);
                    max[c] = max[c].max(value[c]);
                }
            }
            (min.to_vec(), max.to_vec())
        });
        let words = values.iter().flatten().map(|v| v.to_le_bytes());
        let component = json::accessor::ComponentType::F32;
        self.accessor(words, values.len(), (component, kind), target, bounds)
    }
}

/// `value` as f32 components.
fn f32s(value: DVec3) -> [f32; 3] {
    value.as_vec3().to_array()
}

/// The vertex normals of `positions`, flipped where the node mirrors: the
/// triangles are then written in the source's winding ([`json_primitive`]).
fn normals(positions: &[DVec3], triangles: &[[u32; 3]], mirrored: bool) -> Vec<DVec3> {
    let mut normals = vertex_normals(positions, triangles);
    if mirrored {
        normals.iter_mut().for_each(|n| *n = -*n);
    }
    normals
}

fn build(layout: &Layout, scene: &GltfScene) -> (json::Root, Vec<u8>) {
    use json::accessor::Type;
    let array = Some(json::buffer::Target::ArrayBuffer);
    let mut builder = Builder {
        root: json::Root::default(),
        bin: Vec::new(),
    };
    let triangles = &scene.mesh.mesh.triangles;
    let frame = Frame::of(scene.mesh, scene.base);
    let base: Vec<DVec3> = scene.base.iter().map(|&p| frame.point(p)).collect();
    let base_normals = (!layout.points).then(|| normals(&base, triangles, frame.mirrored));
    let mut primitives: Vec<json::mesh::Primitive> = layout
        .primitives
        .iter()
        .map(|primitive| {
            let sources = &layout.source[primitive.vertices.clone()];
            let positions: Vec<[f32; 3]> =
                sources.iter().map(|&s| f32s(base[s as usize])).collect();
            let mut attributes = std::collections::BTreeMap::new();
            let position = builder.floats(&positions, Type::Vec3, array, true);
            attributes.insert(Valid(json::mesh::Semantic::Positions), position);
            if let Some(normals) = &base_normals {
                let normals: Vec<[f32; 3]> =
                    sources.iter().map(|&s| f32s(normals[s as usize])).collect();
                let normal = builder.floats(&normals, Type::Vec3, array, false);
                attributes.insert(Valid(json::mesh::Semantic::Normals), normal);
            }
            if primitive.has_uvs {
                let uvs: Vec<[f32; 2]> = layout.uvs[primitive.vertices.clone()]
                    .iter()
                    .map(|&[u, v]| if u.is_nan() { [0.0, 1.0] } else { [u, 1.0 - v] })
                    .collect();
                let uv = builder.floats(&uvs, Type::Vec2, array, false);
                attributes.insert(Valid(json::mesh::Semantic::TexCoords(0)), uv);
            }
            json_primitive(&mut builder, primitive, attributes, frame.mirrored)
        })
        .collect();
    add_targets(
        &mut builder,
        &mut primitives,
        layout,
        scene,
        (&frame, base_normals.as_deref()),
    );
    let names: Vec<&str> = scene.poses.iter().map(|p| p.name).collect();
    let stem = scene
        .mesh
        .path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned());
    let has_targets = !scene.poses.is_empty();
    let mesh = builder.root.push(json::Mesh {
        extensions: None,
        extras: has_targets.then(|| raw(&serde_json::json!({ "targetNames": names }))),
        name: stem.clone(),
        primitives,
        weights: has_targets.then(|| vec![0.0; scene.poses.len()]),
    });
    let node = builder.root.push(json::Node {
        mesh: Some(mesh),
        name: stem,
        translation: (frame.translation != Vec3::ZERO).then(|| frame.translation.to_array()),
        rotation: (frame.rotation != [0.0, 0.0, 0.0, 1.0])
            .then_some(json::scene::UnitQuaternion(frame.rotation)),
        scale: (frame.scale != Vec3::ONE).then(|| frame.scale.to_array()),
        ..Default::default()
    });
    let scene_index = builder.root.push(json::Scene {
        extensions: None,
        extras: None,
        name: None,
        nodes: vec![node],
    });
    builder.root.scene = Some(scene_index);
    if let Some(keys) = scene.animation {
        add_animation(&mut builder, node, keys, scene.poses.len());
    }
    builder.root.asset = json::Asset {
        generator: Some(format!("pmvc {}", env!("CARGO_PKG_VERSION"))),
        ..Default::default()
    };
    builder.root.buffers.push(json::Buffer {
        byte_length: USize64(builder.bin.len() as u64),
        name: None,
        uri: None,
        extensions: None,
        extras: None,
    });
    (builder.root, builder.bin)
}

/// `value` as the raw JSON of an `extras`.
fn raw(value: &serde_json::Value) -> Box<serde_json::value::RawValue> {
    serde_json::value::to_raw_value(value).expect("a JSON value serializes")
}

/// The primitive's indices, material and name, around its `attributes`.
fn json_primitive(
    builder: &mut Builder,
    primitive: &Primitive,
    attributes: std::collections::BTreeMap<
        json::validation::Checked<json::mesh::Semantic>,
        Index<json::Accessor>,
    >,
    mirrored: bool,
) -> json::mesh::Primitive {
    let indices = (!primitive.indices.is_empty()).then(|| {
        // The reader reversed the winding where the node mirrors; a viewer
        // reverses it again.
        let words = primitive.indices.chunks_exact(3).flat_map(|t| {
            let t = if mirrored {
                [t[0], t[2], t[1]]
            } else {
                [t[0], t[1], t[2]]
            };
            t.map(u32::to_le_bytes)
        });
        let kind = (
            json::accessor::ComponentType::U32,
            json::accessor::Type::Scalar,
        );
        let target = Some(json::buffer::Target::ElementArrayBuffer);
        builder.accessor(words, primitive.indices.len(), kind, target, None)
    });
    let material = primitive.group.material.as_ref().map(|name| {
        let existing = builder
            .root
            .materials
            .iter()
            .position(|m| m.name.as_deref() == Some(name.as_str()));
        match existing {
            Some(index) => Index::new(index as u32),
            None => builder.root.push(json::Material {
                name: Some(name.clone()),
                ..Default::default()
            }),
        }
    });
    let name = &primitive.group.name;
    json::mesh::Primitive {
        attributes,
        extensions: None,
        extras: (!name.is_empty()).then(|| raw(&serde_json::json!({ "name": name }))),
        indices,
        material,
        mode: Valid(if primitive.indices.is_empty() {
            json::mesh::Mode::Points
        } else {
            json::mesh::Mode::Triangles
        }),
        targets: None,
    }
}

/// One morph target per pose on every primitive: POSITION deltas from the base
/// (taken in f64) and, for triangles, NORMAL deltas between the shapes'
/// recomputed normals.
fn add_targets(
    builder: &mut Builder,
    primitives: &mut [json::mesh::Primitive],
    layout: &Layout,
    scene: &GltfScene,
    (frame, base_normals): (&Frame, Option<&[DVec3]>),
) {
    use json::accessor::Type;
    let array = Some(json::buffer::Target::ArrayBuffer);
    let triangles = &scene.mesh.mesh.triangles;
    for pose in scene.poses {
        let normals = base_normals.map(|_| {
            let local: Vec<DVec3> = pose.positions.iter().map(|&p| frame.point(p)).collect();
            normals(&local, triangles, frame.mirrored)
        });
        for (primitive, json_primitive) in layout.primitives.iter().zip(primitives.iter_mut()) {
            let sources = &layout.source[primitive.vertices.clone()];
            let deltas: Vec<[f32; 3]> = sources
                .iter()
                .map(|&s| f32s(frame.vector(pose.positions[s as usize] - scene.base[s as usize])))
                .collect();
            let positions = Some(builder.floats(&deltas, Type::Vec3, array, true));
            let normals = normals.as_ref().zip(base_normals).map(|(pose, base)| {
                let deltas: Vec<[f32; 3]> = sources
                    .iter()
                    .map(|&s| f32s(pose[s as usize] - base[s as usize]))
                    .collect();
                builder.floats(&deltas, Type::Vec3, array, false)
            });
            json_primitive
                .targets
                .get_or_insert_with(Vec::new)
                .push(json::mesh::MorphTarget {
                    positions,
                    normals,
                    tangents: None,
                });
        }
    }
}

/// The animation: one LINEAR sampler of the target weights, 1 for the key's
/// pose and 0 for the others, driving the node's `weights`.
fn add_animation(
    builder: &mut Builder,
    node: Index<json::Node>,
    keys: &[AnimationKey],
    targets: usize,
) {
    use json::accessor::Type;
    let times: Vec<[f32; 1]> = keys.iter().map(|k| [k.seconds]).collect();
    let input = builder.floats(&times, Type::Scalar, None, true);
    let weights: Vec<[f32; 1]> = keys
        .iter()
        .flat_map(|key| (0..targets).map(move |t| [f32::from(key.pose == Some(t))]))
        .collect();
    let output = builder.floats(&weights, Type::Scalar, None, false);
    let mut samplers = Vec::new();
    let sampler = Index::push(
        &mut samplers,
        json::animation::Sampler {
            extensions: None,
            extras: None,
            input,
            interpolation: Valid(json::animation::Interpolation::Linear),
            output,
        },
    );
    builder.root.push(json::Animation {
        extensions: None,
        extras: None,
        channels: vec![json::animation::Channel {
            sampler,
            target: json::animation::Target {
                extensions: None,
                extras: None,
                node,
                path: Valid(json::animation::Property::MorphTargetWeights),
            },
            extensions: None,
            extras: None,
        }],
        name: Some("poses".to_owned()),
        samplers,
    });
}

/// A binary glTF of `total` bytes: the header, the JSON chunk (padded with
/// spaces) and the binary chunk (padded with zeros), each a multiple of 4 bytes.
fn write_glb(out: &mut dyn Write, total: u32, text: &[u8], bin: &[u8]) -> std::io::Result<()> {
    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&total.to_le_bytes())?;
    for (kind, chunk) in [(b"JSON", text), (b"BIN\0", bin)] {
        out.write_all(&(chunk.len() as u32).to_le_bytes())?;
        out.write_all(kind)?;
        out.write_all(chunk)?;
    }
    Ok(())
}
