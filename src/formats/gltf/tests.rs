use super::layout::Layout;
use super::*;
use crate::formats::{load_cage, load_mesh, parse_mesh, LoadError, MeshFormat};
use glam::DVec3;

/// A unit square of two triangles in two groups, with a texture seam along
/// its diagonal (corners of vertices 0 and 2 differ between the triangles).
const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n\
g first\nusemtl red\nf 1/1 2/2 3/3\n\
g second\nusemtl blue\nf 1/5 3/5 4/4\n";

fn square() -> MeshFile {
    parse_mesh(Path::new("square.obj"), SQUARE.to_owned()).unwrap()
}

#[test]
fn corners_that_disagree_split_their_vertex_and_groups_become_primitives() {
    let layout = Layout::of(&square()).unwrap();
    assert_eq!(layout.primitives.len(), 2);
    let names: Vec<(&str, Option<&str>)> = layout
        .primitives
        .iter()
        .map(|p| (p.group.name.as_str(), p.group.material.as_deref()))
        .collect();
    assert_eq!(names, [("first", Some("red")), ("second", Some("blue"))]);
    // Each triangle in its own primitive: three vertices each.
    assert_eq!(layout.source, [0, 1, 2, 0, 2, 3]);
    assert_eq!(layout.uvs[3], [0.5, 0.5]);
    assert_eq!(layout.primitives[1].indices, [0, 1, 2]);
    assert!(layout.primitives.iter().all(|p| p.has_uvs));
}

#[test]
fn a_mesh_without_texture_or_groups_keeps_its_vertex_order() {
    let file = parse_mesh(
        Path::new("plain.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nf 4 1 2\nf 2 3 4\n".to_owned(),
    )
    .unwrap();
    let layout = Layout::of(&file).unwrap();
    assert_eq!(layout.primitives.len(), 1);
    // The vertex in no triangle (5) is left out.
    assert_eq!(layout.source, [0, 1, 2, 3]);
    assert_eq!(layout.primitives[0].indices, [3, 0, 1, 1, 2, 3]);
    assert!(layout.uvs.is_empty() && !layout.primitives[0].has_uvs);
}

fn write_to(dir: &Path, name: &str, scene: &GltfScene) -> PathBuf {
    let path = dir.join(name);
    write_gltf(&path, scene).unwrap();
    path
}

#[test]
fn written_glb_and_gltf_read_back_with_texture_groups_and_welded_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let file = square();
    let base: Vec<DVec3> = file.mesh.positions.iter().map(|p| *p * 2.0).collect();
    let scene = GltfScene {
        mesh: &file,
        base: &base,
        poses: &[],
        animation: None,
    };
    for name in ["square.glb", "square.gltf"] {
        let path = write_to(dir.path(), name, &scene);
        let read = load_mesh(&path).unwrap();
        assert_eq!(read.format, MeshFormat::Gltf);
        // Welded: four positions again, and the same triangles.
        assert_eq!(read.mesh.positions, base, "{name}");
        assert_eq!(read.mesh.triangles, file.mesh.triangles, "{name}");
        let text = read.obj_text.as_deref().unwrap();
        assert!(text.contains("g first\nusemtl red\n"), "{text}");
        assert!(text.contains("g second\nusemtl blue\n"), "{text}");
        // v flipped on the way out and back: the same texture coordinates.
        let again = Layout::of(&read).unwrap();
        assert_eq!(again.uvs, Layout::of(&file).unwrap().uvs, "{name}");
    }
}

