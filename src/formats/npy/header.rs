//! The header of a NumPy `.npy` file, read strictly: magic, version, header
//! length, and the Python dict literal NumPy writes
//! (`{'descr': '<f4', 'fortran_order': False, 'shape': (3, 4), }`). Nothing is
//! allocated from a declared size before it is checked against the bytes present.

use std::io::Read;

/// The most header bytes a weights or point-set file may declare. NumPy's own
/// reader refuses more than 10,000 unless told otherwise; theirs are under 128.
pub const MAX_HEADER_BYTES: u64 = 1 << 16;

/// What the header says about the values that follow it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NpyHeader {
    /// The dtype string, e.g. `<f4`.
    pub descr: String,
    pub fortran_order: bool,
    pub shape: Vec<u64>,
    /// Bytes from the start of the file to the first value.
    pub data_offset: u64,
}

/// Why a header could not be read; the caller adds the file's name.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum HeaderError {
    #[error("not a .npy file (it does not start with \\x93NUMPY)")]
    NoMagic,
    #[error(".npy format version {major}.{minor} is not one NumPy writes (1.0, 2.0 or 3.0)")]
    Version { major: u8, minor: u8 },
    #[error(
        "its .npy header declares {declared} bytes, more than the {MAX_HEADER_BYTES} pmvc reads"
    )]
    HeaderTooLong { declared: u64 },
    #[error(
        "truncated in its .npy header: the header needs {needed} bytes, the file holds {present}"
    )]
    Truncated { needed: u64, present: u64 },
    #[error("cannot read its .npy header: {0}")]
    Io(String),
    #[error("its .npy header is malformed: {0}")]
    Malformed(String),
}

/// Read the header from `reader`, which holds `present` bytes when that is known
/// (a regular file or an archive entry), leaving it at the first value.
pub fn read_header(reader: &mut impl Read, present: Option<u64>) -> Result<NpyHeader, HeaderError> {
    let io = |error: std::io::Error| HeaderError::Io(error.to_string());
    let mut preamble = [0u8; 8];
    if read_fully(reader, &mut preamble).map_err(io)? < preamble.len()
        || &preamble[..6] != b"\x93NUMPY"
    {
        return Err(HeaderError::NoMagic);
    }
    let (major, minor) = (preamble[6], preamble[7]);
    let (length_bytes, utf8) = match (major, minor) {
        (1, 0) => (2usize, false),
        (2, 0) => (4, false),
        (3, 0) => (4, true),
        _ => return Err(HeaderError::Version { major, minor }),
    };
    let mut length = [0u8; 4];
    let filled = read_fully(reader, &mut length[..length_bytes]).map_err(io)?;
    if filled < length_bytes {
        return Err(HeaderError::Truncated {
            needed: 8 + length_bytes as u64,
            present: 8 + filled as u64,
        });
    }
    let declared = u64::from(u32::from_le_bytes(length));
    if declared > MAX_HEADER_BYTES {
        return Err(HeaderError::HeaderTooLong { declared });
    }
    let data_offset = 8 + length_bytes as u64 + declared;
    if let Some(present) = present.filter(|&present| present < data_offset) {
        return Err(HeaderError::Truncated {
            needed: data_offset,
            present,
        });
    }
    let mut text = vec![0u8; declared as usize];
    let filled = read_fully(reader, &mut text).map_err(io)?;
    if filled < text.len() {
        return Err(HeaderError::Truncated {
            needed: data_offset,
            present: 8 + length_bytes as u64 + filled as u64,
        });
    }
    let text = if utf8 {
        std::str::from_utf8(&text).map_err(|_| malformed("it is not UTF-8"))?
    } else if text.is_ascii() {
        std::str::from_utf8(&text).map_err(|_| malformed("it is not ASCII"))?
    } else {
        return Err(malformed(
            "it is not ASCII (version 1.0 and 2.0 headers are)",
        ));
    };
    let mut header = parse_dict(text)?;
    header.data_offset = data_offset;
    Ok(header)
}

