//! What the glTF reader refuses: node graphs that are not a forest, partial
//! triangles, named pipes as buffers, and documents larger in memory than
//! their size tells.

use super::tests::{gltf_error, triangle_json, triangle_uri};
use super::*;
use crate::formats::{load_mesh, LoadError};

/// The x extent of what `json` reads as.
fn width(json: &str) -> Result<f64, LoadError> {
    let read = parse_gltf(Path::new("graph.gltf"), json.as_bytes(), &MeshPick::First)?;
    let xs = read.mesh.positions.iter().map(|p| p.x);
    Ok(xs.clone().fold(f64::MIN, f64::max) - xs.fold(f64::MAX, f64::min))
}

#[test]
fn a_node_hierarchy_that_is_not_a_forest_is_refused_naming_the_nodes() {
    // A valid hierarchy: scale 2 under a parent, the triangle twice as wide.
    let nodes = r#"{"mesh":0,"scale":[2,2,2]},{"children":[0]}"#;
    assert_eq!(
        width(&triangle_json(&triangle_uri(), 0, nodes)).unwrap(),
        2.0
    );
    let cases = [
        // Read as 4 units wide before: the scale applied twice.
        (
            r#"{"mesh":0,"scale":[2,2,2],"children":[0]}"#,
            "node 0 is a child of itself",
        ),
        (
            r#"{"mesh":0,"scale":[2,2,2],"children":[1]},{"children":[0]}"#,
            "nodes 0 and 1 form a cycle: node 0 lists child 1, node 1 lists child 0",
        ),
        (
            r#"{},{"children":[2]},{"children":[3]},{"mesh":0,"children":[1]}"#,
            "nodes 1, 2 and 3 form a cycle: node 1 lists child 2, node 2 lists child 3, node 3 lists child 1",
        ),
        (
            r#"{"mesh":0},{"children":[0]},{"children":[0]}"#,
            "node 0 has two parents: nodes 1 and 2",
        ),
        (
            r#"{"mesh":0},{"children":[0,0]}"#,
            "node 1 lists child 0 twice",
        ),
        (
            r#"{"mesh":0},{},{"children":[9]},{}"#,
            "node 2 lists child 9, but the file has 4 nodes",
        ),
    ];
    for (nodes, expected) in cases {
        let json = triangle_json(&triangle_uri(), 0, nodes);
        match width(&json) {
            Err(LoadError::Gltf { message, .. }) => {
                assert_eq!(message, expected, "for nodes {nodes}")
            }
            other => panic!("nodes {nodes} read as {other:?}, not refused"),
        }
    }
}

/// Four vertices (a unit square's corners) and the u16 indices `indices`, in
/// one data: URI buffer: positions at 0, indices at 48.
fn square_json(indices: Option<&[u16]>, mode: u32) -> String {
    use base64::Engine as _;
    let floats = [0f32, 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.];
    let mut bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    let list = indices.unwrap_or_default();
    bytes.extend(list.iter().flat_map(|i| i.to_le_bytes()));
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bytes)
    );
    let indexed = match indices {
        Some(_) => r#","indices":1"#,
        None => "",
    };
    format!(
        r#"{{"asset":{{"version":"2.0"}},
        "buffers":[{{"byteLength":{length},"uri":"{uri}"}}],
        "bufferViews":[{{"buffer":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":{index_bytes}}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"}},
            {{"bufferView":1,"componentType":5123,"count":{count},"type":"SCALAR"}}],
        "meshes":[{{"name":"quad","primitives":[{{"attributes":{{"POSITION":0}}{indexed},"mode":{mode}}}]}}]}}"#,
        length = bytes.len(),
        index_bytes = 2 * list.len().max(1),
        count = list.len().max(1),
    )
}

#[test]
fn triangles_whose_index_count_is_not_a_multiple_of_three_are_refused() {
    let path = Path::new("quad.gltf");
    let read = |json: &str| parse_gltf(path, json.as_bytes(), &MeshPick::First);
    let six = read(&square_json(Some(&[0, 1, 2, 0, 2, 3]), 4)).unwrap();
    assert_eq!(six.mesh.triangles.len(), 2);
    // Before: the fourth index was dropped without a word.
    let message = gltf_error(path, &square_json(Some(&[0, 1, 2, 3]), 4));
    assert_eq!(
        message,
        "mesh 0 primitive 0: accessor 1 holds 4 indices, not a multiple of 3 as TRIANGLES needs"
    );
    let message = gltf_error(path, &square_json(None, 4));
    assert_eq!(
        message,
        "mesh 0 primitive 0: accessor 0 (POSITION) holds 4 vertices and there are no indices, \
         but TRIANGLES needs a multiple of 3"
    );
    // Strips, fans and points take any count.
    for mode in [0, 5, 6] {
        assert!(
            read(&square_json(Some(&[0, 1, 2, 3]), mode)).is_ok(),
            "mode {mode}"
        );
        assert!(read(&square_json(None, mode)).is_ok(), "mode {mode}");
    }
}

/// Runs `parse` on a thread and waits at most `seconds` for it; `unblock` is
/// called before failing, to let a blocked thread go.
fn within<T: Send + 'static>(
    seconds: u64,
    parse: impl FnOnce() -> T + Send + 'static,
    unblock: impl FnOnce(),
) -> T {
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = send.send(parse());
    });
    match receive.recv_timeout(std::time::Duration::from_secs(seconds)) {
        Ok(result) => result,
        Err(_) => {
            unblock();
            panic!("still reading after {seconds} s");
        }
    }
}

#[cfg(unix)]
#[test]
fn a_named_pipe_as_a_buffer_file_is_refused_without_opening_it() {
    let dir = tempfile::tempdir().unwrap();
    let pipe = dir.path().join("pipe.bin");
    let made = std::process::Command::new("mkfifo")
        .arg(&pipe)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    let json = triangle_json("pipe.bin", 0, "{}")
        .replace(r#""byteLength":36,"uri""#, r#""byteLength":0,"uri""#);
    let path = dir.path().join("piped.gltf");
    std::fs::write(&path, &json).unwrap();
    let reading = path.clone();
    let result = within(
        10,
        move || load_mesh(&reading).map(|_| ()).map_err(|e| e.to_string()),
        || {
            // Opening the write end lets a reader blocked in open go on.
            let _ = std::fs::OpenOptions::new().write(true).open(&pipe);
        },
    );
    let message = result.unwrap_err();
    assert_eq!(
        message,
        format!(
            "{}: buffer 0 (\"pipe.bin\"): it is a named pipe, not a regular file; \
             buffers are read from regular files only",
            path.display()
        )
    );
}

#[test]
fn a_document_of_many_empty_strings_is_predicted_past_a_small_limit() {
    use super::json_size::JsonSize;
    // A 3 MiB JSON whose 1 Mi strings become a 24-byte String each in a Vec
    // that may have twice the room (the 540 MB file of 180 million aborted
    // on a 6 GB allocation).
    let count = 1 << 20;
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":[{}""]}}"#,
        "\"\",".repeat(count - 1)
    );
    let size = JsonSize::of(json.as_bytes());
    let limit: u64 = 32 << 20;
    assert!(
        size.bytes > limit,
        "{} predicted for {} bytes of JSON",
        size.bytes,
        json.len()
    );
    assert!(size.bytes >= 48 * count as u64, "{}", size.bytes);
    // And "2.0"; the members' names are not kept.
    assert_eq!(size.strings, count as u64 + 1);
    assert!(
        size.describe().contains(&format!("{} strings", count + 1)),
        "{}",
        size.describe()
    );
}