#[test]
fn a_mesh_far_from_the_origin_is_written_relative_to_a_translation() {
    let dir = tempfile::tempdir().unwrap();
    let file = square();
    let far = DVec3::new(1e7, -3e6, 2.5e6);
    let base: Vec<DVec3> = file
        .mesh
        .positions
        .iter()
        .map(|p| *p * 1e-3 + far)
        .collect();
    let lifted: Vec<DVec3> = base.iter().map(|p| *p + DVec3::Z * 1e-4).collect();
    let poses = [GltfPose {
        name: "lifted",
        positions: &lifted,
    }];
    let scene = GltfScene {
        mesh: &file,
        base: &base,
        poses: &poses,
        animation: None,
    };
    let path = write_to(dir.path(), "far.glb", &scene);
    let read = load_mesh(&path).unwrap();
    for (read, written) in read.mesh.positions.iter().zip(&base) {
        // f32 relative to a point within a diagonal: far below the 1 m an
        // f32 of 1e7 would keep.
        assert!((*read - *written).length() < 1e-9, "{read} vs {written}");
    }
}

#[test]
fn a_gltf_cage_welds_into_a_closed_cage() {
    let dir = tempfile::tempdir().unwrap();
    let cage = crate::geometry::procedural::cube_cage(1.0);
    let text = format!(
        "{}{}",
        cage.positions()
            .iter()
            .map(|p| format!("v {} {} {}\n", p.x, p.y, p.z))
            .collect::<String>(),
        // A texture coordinate per corner splits every vertex in glTF.
        (0..cage.triangles().len() * 3)
            .map(|k| format!("vt {} 0\n", k as f64 / 64.0))
            .collect::<String>()
    );
    let faces: String = cage
        .triangles()
        .iter()
        .enumerate()
        .map(|(t, [a, b, c])| {
            let k = 3 * t;
            format!(
                "f {}/{} {}/{} {}/{}\n",
                a + 1,
                k + 1,
                b + 1,
                k + 2,
                c + 1,
                k + 3
            )
        })
        .collect();
    let file = parse_mesh(Path::new("cage.obj"), text + &faces).unwrap();
    let scene = GltfScene {
        mesh: &file,
        base: &file.mesh.positions,
        poses: &[],
        animation: None,
    };
    let path = write_to(dir.path(), "cage.glb", &scene);
    assert_eq!(Layout::of(&file).unwrap().source.len(), 36);
    let (read, _) = load_cage(&path).unwrap();
    assert_eq!(read.vertex_count(), 8);
}

#[test]
fn poses_of_the_wrong_size_and_keys_out_of_order_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.glb");
    let file = square();
    let short = vec![DVec3::ZERO; 3];
    let base = &file.mesh.positions;
    type Case<'a> = (&'a [GltfPose<'a>], Option<&'a [AnimationKey]>, &'a str);
    let cases: [Case; 4] = [
        (
            &[GltfPose {
                name: "short",
                positions: &short,
            }],
            None,
            "pose 'short' has 3 positions, but the mesh has 4 vertices",
        ),
        (&[], Some(&[]), "needs at least one pose"),
        (
            &[GltfPose {
                name: "p",
                positions: base,
            }],
            Some(&[
                AnimationKey {
                    seconds: 1.0,
                    pose: None,
                },
                AnimationKey {
                    seconds: 1.0,
                    pose: Some(0),
                },
            ]),
            "animation key 1 is at 1 s, not after the key before it",
        ),
        (
            &[GltfPose {
                name: "p",
                positions: base,
            }],
            Some(&[AnimationKey {
                seconds: 0.0,
                pose: Some(1),
            }]),
            "animation key 0 names pose 1, but there are 1 poses",
        ),
    ];
    for (poses, animation, message) in cases {
        let scene = GltfScene {
            mesh: &file,
            base,
            poses,
            animation,
        };
        let error = write_gltf(&path, &scene).unwrap_err().to_string();
        assert!(
            error.starts_with(&format!("{}: ", path.display())),
            "{error}"
        );
        assert!(error.contains(message), "{error}");
        assert!(!path.exists());
    }
}

#[test]
fn keys_evenly_start_at_the_base_and_end_on_the_last_pose() {
    let keys = AnimationKey::evenly(3, 1.5);
    let times: Vec<f32> = keys.iter().map(|k| k.seconds).collect();
    assert_eq!(times, [0.0, 0.5, 1.0, 1.5]);
    let poses: Vec<Option<usize>> = keys.iter().map(|k| k.pose).collect();
    assert_eq!(poses, [None, Some(0), Some(1), Some(2)]);
}

