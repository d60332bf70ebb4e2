//! Sessions mutated at random (types, ranges, sizes, a byte-order mark, missing
//! keys, huge numbers, deep nesting, long strings) and read through the library's
//! loader: never a panic; either a clean error naming the file, or a session that
//! says what the file says (or a notice for what it changed). And inputs that
//! would exhaust memory (a device as a mesh) give a clean error under an
//! address-space limit instead of an abort.

use crate::common;

use common::{comb_session, Random};
use pmvc::app::scenes::BundledScene;
use pmvc::app::session::open_session;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

fn odd_value(random: &mut Random) -> Value {
    match random.below(14) {
        0 => Value::Null,
        1 => json!(true),
        2 => json!(-1),
        3 => json!(0),
        4 => json!(4_294_967_296u64),
        5 => json!(u64::MAX),
        6 => json!(1e308),
        7 => json!(-1e308),
        8 => json!(1e-300),
        9 => json!(""),
        10 => json!("x".repeat(200_000)),
        11 => json!([]),
        12 => json!({}),
        _ => json!([[1.0, 2.0, 3.0], [1.0, 2.0, 3.0], [1.0, 2.0, 3.0]]),
    }
}

/// Every path into `value` (object keys and array indices), breadth first.
fn paths(value: &Value) -> Vec<Vec<Value>> {
    let mut found = vec![Vec::new()];
    let mut next = 0;
    while next < found.len() && found.len() < 5_000 {
        let path = found[next].clone();
        next += 1;
        let children: Vec<Value> = match lookup(value, &path) {
            Some(Value::Object(map)) => map.keys().map(|k| json!(k)).collect(),
            Some(Value::Array(items)) => (0..items.len()).map(|i| json!(i)).collect(),
            _ => Vec::new(),
        };
        for child in children {
            let mut longer = path.clone();
            longer.push(child);
            found.push(longer);
        }
    }
    found
}

fn lookup<'a>(value: &'a Value, path: &[Value]) -> Option<&'a Value> {
    path.iter().try_fold(value, |node, step| match step {
        Value::String(key) => node.get(key),
        Value::Number(index) => node.get(index.as_u64()? as usize),
        _ => None,
    })
}

fn lookup_mut<'a>(value: &'a mut Value, path: &[Value]) -> Option<&'a mut Value> {
    path.iter().try_fold(value, |node, step| match step {
        Value::String(key) => node.get_mut(key),
        Value::Number(index) => node.get_mut(index.as_u64()? as usize),
        _ => None,
    })
}

/// One random mutation of `session`, as file text, and what it was.
fn mutate(session: &Value, random: &mut Random) -> (String, String) {
    let mut value = session.clone();
    let all = paths(&value);
    let path = all[1 + random.below(all.len() - 1)].clone();
    let kind = random.below(8);
    let described = format!("kind {kind} at {path:?}");
    match kind {
        0..=2 => {
            let odd = odd_value(random);
            if let Some(node) = lookup_mut(&mut value, &path) {
                *node = odd;
            }
        }
        3 => {
            let (parent, last) = path.split_at(path.len() - 1);
            match (lookup_mut(&mut value, parent), &last[0]) {
                (Some(Value::Object(map)), Value::String(key)) => {
                    map.remove(key);
                }
                (Some(Value::Array(items)), Value::Number(index)) => {
                    items.remove(index.as_u64().unwrap() as usize);
                }
                _ => {}
            }
        }
        4 => {
            // Deeper than any parser should follow.
            let mut deep = json!(1);
            for _ in 0..(100 + random.below(400)) {
                deep = json!([deep]);
            }
            if let Some(node) = lookup_mut(&mut value, &path) {
                *node = deep;
            }
        }
        5 => {
            if let Some(node) = lookup_mut(&mut value, &path) {
                if let Some(number) = node.as_f64() {
                    let scale = [1e6, -1.0, 1e-12, 3.0][random.below(4)];
                    *node = json!(number * scale);
                }
            }
        }
        _ => {}
    }
    let mut text = serde_json::to_string_pretty(&value).unwrap_or_default();
    match kind {
        6 => text.insert(0, '\u{feff}'),
        7 => {
            let mut cut = random.below(text.len());
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            text.truncate(cut);
        }
        _ => {}
    }
    (text, described)
}