/// Fill `buffer` from `reader` until it is full or the stream ends; returns the
/// bytes read, fewer than `buffer.len()` only at the end of the stream.
pub fn read_fully(reader: &mut impl Read, buffer: &mut [u8]) -> std::io::Result<usize> {
    let mut filled = 0;
    while filled < buffer.len() {
        match reader.read(&mut buffer[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(error) if error.kind() == std::io::ErrorKind::Interrupted => {}
            Err(error) => return Err(error),
        }
    }
    Ok(filled)
}

/// A shape as NumPy prints it: `(12,)`, `(4, 3)`.
pub fn shape_text(shape: &[u64]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The bytes before the values of a version 1.0 `.npy` in C order: magic,
/// version, header length and the dict, padded with spaces and a newline to a
/// multiple of 64 bytes, as NumPy writes it. An error when the dict is too long
/// for version 1.0's two-byte length.
pub fn header_bytes(descr: &str, shape: &[u64]) -> Result<Vec<u8>, String> {
    let shape = shape_text(shape);
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    let padded = (10 + header.len() + 1).div_ceil(64) * 64 - 10;
    header.extend(std::iter::repeat_n(' ', padded - 1 - header.len()));
    header.push('\n');
    let length = u16::try_from(header.len())
        .map_err(|_| format!("shape {shape} is too long for a .npy header"))?;
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&length.to_le_bytes());
    bytes.extend_from_slice(header.as_bytes());
    Ok(bytes)
}

fn malformed(what: impl Into<String>) -> HeaderError {
    HeaderError::Malformed(what.into())
}

/// The dict literal: exactly the keys `descr`, `fortran_order` and `shape`, in
/// any order, with an optional trailing comma and padding after the brace.
fn parse_dict(text: &str) -> Result<NpyHeader, HeaderError> {
    let mut parser = Parser {
        text: text.as_bytes(),
        at: 0,
    };
    parser.expect(b'{')?;
    let (mut descr, mut fortran_order, mut shape) = (None, None, None);
    loop {
        if parser.eat(b'}') {
            break;
        }
        let key = parser.string()?;
        parser.expect(b':')?;
        match key.as_str() {
            "descr" if descr.is_none() => descr = Some(parser.descr()?),
            "fortran_order" if fortran_order.is_none() => fortran_order = Some(parser.boolean()?),
            "shape" if shape.is_none() => shape = Some(parser.tuple()?),
            "descr" | "fortran_order" | "shape" => {
                return Err(malformed(format!("the key '{key}' appears twice")))
            }
            _ => {
                return Err(malformed(format!(
                    "unexpected key '{}'",
                    key.escape_debug()
                )))
            }
        }
        if !parser.eat(b',') {
            parser.expect(b'}')?;
            break;
        }
    }
    parser.skip_space();
    if parser.at != parser.text.len() {
        return Err(malformed("text after the closing brace"));
    }
    let missing = |key: &str| malformed(format!("no '{key}' key"));
    Ok(NpyHeader {
        descr: descr.ok_or_else(|| missing("descr"))?,
        fortran_order: fortran_order.ok_or_else(|| missing("fortran_order"))?,
        shape: shape.ok_or_else(|| missing("shape"))?,
        data_offset: 0,
    })
}

struct Parser<'a> {
    text: &'a [u8],
    at: usize,
}