pub(super) fn gltf_error(path: &Path, json: &str) -> String {
    match parse_gltf(path, json.as_bytes(), &MeshPick::First) {
        Err(LoadError::Gltf { message, .. }) => message,
        other => panic!("expected a glTF error for {json}, got {other:?}"),
    }
}

/// A one-triangle glTF JSON whose buffer is `uri` and whose POSITION is
/// accessor `position`.
pub(super) fn triangle_json(uri: &str, position: usize, node: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},
        "buffers":[{{"byteLength":36,"uri":"{uri}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":{position}}}}}]}}],
        "nodes":[{node}]}}"#
    )
}

/// A triangle's 36 bytes, (0,0,0), (1,0,0), (0,1,0), as a base64 data: URI.
pub(super) fn triangle_uri() -> String {
    use base64::Engine as _;
    let floats = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.];
    let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

#[test]
fn node_transforms_move_the_mesh_and_a_mirror_reverses_its_winding() {
    let path = Path::new("t.gltf");
    let node = r#"{"mesh":0,"translation":[10,0,0],"scale":[-2,2,2]}"#;
    let json = triangle_json(&triangle_uri(), 0, node);
    let read = parse_gltf(path, json.as_bytes(), &MeshPick::First).unwrap();
    assert_eq!(
        read.mesh.positions,
        [
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(8.0, 0.0, 0.0),
            DVec3::new(10.0, 2.0, 0.0)
        ]
    );
    assert_eq!(read.mesh.triangles, [[0, 2, 1]]);
    // A parent's transform applies too.
    let nodes = r#"{"mesh":0},{"children":[0],"translation":[0,0,5]}"#;
    let json = triangle_json(&triangle_uri(), 0, nodes);
    let read = parse_gltf(path, json.as_bytes(), &MeshPick::First).unwrap();
    assert_eq!(read.mesh.positions[1], DVec3::new(1.0, 0.0, 5.0));
}