/// What a session that opened must show: what the file says, or a notice.
fn check_faithful(file: &Value, opened: &pmvc::app::session::OpenedSession, what: &str) {
    let notes = opened.notes.join("\n");
    let options = opened.settings.bind_options;
    for (key, loaded) in [("resolution", options.resolution), ("grid", options.grid)] {
        if let Some(written) = file["parameters"].get(key) {
            assert_eq!(written.as_u64(), Some(loaded.into()), "{what}: {key}");
        }
    }
    let title = opened.document.title();
    if file["title"].as_str() != Some(title) {
        assert!(notes.contains("title"), "{what}: title changed silently");
    }
    let handle_size = opened.settings.view.handle_size;
    assert!(
        pmvc::app::compare::HANDLE_SIZES.contains(&handle_size),
        "{what}: handle size {handle_size}"
    );
    if let Some(written) = file["view"]["handle_size"].as_f64() {
        if written as f32 != handle_size {
            assert!(notes.contains("handle_size"), "{what}: {notes}");
        }
    }
    let pose = opened.document.pose();
    assert_eq!(pose.len(), opened.document.cage().vertex_count(), "{what}");
    assert!(
        pose.iter().all(|p| p.is_finite() && p.length() < 1e6),
        "{what}: pose {pose:?}"
    );
    for camera in &opened.settings.cameras {
        assert!(
            camera.target.is_finite()
                && camera.target.length() < 1e6
                && camera.distance > 0.0
                && camera.distance < 1e6
                && camera.yaw.is_finite()
                && camera.pitch.abs() < 1.6,
            "{what}: camera {camera:?}"
        );
    }
}

#[test]
fn mutated_sessions_open_faithfully_or_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let reference = comb_session();
    let mut random = Random(0x5eed_1234_abcd_0001);
    let (mut opened_count, mut refused_count) = (0, 0);
    for round in 0..300 {
        let (text, described) = mutate(&reference, &mut random);
        let name = format!("mutated-{round}.json");
        let path = dir.path().join(&name);
        std::fs::write(&path, &text).unwrap();
        let what = format!("{name} ({described})");
        let result = std::panic::catch_unwind(|| open_session(&path))
            .unwrap_or_else(|_| panic!("{what}: the loader panicked"));
        match result {
            Ok(opened) => {
                opened_count += 1;
                let file: Value =
                    serde_json::from_str(text.trim_start_matches('\u{feff}')).unwrap();
                check_faithful(&file, &opened, &what);
            }
            Err(error) => {
                refused_count += 1;
                let message = error.to_string();
                assert!(message.contains(&name), "{what}: {message}");
                assert!(!message.contains('\n'), "{what}: one line: {message}");
                assert!(message.len() < 2_000, "{what}: {} bytes", message.len());
            }
        }
    }
    // Both outcomes were exercised, so neither check above is vacuous.
    assert!(
        opened_count > 20 && refused_count > 20,
        "{opened_count} opened, {refused_count} refused"
    );
}

#[test]
fn raw_nesting_and_garbage_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        "[".repeat(1_000_000),
        "{\"a\":".repeat(100_000),
        "\u{feff}".to_owned(),
        "\u{feff}\u{feff}{}".to_owned(),
        String::from_utf8_lossy(&[0xff, 0xfe, 0x00, 0x7b]).into_owned(),
        String::new(),
    ];
    for (index, text) in cases.iter().enumerate() {
        let path = dir.path().join(format!("garbage-{index}.json"));
        std::fs::write(&path, text).unwrap();
        let error = open_session(&path).err().expect("refused").to_string();
        assert!(error.contains(&format!("garbage-{index}.json")), "{error}");
    }
}

#[cfg(unix)]
/// An address-space limit for the children below: far less than reading a
/// device to its end needs, far more than a clean refusal needs.
const ADDRESS_SPACE_KIB: u64 = 1 << 20;

