//! Reading sessions through the library's loader: every value is checked by the
//! rule its control uses (a parameter by its family's spec, a view value by its
//! menu's range), long text is cut with a notice, the file is read with a size
//! limit, and messages number what they name as the file writes it.

use crate::common;

use common::comb_session;
use pmvc::app::session::{open_session, OpenedSession};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn open(dir: &Path, name: &str, session: &Value) -> Result<OpenedSession, String> {
    let path = write(dir, name, &serde_json::to_string_pretty(session).unwrap());
    open_session(&path).map_err(|error| error.to_string())
}

fn refused(dir: &Path, name: &str, session: &Value) -> String {
    match open(dir, name, session) {
        Ok(_) => panic!("{name} opened"),
        Err(error) => {
            assert!(error.contains(name), "{error}");
            error
        }
    }
}

#[test]
fn the_reference_session_opens() {
    let dir = tempfile::tempdir().unwrap();
    let opened = open(dir.path(), "good.json", &comb_session()).unwrap();
    assert_eq!(opened.settings.bind_options.resolution, 16);
    assert_eq!(opened.settings.bind_options.grid, 32);
    assert!(opened.notes.is_empty(), "{:?}", opened.notes);
}

#[test]
fn parameters_outside_their_families_range_are_refused_by_name_value_and_range() {
    let dir = tempfile::tempdir().unwrap();
    for (key, value, range) in [
        ("resolution", 100_000u64, "1 to 1024"),
        ("resolution", 0, "1 to 1024"),
        ("grid", 4_294_967_295, "4 to 2048"),
        ("grid", 3, "4 to 2048"),
    ] {
        let mut session = comb_session();
        session["parameters"][key] = json!(value);
        let error = refused(dir.path(), &format!("{key}-{value}.json"), &session);
        assert!(error.contains(&format!("{key} {value}")), "{error}");
        assert!(error.contains(range), "{error}");
    }
    let mut session = comb_session();
    session["parameters"]["grid"] = json!(2048);
    let opened = open(dir.path(), "largest.json", &session).unwrap();
    assert_eq!(opened.settings.bind_options.grid, 2048);
}

#[test]
fn long_titles_and_pose_names_are_cut_with_a_notice() {
    let dir = tempfile::tempdir().unwrap();
    let mut session = comb_session();
    session["title"] = json!("t".repeat(1_000_000));
    session["named_poses"][0]["name"] = json!("é".repeat(100_000));
    let opened = open(dir.path(), "long.json", &session).unwrap();
    let title = opened.document.title();
    assert!(title.chars().count() <= 200, "{} characters", title.len());
    assert!(title.starts_with("ttt"), "{title}");
    let name = &opened.document.named_poses()[0].name;
    assert!(name.chars().count() <= 200, "{} characters", name.len());
    assert!(name.starts_with("ééé"), "{name}");
    let notes = opened.notes.join("\n");
    assert!(notes.contains("the title"), "{notes}");
    assert!(notes.contains("1000000 characters"), "{notes}");
    assert!(notes.contains("named pose 1"), "{notes}");
}

#[test]
fn a_session_larger_than_any_session_is_refused_before_it_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.json");
    let file = std::fs::File::create(&path).unwrap();
    file.set_len(1 << 30).unwrap(); // sparse: nothing is written
    let error = open_session(&path).err().expect("refused").to_string();
    assert!(error.contains("huge.json"), "{error}");
    assert!(error.contains("1.0 GiB"), "{error}");
    assert!(error.contains("MiB"), "names the limit: {error}");
}

#[test]
fn a_session_with_a_byte_order_mark_opens() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "\u{feff}{}",
        serde_json::to_string_pretty(&comb_session()).unwrap()
    );
    let path = write(dir.path(), "bom.json", &text);
    let opened = open_session(&path).map_err(|e| e.to_string()).unwrap();
    assert_eq!(opened.document.title(), "comb");
}

/// A cube of 8 positions and 12 triangles, as a session writes an edited cage.
fn inline_cube(triangles: Vec<[u32; 3]>) -> Value {
    let positions: Vec<[f64; 3]> = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    json!({"inline": {"positions": positions, "triangles": triangles}})
}

fn cube_triangles() -> Vec<[u32; 3]> {
    vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ]
}

#[test]
fn an_inline_cage_is_described_with_the_indices_the_file_uses() {
    let dir = tempfile::tempdir().unwrap();
    let with_cube = |triangles| {
        let mut session = comb_session();
        session["cage"] = inline_cube(triangles);
        session["pose"] = session["cage"]["inline"]["positions"].clone();
        session["named_poses"] = json!([]);
        session
    };
    open(dir.path(), "cube.json", &with_cube(cube_triangles())).expect("the cube is a cage");

    let mut triangles = cube_triangles();
    triangles[4] = [0, 1, 99];
    let error = refused(dir.path(), "index.json", &with_cube(triangles));
    assert!(error.contains("99"), "{error}");
    assert!(
        !error.contains("100"),
        "an index written 99 is not 100: {error}"
    );
    assert!(error.contains("triangle 5"), "{error}");
    assert!(error.contains("0 to 7"), "{error}");

    // A degenerate triangle names its corners as written, from 0.
    let mut triangles = cube_triangles();
    triangles[0] = [0, 0, 1];
    let error = refused(dir.path(), "degenerate.json", &with_cube(triangles));
    assert!(error.contains("0, 0, 1"), "{error}");
}

