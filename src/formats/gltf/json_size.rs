//! What parsing a glTF's JSON will hold in memory, predicted before it is
//! parsed, from one pass over its bytes that allocates nothing.
//!
//! gltf-json (through serde_json) keeps a JSON text as:
//!
//! - objects: a struct (an accessor, a node…), alone or in a `Vec`; a
//!   primitive's `attributes` as a map; an accessor's `min` and `max` as
//!   [`serde_json::Value`]s, whose objects are maps of `String`s to `Value`s;
//! - arrays: a `Vec` of structs, of `String`s (`extensionsUsed`), of numbers
//!   (`children`, `weights`), or of `Value`s;
//! - strings: a `String` (24 bytes, and its text on the heap); numbers,
//!   `true`, `false` and `null`: a slot of a struct, a `Vec` or a map;
//! - `extras`: a copy of its text (`Box<RawValue>`);
//! - what gltf-json has no field for (unknown members, the `extensions` of
//!   extensions not compiled in): nothing.
//!
//! A `Vec` built by pushing has room for up to twice its elements, and while
//! it grows both its old and its new room may be allocated; a map's node has
//! room for 11 entries and may be half full. So the prediction counts every
//! value's slot three times over, every non-empty array's first allocation
//! (room for 4), every non-empty map's first node, and each map entry's key
//! as a value. It tells structs from values by the member names that open
//! values (`min`, `max`, `attributes`, `extensions`, and any name with an
//! escape, which might spell one of them), and counts what gltf-json ignores
//! as if it were kept, except under `extras`: it errs high, never low.

use gltf::json;
use std::mem::size_of;

const fn max(a: usize, b: usize) -> usize {
    if a > b {
        a
    } else {
        b
    }
}

/// The largest struct gltf-json keeps in a `Vec` (an element of one of the
/// document's arrays).
const STRUCT: usize = {
    let sizes = [
        size_of::<json::Accessor>(),
        size_of::<json::Animation>(),
        size_of::<json::animation::Channel>(),
        size_of::<json::animation::Sampler>(),
        size_of::<json::Buffer>(),
        size_of::<json::buffer::View>(),
        size_of::<json::Camera>(),
        size_of::<json::Image>(),
        size_of::<json::Material>(),
        size_of::<json::Mesh>(),
        size_of::<json::mesh::Primitive>(),
        size_of::<json::mesh::MorphTarget>(),
        size_of::<json::Node>(),
        size_of::<json::Scene>(),
        size_of::<json::Skin>(),
        size_of::<json::Texture>(),
        size_of::<json::texture::Sampler>(),
    ];
    let mut largest = 0;
    let mut k = 0;
    while k < sizes.len() {
        largest = max(largest, sizes[k]);
        k += 1;
    }
    largest
};

/// A slot of an array or a map: a `Value`, or a `String` of `extensionsUsed`.
const VALUE: usize = max(size_of::<serde_json::Value>(), size_of::<String>());

/// A map's key: a `String`, or a primitive's attribute name.
const KEY: usize = max(
    size_of::<String>(),
    size_of::<json::validation::Checked<json::mesh::Semantic>>(),
);

/// Bytes the allocator may take on top of a request.
const OVERHEAD: u64 = 32;

/// A map's node: room for 11 keys and values, with its header.
const MAP_NODE: u64 = 11 * (KEY + VALUE) as u64 + 2 * OVERHEAD;

/// A value's slot in an array or a map of values, three times over (see the
/// module documentation).
const SLOT: u64 = 3 * VALUE as u64;

/// Among structs: a struct's slot in a `Vec`, a `String`'s in
/// `extensionsUsed`, a number's in `children` or `weights` (4 bytes, 8 taken).
const STRUCT_SLOT: u64 = 3 * STRUCT as u64;
const STRING_SLOT: u64 = 3 * size_of::<String>() as u64;
const NUMBER_SLOT: u64 = 3 * size_of::<u64>() as u64;

/// A non-empty array's first allocation: room for 4 elements.
const FIRST_STRUCTS: u64 = 4 * STRUCT as u64 + OVERHEAD;
const FIRST_VALUES: u64 = 4 * VALUE as u64 + OVERHEAD;

/// The prediction for one JSON text: how many values of each kind it keeps
/// (those inside `extras` are kept as text, not counted) and the bytes
/// parsing it may hold at once.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct JsonSize {
    pub objects: u64,
    pub arrays: u64,
    /// Strings, and members' names where they are a map's keys.
    pub strings: u64,
    /// Numbers, `true`, `false` and `null` (and anything else that is not
    /// JSON, which serde refuses).
    pub scalars: u64,
    pub bytes: u64,
}

/// Where the scan is.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// Among gltf-json's structs, their `Vec`s and `String`s.
    Structs,
    /// Inside a value kept as `Value`s or a map (`min`, `max`, `attributes`,
    /// `extensions`), from the value opened at `depth` until the scan is back
    /// there. A member named `extras` in there is kept like any other.
    Values { depth: usize },
    /// Inside an `extras` value (kept as its text, from `start`).
    Extras { depth: usize, start: usize },
}

/// What a token is.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Token {
    Object,
    Array,
    String { length: u64 },
    Scalar,
}

fn is_space(byte: u8) -> bool {
    matches!(byte, b' ' | b'\t' | b'\n' | b'\r')
}

/// The bytes a string's text takes on the heap, at most (escapes only
/// shorten it).
fn text(length: u64) -> u64 {
    if length > 0 {
        length + OVERHEAD
    } else {
        0
    }
}

