//! The objects of a glTF file, as Blender names them: each node that draws a
//! mesh, by the node's name (else its mesh's), then each mesh no node draws.
//! One is picked by name ([`super::MeshPick::Object`]); where none is, the
//! first mesh is read and a note says so.

use super::super::error::{object_list, ObjectError};

/// A mesh of the file and the node it is drawn through.
pub(super) struct Object<'a> {
    pub name: String,
    pub mesh: gltf::Mesh<'a>,
    /// The node whose world transform moves it; `None` for a mesh no node draws.
    pub node: Option<usize>,
}

pub(super) fn objects(document: &gltf::Document) -> Vec<Object<'_>> {
    let mut objects: Vec<Object> = document
        .nodes()
        .filter_map(|node| {
            let mesh = node.mesh()?;
            let name = node
                .name()
                .or(mesh.name())
                .map_or_else(|| format!("node {}", node.index()), str::to_owned);
            Some(Object {
                name,
                mesh,
                node: Some(node.index()),
            })
        })
        .collect();
    for mesh in document.meshes() {
        if !objects.iter().any(|o| o.mesh.index() == mesh.index()) {
            let name = mesh
                .name()
                .map_or_else(|| format!("mesh {}", mesh.index()), str::to_owned);
            objects.push(Object {
                name,
                mesh,
                node: None,
            });
        }
    }
    objects
}

/// The object named `name` (a node's name, or an unnamed node's mesh's),
/// else the mesh of that name through the first node that draws it.
pub(super) fn pick_object<'a>(
    document: &'a gltf::Document,
    name: &str,
) -> Result<Object<'a>, ObjectError> {
    let all = objects(document);
    let names: Vec<String> = all.iter().map(|o| o.name.clone()).collect();
    let ambiguous = |count| ObjectError::Ambiguous {
        name: name.to_owned(),
        count,
        names: names.clone(),
    };
    let by_node: Vec<Object> = all.into_iter().filter(|o| o.name == name).collect();
    if by_node.len() > 1 {
        return Err(ambiguous(by_node.len()));
    }
    if let Some(object) = by_node.into_iter().next() {
        return Ok(object);
    }
    let meshes: Vec<gltf::Mesh> = document
        .meshes()
        .filter(|m| m.name() == Some(name))
        .collect();
    match meshes.as_slice() {
        [] => Err(ObjectError::NotFound {
            name: name.to_owned(),
            names,
        }),
        [mesh] => Ok(Object {
            name: name.to_owned(),
            mesh: mesh.clone(),
            node: document
                .nodes()
                .find(|n| n.mesh().is_some_and(|m| m.index() == mesh.index()))
                .map(|n| n.index()),
        }),
        more => Err(ambiguous(more.len())),
    }
}

/// What was read where no object was asked for and the file has several:
/// the first mesh, through the first node that draws it.
pub(super) fn default_note(document: &gltf::Document, mesh: usize) -> Option<String> {
    let all = objects(document);
    if all.len() < 2 {
        return None;
    }
    let read = all.iter().find(|o| o.mesh.index() == mesh)?;
    let names: Vec<String> = all.iter().map(|o| o.name.clone()).collect();
    Some(format!(
        "the file has {}; the first mesh, object '{}', was read",
        object_list(&names),
        read.name
    ))
}

#[cfg(test)]
mod tests {
    use crate::formats::{load_mesh, load_mesh_object, LoadError};
    use base64::Engine as _;

    /// Two triangles, meshes 0 and 1 of one accessor, drawn by `nodes`.
    fn two_meshes(nodes: &str) -> String {
        let floats = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.];
        let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
        let uri = base64::engine::general_purpose::STANDARD.encode(bytes);
        let mesh = r#"{"name":"Tri","primitives":[{"attributes":{"POSITION":0}}]}"#;
        format!(
            r#"{{"asset":{{"version":"2.0"}},
            "buffers":[{{"byteLength":36,"uri":"data:application/octet-stream;base64,{uri}"}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}}],
            "meshes":[{mesh},{mesh}],
            "nodes":[{nodes}]}}"#
        )
    }

    #[test]
    fn an_object_is_picked_by_its_nodes_name_with_that_nodes_transform() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("two.gltf");
        let nodes = r#"{"name":"Left","mesh":0,"translation":[-5,0,0]},{"name":"Right","mesh":1,"translation":[5,0,0]}"#;
        std::fs::write(&path, two_meshes(nodes)).unwrap();
        let right = load_mesh_object(&path, Some("Right")).unwrap();
        assert_eq!(right.mesh.positions[0].x, 5.0);
        assert!(right.object_note.is_none());
        let first = load_mesh(&path).unwrap();
        assert_eq!(first.mesh.positions[0].x, -5.0);
        assert_eq!(
            first.object_note.as_deref(),
            Some(
                "the file has 2 objects: 'Left', 'Right'; the first mesh, object 'Left', was read"
            )
        );
        let error = load_mesh_object(&path, Some("Middle")).unwrap_err();
        assert!(matches!(error, LoadError::Object { .. }));
        assert!(
            error.to_string().ends_with(
                "two.gltf: no object is named 'Middle'; the file has 2 objects: 'Left', 'Right'"
            ),
            "{error}"
        );
        // Both meshes are named "Tri": by that name the choice is unclear.
        let error = load_mesh_object(&path, Some("Tri"))
            .unwrap_err()
            .to_string();
        assert!(error.contains("2 objects are named 'Tri'"), "{error}");
    }

    #[test]
    fn two_nodes_of_one_name_are_ambiguous_and_an_off_file_has_no_objects() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("twins.gltf");
        let nodes = r#"{"name":"Twin","mesh":0},{"name":"Twin","mesh":1}"#;
        std::fs::write(&path, two_meshes(nodes)).unwrap();
        let error = load_mesh_object(&path, Some("Twin"))
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("2 objects are named 'Twin'") && error.contains("'Twin', 'Twin'"),
            "{error}"
        );
        let off = dir.path().join("m.off");
        std::fs::write(&off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").unwrap();
        let error = load_mesh_object(&off, Some("a")).unwrap_err().to_string();
        assert!(
            error.contains("OFF files hold one unnamed object"),
            "{error}"
        );
        assert!(load_mesh_object(&off, None).is_ok());
    }
}