#[test]
fn view_values_outside_their_controls_ranges_are_clamped_with_a_notice() {
    let dir = tempfile::tempdir().unwrap();
    let mut session = comb_session();
    session["view"] = json!({"handle_size": 1e30, "difference_limit": 1e30});
    session["cameras"] =
        json!([{"target": [0.0, 0.0, 0.0], "distance": 1e-30, "yaw": 0.0, "pitch": 0.0}]);
    let opened = open(dir.path(), "view.json", &session).unwrap();
    let view = opened.settings.view;
    assert_eq!(view.handle_size, 12.0);
    assert!(view.difference_limit.is_some_and(|limit| limit <= 1.0));
    let camera = opened.settings.cameras[0];
    assert!(camera.distance >= 1e-3, "{}", camera.distance);
    let notes = opened.notes.join("\n");
    assert!(notes.contains("handle_size"), "{notes}");
    assert!(notes.contains("1.5 to 12"), "{notes}");
    assert!(notes.contains("difference_limit"), "{notes}");
    assert!(notes.contains("distance"), "{notes}");

    // A camera far beyond the cage is brought back to it.
    let mut session = comb_session();
    session["cameras"] =
        json!([{"target": [1e30, 0.0, 0.0], "distance": 1e30, "yaw": 1e30, "pitch": 0.0}]);
    let opened = open(dir.path(), "far.json", &session).unwrap();
    let camera = opened.settings.cameras[0];
    assert!(camera.target.length() < 1e3, "{:?}", camera.target);
    assert!(camera.distance < 1e4, "{}", camera.distance);
    assert!(camera.yaw.abs() <= std::f32::consts::TAU, "{}", camera.yaw);
    let notes = opened.notes.join("\n");
    assert!(notes.contains("target"), "{notes}");
}

#[test]
fn poses_far_beyond_the_cage_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut session = comb_session();
    session["pose"][3][1] = json!(1e308);
    let error = refused(dir.path(), "far-pose.json", &session);
    assert!(error.contains("the pose"), "{error}");
    assert!(error.contains("position 4"), "{error}");
    assert!(error.contains("cage diagonals"), "{error}");

    let mut session = comb_session();
    session["named_poses"][0]["positions"][0][0] = json!(-1e12);
    let error = refused(dir.path(), "far-named.json", &session);
    assert!(error.contains("named pose 1"), "{error}");
}

#[cfg(unix)]
#[test]
fn a_session_naming_a_device_as_its_mesh_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let zero = dir.path().join("zero.obj");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    let mut session = comb_session();
    session["mesh"] = json!({"file": "zero.obj"});
    let error = refused(dir.path(), "zero.json", &session);
    assert!(error.contains("zero.obj"), "{error}");
    assert!(error.contains("binary data near byte 0"), "{error}");
}

/// A scene a million units from the origin: the camera's target comes back from
/// the file, and goes back to it, as it was (f32 world coordinates there are
/// 0.0625 apart).
#[test]
fn a_camera_far_from_the_origin_keeps_its_target_through_open_and_save() {
    use pmvc::app::session::save_session;
    use pmvc::render::SceneOrigin;
    let dir = tempfile::tempdir().unwrap();
    let offset = 1.0e6;
    let mut cage = String::new();
    for corner in 0..8 {
        let at = |bit: usize| offset + if corner & bit != 0 { 1.0 } else { -1.0 };
        cage += &format!("v {} {} {}\n", at(4), at(2), at(1));
    }
    cage += "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n";
    write(dir.path(), "cage.obj", &cage);
    let mesh = format!(
        "v {offset} {offset} {offset}\nv {} {offset} {offset}\n",
        offset + 0.5
    );
    write(dir.path(), "mesh.obj", &mesh);
    let target = [offset + 0.123456, offset + 0.5, offset - 0.25];
    let pose: Vec<[f64; 3]> = (0..8)
        .map(|corner| {
            let at = |bit: usize| offset + if corner & bit != 0 { 1.0 } else { -1.0 };
            [at(4), at(2), at(1)]
        })
        .collect();
    let session = json!({
        "pmvc_session": 1,
        "title": "far",
        "mesh": {"file": "mesh.obj"},
        "cage": {"file": "cage.obj"},
        "pose": pose,
        "method": "mvc",
        "cameras": [{"target": target, "distance": 6.0, "yaw": 0.3, "pitch": 0.2}],
    });
    let opened = open(dir.path(), "far.json", &session).unwrap();
    let origin = SceneOrigin::of_cage(opened.document.cage().positions());
    let world = origin.to_world(opened.settings.cameras[0].target);
    let error = (world - glam::DVec3::from_array(target)).length();
    assert!(
        error < 1e-6,
        "opened {world:?} for {target:?}: {error:e} off"
    );

    let saved = dir.path().join("saved.json");
    save_session(&saved, &opened.document, &opened.settings).unwrap();
    let written: Value = serde_json::from_str(&std::fs::read_to_string(&saved).unwrap()).unwrap();
    let back: Vec<f64> = serde_json::from_value(written["cameras"][0]["target"].clone()).unwrap();
    let error = (glam::DVec3::from_slice(&back) - glam::DVec3::from_array(target)).length();
    assert!(error < 1e-6, "saved {back:?} for {target:?}: {error:e} off");
}

