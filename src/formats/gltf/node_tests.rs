//! An export keeps the transform of the node the mesh was read through.

use super::*;
use crate::formats::load_mesh;
use base64::Engine as _;
use glam::DVec3;

/// A glTF of one triangle, (0,0,0), (1,0,0), (0,1,0), drawn by `node`.
fn triangle_gltf(node: &str) -> String {
    let floats = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.];
    let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    let uri = base64::engine::general_purpose::STANDARD.encode(bytes);
    format!(
        r#"{{"asset":{{"version":"2.0"}},
        "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{uri}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "nodes":[{node}]}}"#
    )
}

/// Accessor `index` of an embedded `.gltf` as f32 triples.
fn vec3s(json: &serde_json::Value, index: &serde_json::Value) -> Vec<DVec3> {
    let uri = json["buffers"][0]["uri"].as_str().unwrap();
    let payload = uri.split_once("base64,").unwrap().1;
    let buffer = base64::engine::general_purpose::STANDARD
        .decode(payload)
        .unwrap();
    let accessor = &json["accessors"][index.as_u64().unwrap() as usize];
    let view = &json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let count = accessor["count"].as_u64().unwrap() as usize;
    let f = |at: usize| f64::from(f32::from_le_bytes(buffer[at..at + 4].try_into().unwrap()));
    (0..count)
        .map(|i| {
            let at = start + 12 * i;
            DVec3::new(f(at), f(at + 4), f(at + 8))
        })
        .collect()
}

/// Read the triangle through `node`, export it, and read the export's JSON.
fn export_through(node: &str) -> (MeshFile, MeshFile, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    let source = dir.path().join("source.gltf");
    std::fs::write(&source, triangle_gltf(node)).unwrap();
    let file = load_mesh(&source).unwrap();
    let out = dir.path().join("out.gltf");
    let scene = GltfScene {
        mesh: &file,
        base: &file.mesh.positions,
        poses: &[],
        animation: None,
    };
    write_gltf(&out, &scene).unwrap();
    let again = load_mesh(&out).unwrap();
    let json = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    (file, again, json)
}

fn close(a: &[DVec3], b: &[DVec3]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(p, q)| p.distance(*q) < 1e-5)
}

#[test]
fn an_export_keeps_the_nodes_transform_and_lands_where_the_original_was() {
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let node = format!(
        r#"{{"mesh":0,"translation":[10,0,0],"rotation":[0,{half},0,{half}],"scale":[2,2,2]}}"#
    );
    let (file, again, json) = export_through(&node);
    assert!(file.node_transform.is_some());
    let written = &json["nodes"][0];
    assert_eq!(written["translation"], serde_json::json!([10.0, 0.0, 0.0]));
    assert_eq!(written["scale"], serde_json::json!([2.0, 2.0, 2.0]));
    let rotation: Vec<f64> = written["rotation"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let expected = [0.0, f64::from(half), 0.0, f64::from(half)];
    // q and −q are one rotation.
    let dot: f64 = rotation.iter().zip(expected).map(|(a, b)| a * b).sum();
    assert!((dot.abs() - 1.0).abs() < 1e-6, "{rotation:?}");
    // The vertices are the source's, in the node's frame.
    let primitive = &json["meshes"][0]["primitives"][0];
    let local = vec3s(&json, &primitive["attributes"]["POSITION"]);
    let source = [DVec3::ZERO, DVec3::X, DVec3::Y];
    assert!(close(&local, &source), "{local:?}");
    // Read again, it is where the original was.
    assert!(close(&again.mesh.positions, &file.mesh.positions));
    assert_eq!(again.mesh.triangles, file.mesh.triangles);
}

#[test]
fn a_mirroring_node_is_kept_with_the_sources_winding_and_normals() {
    let (file, again, json) =
        export_through(r#"{"mesh":0,"translation":[10,0,0],"scale":[-2,2,2]}"#);
    let written = &json["nodes"][0];
    let scale = written["scale"].as_array().unwrap();
    let product: f64 = scale.iter().map(|s| s.as_f64().unwrap()).product();
    assert_eq!(product, -8.0);
    let primitive = &json["meshes"][0]["primitives"][0];
    let local = vec3s(&json, &primitive["attributes"]["POSITION"]);
    assert!(
        close(&local, &[DVec3::ZERO, DVec3::X, DVec3::Y]),
        "{local:?}"
    );
    // The source's triangle faces +z in its own frame, and so does the copy.
    let normals = vec3s(&json, &primitive["attributes"]["NORMAL"]);
    assert!(
        normals.iter().all(|n| n.distance(DVec3::Z) < 1e-6),
        "{normals:?}"
    );
    assert!(close(&again.mesh.positions, &file.mesh.positions));
    assert_eq!(again.mesh.triangles, file.mesh.triangles);
}

#[test]
fn a_shear_is_baked_into_the_vertices_and_a_far_node_keeps_them_near_its_origin() {
    let shear = r#"{"mesh":0,"matrix":[1,0,0,0, 0.5,1,0,0, 0,0,1,0, 3,0,0,1]}"#;
    let (file, again, json) = export_through(shear);
    let written = &json["nodes"][0];
    assert!(written.get("scale").is_none() && written.get("rotation").is_none());
    assert!(written.get("matrix").is_none());
    assert!(close(&again.mesh.positions, &file.mesh.positions));
    // Ten million units away through a parent: in f32 world positions the
    // triangle would lose its shape; in its node's frame it keeps it.
    let far = r#"{"children":[1],"translation":[1e7,0,0]},{"mesh":0,"translation":[0,3e6,0],"scale":[2,2,2]}"#;
    let (file, again, json) = export_through(far);
    let primitive = &json["meshes"][0]["primitives"][0];
    let local = vec3s(&json, &primitive["attributes"]["POSITION"]);
    assert!(
        close(&local, &[DVec3::ZERO, DVec3::X, DVec3::Y]),
        "{local:?}"
    );
    assert_eq!(
        json["nodes"][0]["translation"],
        serde_json::json!([1e7, 3e6, 0.0])
    );
    assert!(close(&again.mesh.positions, &file.mesh.positions));
}