#[cfg(unix)]
/// `program args…` with its address space limited to `ADDRESS_SPACE_KIB`.
fn limited(program: &Path, args: &[&str]) -> std::process::Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {ADDRESS_SPACE_KIB} && exec \"$0\" \"$@\""
        ))
        .arg(program)
        .args(args)
        .env("RAYON_NUM_THREADS", "2")
        .output()
        .expect("run sh")
}

#[cfg(unix)]
/// A cage file for the commands below.
fn write_cage(dir: &Path) -> PathBuf {
    let (_, cage) = BundledScene::Comb.build().unwrap();
    let mut text = String::new();
    for p in cage.positions() {
        text.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    for [a, b, c] in cage.triangles() {
        text.push_str(&format!("f {} {} {}\n", a + 1, b + 1, c + 1));
    }
    let path = dir.join("cage.obj");
    std::fs::write(&path, text).unwrap();
    path
}

#[cfg(unix)]
#[test]
fn pmvc_check_on_a_device_fails_cleanly_under_an_address_space_limit() {
    let dir = tempfile::tempdir().unwrap();
    let cage = write_cage(dir.path());
    let zero = dir.path().join("zero.obj");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    let output = limited(
        Path::new(env!("CARGO_BIN_EXE_pmvc")),
        &[
            "check",
            "--mesh",
            zero.to_str().unwrap(),
            "--cage",
            cage.to_str().unwrap(),
        ],
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("zero.obj"), "{stderr}");
    assert!(stderr.contains("binary data near byte 0"), "{stderr}");
}

/// Endless text on a pipe (`yes "v 0 0 0" | pmvc check --mesh stream.obj`, where
/// stream.obj leads to standard input) is read up to a limit, then refused.
#[cfg(target_os = "linux")]
#[test]
fn pmvc_check_on_endless_text_fails_cleanly_under_an_address_space_limit() {
    let dir = tempfile::tempdir().unwrap();
    let cage = write_cage(dir.path());
    let stream = dir.path().join("stream.obj");
    std::os::unix::fs::symlink("/dev/stdin", &stream).unwrap();
    let output = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {ADDRESS_SPACE_KIB} && yes 'v 0 0 0' | \"$0\" \"$@\""
        ))
        .arg(env!("CARGO_BIN_EXE_pmvc"))
        .args([
            "check",
            "--mesh",
            stream.to_str().unwrap(),
            "--cage",
            cage.to_str().unwrap(),
        ])
        .output()
        .expect("run sh");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("stream.obj"), "{stderr}");
    assert!(stderr.contains("not a regular file"), "{stderr}");
}

/// Run by the test below in a child process: opens the session named by
/// `PMVC_TEST_SESSION` and prints how it ended.
#[test]
fn child_opens_the_session_named_by_its_environment() {
    let Ok(path) = std::env::var("PMVC_TEST_SESSION") else {
        return;
    };
    match open_session(Path::new(&path)) {
        Ok(_) => println!("CHILD: opened"),
        Err(error) => println!("CHILD: refused: {error}"),
    }
}

#[cfg(unix)]
#[test]
fn a_session_naming_a_device_fails_cleanly_under_an_address_space_limit() {
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.obj")).unwrap();
    let mut session = comb_session();
    session["mesh"] = json!({"file": "zero.obj"});
    let path = dir.path().join("zero.json");
    std::fs::write(&path, serde_json::to_string(&session).unwrap()).unwrap();
    let test_binary = std::env::current_exe().unwrap();
    let output = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {ADDRESS_SPACE_KIB} && exec \"$0\" \"$@\""
        ))
        .arg(&test_binary)
        .args([
            "--exact",
            // The test's name as the harness lists it: its path below the crate root.
            concat!(
                module_path!(),
                "::child_opens_the_session_named_by_its_environment"
            )
            .split_once("::")
            .unwrap()
            .1,
            "--nocapture",
            "--test-threads=1",
        ])
        .env("PMVC_TEST_SESSION", &path)
        .output()
        .expect("run the test binary");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stdout}\n{stderr}");
    assert!(stdout.contains("CHILD: refused: "), "{stdout}");
    assert!(stdout.contains("zero.obj"), "{stdout}");
    // Stopped at the first zero, not when memory ran out.
    assert!(stdout.contains("binary data near byte 0"), "{stdout}");
}