impl Parser<'_> {
    fn skip_space(&mut self) {
        while self.text.get(self.at).is_some_and(u8::is_ascii_whitespace) {
            self.at += 1;
        }
    }

    fn eat(&mut self, byte: u8) -> bool {
        self.skip_space();
        let found = self.text.get(self.at) == Some(&byte);
        self.at += usize::from(found);
        found
    }

    fn expect(&mut self, byte: u8) -> Result<(), HeaderError> {
        if self.eat(byte) {
            Ok(())
        } else {
            Err(malformed(format!(
                "expected '{}' at byte {}",
                byte as char,
                self.at + 1
            )))
        }
    }

    /// A quoted string without escapes, as NumPy's keys and simple dtypes are.
    fn string(&mut self) -> Result<String, HeaderError> {
        self.skip_space();
        let quote = match self.text.get(self.at) {
            Some(&q @ (b'\'' | b'"')) => q,
            _ => {
                return Err(malformed(format!(
                    "expected a quoted string at byte {}",
                    self.at + 1
                )))
            }
        };
        let start = self.at + 1;
        let length = self.text[start..]
            .iter()
            .position(|&b| b == quote || b == b'\\')
            .ok_or_else(|| malformed("a string is not closed"))?;
        if self.text[start + length] == b'\\' {
            return Err(malformed("a string holds an escape"));
        }
        self.at = start + length + 1;
        Ok(String::from_utf8_lossy(&self.text[start..start + length]).into_owned())
    }

    /// A dtype: a plain type string. A list is a structured dtype.
    fn descr(&mut self) -> Result<String, HeaderError> {
        self.skip_space();
        if self.text.get(self.at) == Some(&b'[') {
            return Err(malformed(
                "'descr' is a structured dtype (a list of fields), not a number type",
            ));
        }
        self.string()
    }

    fn boolean(&mut self) -> Result<bool, HeaderError> {
        self.skip_space();
        for (word, value) in [("True", true), ("False", false)] {
            if self.text[self.at..].starts_with(word.as_bytes()) {
                self.at += word.len();
                return Ok(value);
            }
        }
        Err(malformed("'fortran_order' is neither True nor False"))
    }

    /// `()`, `(3,)`, `(3, 4)`, `(3, 4,)`: non-negative integers.
    fn tuple(&mut self) -> Result<Vec<u64>, HeaderError> {
        self.expect(b'(')?;
        let mut values = Vec::new();
        loop {
            if self.eat(b')') {
                return Ok(values);
            }
            if values.len() == 32 {
                return Err(malformed("'shape' has more than 32 dimensions"));
            }
            values.push(self.integer()?);
            if !self.eat(b',') {
                self.expect(b')')?;
                return Ok(values);
            }
        }
    }

    fn integer(&mut self) -> Result<u64, HeaderError> {
        self.skip_space();
        let digits = self.text[self.at..]
            .iter()
            .take_while(|b| b.is_ascii_digit())
            .count();
        if digits == 0 {
            return Err(malformed(format!(
                "'shape' holds something other than a non-negative integer at byte {}",
                self.at + 1
            )));
        }
        let text = std::str::from_utf8(&self.text[self.at..self.at + digits]).unwrap_or("");
        self.at += digits;
        text.parse().map_err(|_| {
            malformed(format!(
                "'shape' holds {text}, more than any array can have"
            ))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(version: u8, header: &str) -> Vec<u8> {
        let mut bytes = b"\x93NUMPY".to_vec();
        bytes.extend([version, 0]);
        if version == 1 {
            bytes.extend((header.len() as u16).to_le_bytes());
        } else {
            bytes.extend((header.len() as u32).to_le_bytes());
        }
        bytes.extend(header.as_bytes());
        bytes
    }

    fn read(bytes: &[u8]) -> Result<NpyHeader, HeaderError> {
        read_header(&mut &bytes[..], Some(bytes.len() as u64))
    }

    #[test]
    fn numpy_headers_of_every_version_read() {
        let text = "{'descr': '<f4', 'fortran_order': False, 'shape': (3, 4), }    \n";
        for version in [1, 2, 3] {
            let header = read(&file(version, text)).expect("a valid header");
            assert_eq!(header.descr, "<f4");
            assert!(!header.fortran_order);
            assert_eq!(header.shape, [3, 4]);
            let preamble = if version == 1 { 10 } else { 12 };
            assert_eq!(header.data_offset, preamble + text.len() as u64);
        }
        let other_order = "{\"shape\": (5,), \"fortran_order\": True, \"descr\": \"<f8\"}\n";
        let header = read(&file(1, other_order)).expect("keys in any order");
        assert_eq!((header.shape, header.fortran_order), (vec![5], true));
    }

    #[test]
    fn a_header_longer_than_the_file_is_truncated_and_never_allocated() {
        let mut bytes = file(2, "{}");
        bytes[8..12].copy_from_slice(&60_000u32.to_le_bytes());
        assert_eq!(
            read(&bytes),
            Err(HeaderError::Truncated {
                needed: 60_012,
                present: 14
            })
        );
        bytes[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        assert_eq!(
            read(&bytes),
            Err(HeaderError::HeaderTooLong {
                declared: u64::from(u32::MAX)
            })
        );
    }

    #[test]
    fn malformed_headers_say_what_is_wrong() {
        for (text, expected) in [
            ("{'descr': '<f4', 'shape': (2, 2), }", "no 'fortran_order'"),
            (
                "{'descr': '<f4', 'fortran_order': False, 'shape': (2, -2), }",
                "non-negative integer",
            ),
            (
                "{'descr': '<f4', 'fortran_order': False, 'shape': (99999999999999999999, 2), }",
                "more than any array",
            ),
            (
                "{'descr': [('a', '<f4')], 'fortran_order': False, 'shape': (2,), }",
                "structured dtype",
            ),
            (
                "{'descr': '<f4', 'descr': '<f4', 'fortran_order': False, 'shape': (), }",
                "twice",
            ),
            (
                "{'descr': '<f4', 'fortran_order': 0, 'shape': (1,)}",
                "True nor False",
            ),
            (
                "{'descr': '<f4', 'fortran_order': False, 'shape': (1,)} x",
                "after the closing",
            ),
        ] {
            let error = read(&file(1, text)).expect_err(text).to_string();
            assert!(error.contains(expected), "{text}: {error}");
        }
        assert_eq!(read(b"PK\x03\x04"), Err(HeaderError::NoMagic));
        assert_eq!(
            read(&file(4, "{}")),
            Err(HeaderError::Version { major: 4, minor: 0 })
        );
    }
}