/// What a value costs where it is: its slot, its text, and for an object of
/// values its map's first node.
fn cost(token: Token, values: bool, empty: bool) -> u64 {
    match (token, values) {
        (Token::Object, false) => STRUCT_SLOT,
        (Token::Object, true) => SLOT + if empty { 0 } else { MAP_NODE },
        (Token::Array, _) => SLOT,
        (Token::String { length }, false) => STRING_SLOT + text(length),
        (Token::String { length }, true) => SLOT + text(length),
        (Token::Scalar, false) => NUMBER_SLOT,
        (Token::Scalar, true) => SLOT,
    }
}

impl JsonSize {
    /// Scans `json` once. What is not JSON is scanned too (serde refuses it,
    /// but only where it is reached, having kept what came before).
    pub fn of(json: &[u8]) -> JsonSize {
        let mut size = JsonSize::default();
        let mut bytes: u64 = 0;
        let mut depth = 0usize;
        let mut mode = Mode::Structs;
        // The mode the next value opens, set by the member name before it.
        let mut next = Mode::Structs;
        // serde_json's scratch buffer: an escaped string's text, or one byte
        // per level of nesting in what it skips.
        let (mut longest_escaped, mut deepest) = (0u64, 0u64);
        let mut at = 0;
        while at < json.len() {
            let byte = json[at];
            if is_space(byte) || byte == b',' || byte == b':' {
                at += 1;
                continue;
            }
            let start = at;
            let token = match byte {
                b'}' | b']' => {
                    depth = depth.saturating_sub(1);
                    at += 1;
                    // A value ends: the mode it opened ends with it.
                    match mode {
                        Mode::Values { depth: opened } if opened == depth => mode = Mode::Structs,
                        Mode::Extras {
                            depth: opened,
                            start,
                        } if opened == depth => {
                            bytes = bytes.saturating_add((at - start) as u64 + OVERHEAD);
                            mode = Mode::Structs;
                        }
                        _ => {}
                    }
                    continue;
                }
                b'{' => Token::Object,
                b'[' => Token::Array,
                b'"' => {
                    let mut escaped = false;
                    at += 1;
                    while at < json.len() && json[at] != b'"' {
                        if json[at] == b'\\' {
                            escaped = true;
                            at += 1;
                        }
                        at += 1;
                    }
                    let end = at.min(json.len());
                    at = (end + 1).min(json.len());
                    let length = (end - start - 1) as u64;
                    if escaped {
                        longest_escaped = longest_escaped.max(length);
                    }
                    let mut after = at;
                    while after < json.len() && is_space(json[after]) {
                        after += 1;
                    }
                    if json.get(after) == Some(&b':') {
                        // A member's name: a map's key among values, and
                        // what says how the member's value is kept.
                        match mode {
                            Mode::Structs => {
                                next = match &json[start + 1..end] {
                                    b"extras" => Mode::Extras { depth, start: 0 },
                                    b"min" | b"max" | b"attributes" | b"extensions" => {
                                        Mode::Values { depth }
                                    }
                                    // An escape might spell any of those: what
                                    // it names is kept as values.
                                    _ if escaped => Mode::Values { depth },
                                    _ => Mode::Structs,
                                };
                            }
                            Mode::Values { .. } => {
                                size.strings += 1;
                                bytes = bytes.saturating_add(SLOT + text(length));
                            }
                            Mode::Extras { .. } => {}
                        }
                        continue;
                    }
                    Token::String { length }
                }
                _ => {
                    while at < json.len()
                        && !is_space(json[at])
                        && !matches!(json[at], b',' | b':' | b'{' | b'}' | b'[' | b']' | b'"')
                    {
                        at += 1;
                    }
                    Token::Scalar
                }
            };
            // A value starts, in the mode its member's name set.
            if mode == Mode::Structs {
                mode = match next {
                    Mode::Extras { .. } => Mode::Extras { depth, start },
                    other => other,
                };
            }
            next = Mode::Structs;
            let opens = matches!(token, Token::Object | Token::Array);
            if opens {
                at += 1;
            }
            if !matches!(mode, Mode::Extras { .. }) {
                let values = matches!(mode, Mode::Values { .. });
                let mut first = at;
                while first < json.len() && is_space(json[first]) {
                    first += 1;
                }
                let empty = json.get(first).is_none_or(|b| matches!(b, b'}' | b']'));
                bytes = bytes.saturating_add(cost(token, values, empty));
                if token == Token::Array && !empty {
                    bytes = bytes.saturating_add(if json[first] == b'{' {
                        FIRST_STRUCTS
                    } else {
                        FIRST_VALUES
                    });
                }
                match token {
                    Token::Object => size.objects += 1,
                    Token::Array => size.arrays += 1,
                    Token::String { .. } => size.strings += 1,
                    Token::Scalar => size.scalars += 1,
                }
            }
            if opens {
                depth += 1;
                deepest = deepest.max(depth as u64);
            } else {
                match mode {
                    Mode::Values { depth: opened } if opened == depth => mode = Mode::Structs,
                    Mode::Extras {
                        depth: opened,
                        start,
                    } if opened == depth => {
                        bytes = bytes.saturating_add((at - start) as u64 + OVERHEAD);
                        mode = Mode::Structs;
                    }
                    _ => {}
                }
            }
        }
        size.bytes = bytes.saturating_add(3 * longest_escaped.max(deepest));
        size
    }

    /// What is predicted, for a message: "its glTF document (12 objects, …)".
    pub fn describe(&self) -> String {
        format!(
            "its glTF document ({} objects, {} arrays, {} strings, {} numbers and other values)",
            self.objects, self.arrays, self.strings, self.scalars
        )
    }
}