#[test]
fn bad_json_names_the_element_and_what_is_wrong() {
    let path = Path::new("bad.gltf");
    let message = gltf_error(path, &triangle_json(&triangle_uri(), 3, "{}"));
    assert!(
        message.contains(
            "meshes[0].primitives[0].attributes: accessor 3 does not exist (the file has 1)"
        ),
        "{message}"
    );
    let bad_view =
        triangle_json(&triangle_uri(), 0, "{}").replace(r#""bufferView":0"#, r#""bufferView":7"#);
    let message = gltf_error(path, &bad_view);
    assert!(
        message.contains("invalid glTF: accessors[0].bufferView: index out of bounds"),
        "{message}"
    );
    let message = gltf_error(path, &triangle_json("../outside.bin", 0, "{}"));
    assert!(
        message.contains(
            "buffer 0 (\"../outside.bin\"): it is not a file beside the glTF or in a folder below it"
        ),
        "{message}"
    );
    let message = gltf_error(path, &triangle_json("/etc/passwd", 0, "{}"));
    assert!(message.contains("is not a file beside"), "{message}");
    let message = gltf_error(
        path,
        &triangle_json("data:application/octet-stream;base64,AAAA", 0, "{}"),
    );
    assert!(
        message.contains("buffer 0 holds 3 bytes, but its byteLength says 36"),
        "{message}"
    );
    let short_view =
        triangle_json(&triangle_uri(), 0, "{}").replace(r#""count":3"#, r#""count":6"#);
    let message = gltf_error(path, &short_view);
    assert!(
        message.contains(
            "accessor 0: its 6 elements end at byte 72, past the end of buffer view 0 (36 bytes)"
        ),
        "{message}"
    );
    let message = gltf_error(path, "{\"asset\":{\"version\":\"1.0\"}}");
    assert!(message.contains("only 2.x"), "{message}");
    let message = gltf_error(path, "{\"asset\":{\"version\":\"2.0\"}}");
    assert!(message.contains("no meshes"), "{message}");
    let message = gltf_error(path, "[1, 2");
    assert!(message.starts_with("not glTF JSON"), "{message}");
}

#[test]
fn a_mesh_is_picked_by_index_or_name() {
    let path = Path::new("two.gltf");
    let json = triangle_json(&triangle_uri(), 0, "{}").replace(
        r#""meshes":[{"primitives""#,
        r#""meshes":[{"name":"one","primitives":[{"attributes":{"POSITION":0},"mode":0}]},{"name":"two","primitives""#,
    );
    let read = parse_gltf(path, json.as_bytes(), &MeshPick::Name("two".into())).unwrap();
    assert_eq!(read.mesh.triangles.len(), 1);
    let points = parse_gltf(path, json.as_bytes(), &MeshPick::Index(0)).unwrap();
    assert!(points.mesh.triangles.is_empty() && points.mesh.positions.len() == 3);
    let missing = parse_gltf(path, json.as_bytes(), &MeshPick::Index(2)).unwrap_err();
    assert!(
        missing
            .to_string()
            .contains("has 2 meshes, so there is no mesh 2"),
        "{missing}"
    );
    let missing = parse_gltf(path, json.as_bytes(), &MeshPick::Name("x".into())).unwrap_err();
    assert!(missing.to_string().contains("'one', 'two'"), "{missing}");
}

#[test]
fn every_truncation_of_a_glb_is_an_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let file = square();
    let scene = GltfScene {
        mesh: &file,
        base: &file.mesh.positions,
        poses: &[],
        animation: None,
    };
    let bytes = std::fs::read(write_to(dir.path(), "s.glb", &scene)).unwrap();
    let path = Path::new("s.glb");
    assert!(parse_gltf(path, &bytes, &MeshPick::First).is_ok());
    for length in 1..bytes.len() {
        let result = parse_gltf(path, &bytes[..length], &MeshPick::First);
        assert!(
            result.is_err(),
            "accepted {length} of {} bytes",
            bytes.len()
        );
    }
    let message = parse_gltf(path, &bytes[..bytes.len() - 10], &MeshPick::First)
        .unwrap_err()
        .to_string();
    assert!(
        message.starts_with("s.glb: the binary glTF is truncated"),
        "{message}"
    );
}

#[test]
fn any_number_of_a_written_gltf_changed_is_read_or_refused_without_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let file = square();
    let lifted: Vec<DVec3> = file.mesh.positions.iter().map(|p| *p + DVec3::Z).collect();
    let poses = [GltfPose {
        name: "lifted",
        positions: &lifted,
    }];
    let keys = AnimationKey::evenly(1, 1.0);
    let scene = GltfScene {
        mesh: &file,
        base: &file.mesh.positions,
        poses: &poses,
        animation: Some(&keys),
    };
    let text = std::fs::read_to_string(write_to(dir.path(), "s.gltf", &scene)).unwrap();
    let uri = text.find("data:").unwrap()..text.find("\"byteLength\"").unwrap();
    let bytes = text.as_bytes();
    let mut runs = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        if bytes[at].is_ascii_digit() && !uri.contains(&at) {
            let end = at
                + bytes[at..]
                    .iter()
                    .take_while(|b| b.is_ascii_digit())
                    .count();
            runs.push(at..end);
            at = end;
        } else {
            at += 1;
        }
    }
    assert!(runs.len() > 50, "{} numbers", runs.len());
    for run in runs {
        for value in [
            "0",
            "1",
            "3",
            "99",
            "4294967295",
            "18446744073709551615",
            "-1",
        ] {
            let changed = format!("{}{value}{}", &text[..run.start], &text[run.end..]);
            let _ = parse_gltf(Path::new("s.gltf"), changed.as_bytes(), &MeshPick::First);
        }
    }
}
