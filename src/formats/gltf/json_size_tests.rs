//! [`JsonSize`] against what parsing really allocates: the test binary's
//! allocator counts, for the thread that asks, the most bytes held at once,
//! and every kind of JSON value gltf-json keeps (and some it ignores) must be
//! predicted at or above that.

use super::json_size::JsonSize;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting for a thread that asked it to.
struct Counting;

thread_local! {
    // Constant and without destructors: safe to use inside the allocator.
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static HELD: Cell<i64> = const { Cell::new(0) };
    static PEAK: Cell<i64> = const { Cell::new(0) };
}

fn counted(change: i64) {
    let _ = COUNTING.try_with(|counting| {
        if counting.get() {
            let held = HELD.with(|held| {
                held.set(held.get() + change);
                held.get()
            });
            PEAK.with(|peak| peak.set(peak.get().max(held)));
        }
    });
}

// SAFETY: every call is passed on to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        counted(layout.size() as i64);
        System.alloc(layout)
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        counted(layout.size() as i64);
        System.alloc_zeroed(layout)
    }

    unsafe fn dealloc(&self, pointer: *mut u8, layout: Layout) {
        counted(-(layout.size() as i64));
        System.dealloc(pointer, layout)
    }

    unsafe fn realloc(&self, pointer: *mut u8, layout: Layout, size: usize) -> *mut u8 {
        // Both held at once, as when the allocator copies.
        counted(size as i64);
        let moved = System.realloc(pointer, layout, size);
        counted(-(layout.size() as i64));
        moved
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The most bytes held at once by this thread while `parse` runs, over
/// what was held before.
fn peak_of<T>(parse: impl FnOnce() -> T) -> u64 {
    HELD.with(|held| held.set(0));
    PEAK.with(|peak| peak.set(0));
    COUNTING.with(|counting| counting.set(true));
    let kept = parse();
    COUNTING.with(|counting| counting.set(false));
    drop(kept);
    PEAK.with(Cell::get).max(0) as u64
}

/// Documents of `N` values of one kind each, in the places gltf-json keeps
/// them, and two it ignores.
fn documents() -> Vec<(&'static str, String)> {
    const N: usize = 20_000;
    let head = r#"{"asset":{"version":"2.0"},"#;
    let many = |item: &dyn Fn(usize) -> String| (0..N).map(item).collect::<Vec<_>>().join(",");
    let accessor = |min: String| {
        format!(
            r#"{head}"accessors":[{{"componentType":5126,"count":1,"type":"SCALAR","min":{min}}}]}}"#
        )
    };
    vec![
        (
            "empty strings",
            format!(r#"{head}"extensionsUsed":[{}]}}"#, many(&|_| "\"\"".into())),
        ),
        (
            "short strings",
            format!(
                r#"{head}"extensionsUsed":[{}]}}"#,
                many(&|_| "\"a\"".into())
            ),
        ),
        (
            "escaped strings",
            format!(
                r#"{head}"extensionsUsed":[{}]}}"#,
                many(&|_| "\"\\u0041\\n\"".into())
            ),
        ),
        (
            "numbers in min",
            accessor(format!("[{}]", many(&|_| "0".into()))),
        ),
        (
            "empty arrays in min",
            accessor(format!("[{}]", many(&|_| "[]".into()))),
        ),
        (
            "arrays of one in min",
            accessor(format!("[{}]", many(&|_| "[0]".into()))),
        ),
        (
            "empty objects in min",
            accessor(format!("[{}]", many(&|_| "{}".into()))),
        ),
        (
            "objects of one in min",
            accessor(format!("[{}]", many(&|_| r#"{"":0}"#.into()))),
        ),
        (
            "a wide object in min",
            accessor(format!("{{{}}}", many(&|k| format!(r#""{k:x}":0"#)))),
        ),
        (
            "extras in min",
            accessor(format!("[{}]", many(&|_| r#"{"extras":[""]}"#.into()))),
        ),
        (
            "extras under an escaped name",
            format!(
                r#"{head}"accessors":[{{"componentType":5126,"count":1,"type":"SCALAR","m\u0069n":[{}]}}]}}"#,
                many(&|_| format!(r#"{{"extras":[{}]}}"#, ["\"\""; 40].join(",")))
            ),
        ),
        (
            "nested objects in min",
            accessor(format!(
                "{{{}}}",
                many(&|k| format!(r#""{k:x}":{{"a":[0]}}"#))
            )),
        ),
        (
            "empty nodes",
            format!(r#"{head}"nodes":[{}]}}"#, many(&|_| "{}".into())),
        ),
        (
            "nodes with a child",
            format!(
                r#"{head}"nodes":[{}]}}"#,
                many(&|_| r#"{"children":[0]}"#.into())
            ),
        ),
        (
            "named nodes",
            format!(
                r#"{head}"nodes":[{}]}}"#,
                many(&|_| r#"{"name":"a"}"#.into())
            ),
        ),
        (
            "nodes with extras",
            format!(
                r#"{head}"nodes":[{}]}}"#,
                many(&|_| r#"{"extras":[0]}"#.into())
            ),
        ),
        (
            "children",
            format!(
                r#"{head}"nodes":[{{"children":[{}]}}]}}"#,
                many(&|_| "0".into())
            ),
        ),
        (
            "weights",
            format!(
                r#"{head}"nodes":[{{"weights":[{}]}}]}}"#,
                many(&|_| "0".into())
            ),
        ),
        (
            "materials",
            format!(
                r#"{head}"materials":[{}]}}"#,
                many(&|_| r#"{"pbrMetallicRoughness":{}}"#.into())
            ),
        ),
        (
            "meshes",
            format!(
                r#"{head}"meshes":[{}]}}"#,
                many(&|_| r#"{"primitives":[{"attributes":{"POSITION":0}}]}"#.into())
            ),
        ),
        (
            "attributes",
            format!(
                r#"{head}"meshes":[{{"primitives":[{{"attributes":{{{}}}}}]}}]}}"#,
                many(&|k| format!(r#""_{k:x}":0"#))
            ),
        ),
        (
            "morph targets",
            format!(
                r#"{head}"meshes":[{{"primitives":[{{"attributes":{{}},"targets":[{}]}}]}}]}}"#,
                many(&|_| "{}".into())
            ),
        ),
        (
            "animations",
            format!(
                r#"{head}"animations":[{}]}}"#,
                many(&|_| r#"{"channels":[],"samplers":[]}"#.into())
            ),
        ),
        (
            "scenes",
            format!(
                r#"{head}"scenes":[{}]}}"#,
                many(&|_| r#"{"nodes":[0]}"#.into())
            ),
        ),
        (
            "strings in extras",
            format!(r#"{head}"extras":[{}]}}"#, many(&|_| "\"\"".into())),
        ),
        (
            "deep extras",
            format!(r#"{head}"extras":{}0{}}}"#, "[".repeat(N), "]".repeat(N)),
        ),
        (
            "an unknown member",
            format!(r#"{head}"unknown":[{}]}}"#, many(&|_| "\"\"".into())),
        ),
        (
            "extensions",
            format!(
                r#"{head}"extensions":{{"x":[{}]}}}}"#,
                many(&|_| "\"\"".into())
            ),
        ),
        (
            "a scene",
            format!(
                r#"{head}"nodes":[{}],"accessors":[{}],"meshes":[{}]}}"#,
                many(&|k| format!(
                    r#"{{"name":"node_{k}","mesh":{},"translation":[1.5,2,3],"rotation":[0,0,0,1],"scale":[1,1,1],"children":[{}]}}"#,
                    k % 50,
                    k + 1
                )),
                many(&|_| {
                    r#"{"bufferView":3,"byteOffset":1200,"componentType":5126,"count":1234,"type":"VEC3","min":[-1.2,-3.4,-5.6],"max":[1,2,3]}"#.into()
                }),
                many(&|k| format!(
                    r#"{{"name":"mesh_{k}","primitives":[{{"attributes":{{"POSITION":{k},"NORMAL":{k},"TEXCOORD_0":{k}}},"indices":{k},"material":0}}]}}"#
                )),
            ),
        ),
    ]
}

#[test]
fn every_kind_of_json_value_is_predicted_at_or_above_what_parsing_holds() {
    for (what, json) in documents() {
        let predicted = JsonSize::of(json.as_bytes()).bytes;
        let peak =
            peak_of(|| gltf::json::deserialize::from_slice::<gltf::json::Root>(json.as_bytes()));
        assert!(
            predicted >= peak,
            "{what}: {predicted} bytes predicted, {peak} held ({} bytes of JSON)",
            json.len()
        );
        // Not so far above as to refuse what fits.
        if what == "a scene" {
            assert!(
                predicted <= 8 * peak,
                "{what}: {predicted} predicted, {peak} held"
            );
        }
    }
}

#[test]
fn the_counter_counts() {
    let peak = peak_of(|| vec![0u8; 1 << 20]);
    assert!(peak >= 1 << 20, "{peak}");
}