#[test]
fn numbers_past_f32_are_brought_into_range_with_a_notice() {
    let dir = tempfile::tempdir().unwrap();
    let mut session = comb_session();
    session["cameras"][0]["distance"] = json!(1e39);
    session["view"]["handle_size"] = json!(-1e40);
    let opened = open(dir.path(), "far.json", &session).unwrap();
    let notes = opened.notes.join("\n");
    assert!(notes.contains("cameras[0].distance"), "{notes}");
    assert!(notes.contains("view.handle_size"), "{notes}");
    let camera = opened.settings.cameras[0];
    assert!(camera.distance.is_finite(), "{}", camera.distance);
}

#[cfg(unix)]
#[test]
fn a_named_pipe_is_refused_instead_of_waited_on() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("piped.json");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|status| status.success()) {
        eprintln!("not run: no mkfifo");
        return;
    }
    // No writer: opening it for reading would wait forever.
    let (sender, receiver) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        sender.send(open_session(&fifo).map(|_| ()).map_err(|e| e.to_string()))
    });
    let answer = receiver
        .recv_timeout(std::time::Duration::from_secs(20))
        .expect("the loader waited on a named pipe");
    let error = answer.expect_err("a named pipe opened as a session");
    assert!(
        error.contains("piped.json") && error.contains("named pipe"),
        "{error}"
    );
}

#[cfg(unix)]
#[test]
fn a_session_opened_through_a_link_reads_its_files_beside_the_target() {
    let dir = tempfile::tempdir().unwrap();
    let (scenes, links) = (dir.path().join("scenes"), dir.path().join("links"));
    std::fs::create_dir_all(&scenes).unwrap();
    std::fs::create_dir_all(&links).unwrap();
    let (_, cage) = pmvc::app::scenes::BundledScene::Comb.build().unwrap();
    std::fs::write(scenes.join("cage.obj"), common::cage_obj(&cage)).unwrap();
    let mut session = comb_session();
    session["cage"] = json!({"file": "cage.obj"});
    let target = write(&scenes, "s.json", &serde_json::to_string(&session).unwrap());
    let link = links.join("s.json");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let opened = open_session(&link).map_err(|e| e.to_string()).unwrap();
    let notes = opened.notes.join("\n");
    assert!(
        notes.contains("a link to") && notes.contains("scenes"),
        "{notes}"
    );
}

#[test]
fn two_editors_saving_one_session_leave_one_whole_session() {
    use pmvc::app::session::save_session;
    let dir = tempfile::tempdir().unwrap();
    let mut first = comb_session();
    first["title"] = json!("first");
    let mut second = comb_session();
    second["title"] = json!("second");
    let first = open(dir.path(), "a.json", &first).unwrap();
    let second = open(dir.path(), "b.json", &second).unwrap();
    let shared = dir.path().join("shared.json");
    // Two writers, as two editors with the same session open would be: each
    // write replaces the file whole, so a reader never sees a mix or a part.
    let writing = std::sync::atomic::AtomicUsize::new(2);
    let mut reads = 0;
    std::thread::scope(|scope| {
        for opened in [&first, &second] {
            let (shared, writing) = (&shared, &writing);
            scope.spawn(move || {
                for _ in 0..40 {
                    save_session(shared, &opened.document, &opened.settings).unwrap();
                }
                writing.fetch_sub(1, std::sync::atomic::Ordering::SeqCst);
            });
        }
        while writing.load(std::sync::atomic::Ordering::SeqCst) > 0 {
            // Once the file exists it is always a whole session.
            if !shared.exists() {
                continue;
            }
            let read = open_session(&shared).map_err(|e| e.to_string()).unwrap();
            assert!(["first", "second"].contains(&read.document.title()));
            reads += 1;
        }
    });
    assert!(reads > 0, "no read happened while the writers wrote");
    let last = open_session(&shared).map_err(|e| e.to_string()).unwrap();
    assert!(["first", "second"].contains(&last.document.title()));
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| !name.ends_with(".json"))
        .collect();
    assert!(left.is_empty(), "files left behind: {left:?}");
}
