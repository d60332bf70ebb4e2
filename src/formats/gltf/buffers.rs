//! A glTF file's buffers and its accessors' elements, read with every bound
//! checked: the GLB container, base64 `data:` URIs, and files in the glTF's
//! folder or below it.

use crate::budget::{bytes_for, check_memory};
use base64::Engine as _;
use gltf::buffer::Source;
use std::borrow::Cow;
use std::io::Read;
use std::path::{Component, Path};

/// The JSON chunk and, where there is one, the binary chunk of a GLB file.
pub(super) fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let word = |at: usize| -> Option<u32> {
        let bytes = bytes.get(at..at + 4)?;
        Some(u32::from_le_bytes(bytes.try_into().ok()?))
    };
    let truncated = |what: &str| {
        format!(
            "the binary glTF is truncated: it ends at byte {} within its {what}",
            bytes.len()
        )
    };
    let version = word(4).ok_or_else(|| truncated("header"))?;
    let length = word(8).ok_or_else(|| truncated("header"))? as usize;
    if version != 2 {
        return Err(format!(
            "binary glTF version {version}; only version 2 is read"
        ));
    }
    if length > bytes.len() {
        return Err(format!(
            "the binary glTF is truncated: its header says {length} bytes, the file has {}",
            bytes.len()
        ));
    }
    let bytes = &bytes[..length.max(12)];
    let mut chunks = Vec::new();
    let mut at = 12;
    while at < bytes.len() {
        let (Some(size), Some(kind)) = (word(at), bytes.get(at + 4..at + 8)) else {
            return Err(truncated(&format!("chunk {}'s header", chunks.len())));
        };
        let start = at + 8;
        let end = start
            .checked_add(size as usize)
            .filter(|&end| end <= bytes.len())
            .ok_or_else(|| {
                format!(
                    "the binary glTF is truncated: chunk {} says {size} bytes, but only {} follow its header",
                    chunks.len(),
                    bytes.len() - start.min(bytes.len())
                )
            })?;
        chunks.push((kind, &bytes[start..end]));
        at = end;
    }
    match chunks[..] {
        [] => Err("the binary glTF has no JSON chunk".to_owned()),
        [(kind, _), ..] if kind != b"JSON" => {
            Err("the binary glTF's first chunk is not its JSON".to_owned())
        }
        [(_, json), (b"BIN\0", bin), ..] => Ok((json, Some(bin))),
        [(_, json), ..] => Ok((json, None)),
    }
}

/// The buffers of one document, each read when an accessor first needs it.
pub(super) struct Buffers<'a> {
    /// The glTF file, whose folder external buffers must be in.
    path: &'a Path,
    bin: Option<&'a [u8]>,
    loaded: Vec<Option<Cow<'a, [u8]>>>,
}

/// `%XX` escapes of a URI decoded; `None` where that gives no UTF-8.
fn percent_decoded(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut at = 0;
    while at < bytes.len() {
        let escaped = (bytes[at] == b'%')
            .then(|| bytes.get(at + 1..at + 3))
            .flatten()
            .and_then(|hex| u8::from_str_radix(std::str::from_utf8(hex).ok()?, 16).ok());
        match escaped {
            Some(byte) => {
                out.push(byte);
                at += 3;
            }
            None => {
                out.push(bytes[at]);
                at += 1;
            }
        }
    }
    String::from_utf8(out).ok()
}

impl<'a> Buffers<'a> {
    pub fn new(path: &'a Path, document: &gltf::Document, bin: Option<&'a [u8]>) -> Self {
        Buffers {
            path,
            bin,
            loaded: vec![None; document.buffers().len()],
        }
    }

    /// The bytes of `buffer`, at least its `byteLength` of them.
    fn bytes(&mut self, buffer: &gltf::Buffer) -> Result<&[u8], String> {
        let index = buffer.index();
        if self.loaded[index].is_none() {
            let data: Cow<'a, [u8]> = match buffer.source() {
                Source::Bin => Cow::Borrowed(self.bin.ok_or_else(|| {
                    format!("buffer {index} is the binary chunk of a .glb, but the file has none")
                })?),
                Source::Uri(uri) if uri.starts_with("data:") => Cow::Owned(data_uri(index, uri)?),
                Source::Uri(uri) => Cow::Owned(self.external(index, uri, buffer.length())?),
            };
            if data.len() < buffer.length() {
                return Err(format!(
                    "buffer {index} holds {} bytes, but its byteLength says {}",
                    data.len(),
                    buffer.length()
                ));
            }
            self.loaded[index] = Some(data);
        }
        Ok(self.loaded[index].as_deref().unwrap_or_default())
    }

    /// The first `length` bytes of the file `uri` names, which must be a
    /// regular file in the glTF's folder or below it, links followed.
    fn external(&self, index: usize, uri: &str, length: usize) -> Result<Vec<u8>, String> {
        let refused = || {
            format!(
                "buffer {index} ({uri:?}): it is not a file beside the glTF or in a folder below it; no other file is read"
            )
        };
        let decoded = percent_decoded(uri).ok_or_else(refused)?;
        let relative = Path::new(&decoded);
        let plain = !decoded.contains(':')
            && relative
                .components()
                .all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
        if !plain || decoded.is_empty() {
            return Err(refused());
        }
        let folder = match self.path.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => parent,
            _ => Path::new("."),
        };
        let cannot =
            |e: std::io::Error| format!("buffer {index} ({decoded:?}): cannot read it: {e}");
        let file = folder.join(relative).canonicalize().map_err(cannot)?;
        let folder = folder.canonicalize().map_err(cannot)?;
        if !file.starts_with(&folder) {
            return Err(refused());
        }
        // Before it is opened: opening a named pipe for reading waits for a
        // writer, and a device may never end.
        let not_a_file = |kind: &str| {
            format!(
                "buffer {index} ({decoded:?}): it is {kind}, not a regular file; buffers are read from regular files only"
            )
        };
        let metadata = std::fs::metadata(&file).map_err(cannot)?;
        if !metadata.is_file() {
            return Err(not_a_file(file_kind(&metadata.file_type())));
        }
        let size = metadata.len();
        if size < length as u64 {
            return Err(format!(
                "buffer {index} ({decoded:?}): the file has {size} bytes, but its byteLength says {length}"
            ));
        }
        check_memory(|| format!("buffer {index} ({decoded:?})"), length as u64)
            .map_err(|e| e.to_string())?;
        let opened = open_without_waiting(&file).map_err(cannot)?;
        // Replaced by something else since it was looked at.
        let kind = opened.metadata().map_err(cannot)?.file_type();
        if !kind.is_file() {
            return Err(not_a_file(file_kind(&kind)));
        }
        let mut bytes = Vec::with_capacity(length);
        opened
            .take(length as u64)
            .read_to_end(&mut bytes)
            .map_err(cannot)?;
        Ok(bytes)
    }

    /// Each element of `accessor` as `decode` reads its bytes (the element's
    /// components, tightly packed), every bound checked. An accessor with no
    /// buffer view is all zeros; sparse accessors are refused.
    pub fn read<T>(
        &mut self,
        accessor: &gltf::Accessor,
        decode: impl Fn(&[u8]) -> T,
    ) -> Result<Vec<T>, String> {
        let index = accessor.index();
        if accessor.sparse().is_some() {
            return Err(format!("accessor {index}: sparse accessors are not read"));
        }
        let count = accessor.count();
        let element = accessor.size();
        check_memory(
            || format!("accessor {index} ({count} elements)"),
            bytes_for(count as u64, std::mem::size_of::<T>() as u64),
        )
        .map_err(|e| e.to_string())?;
        let Some(view) = accessor.view() else {
            let zeros = vec![0u8; element];
            return Ok((0..count).map(|_| decode(&zeros)).collect());
        };
        let stride = view.stride().unwrap_or(element);
        if stride < element {
            return Err(format!(
                "accessor {index}: its elements are {element} bytes, but buffer view {} strides {stride}",
                view.index()
            ));
        }
        let data = self.bytes(&view.buffer())?;
        let view_bytes = view
            .offset()
            .checked_add(view.length())
            .and_then(|end| data.get(view.offset()..end))
            .ok_or_else(|| {
                format!(
                    "buffer view {}: bytes {} to {} are past the end of buffer {} ({} bytes)",
                    view.index(),
                    view.offset(),
                    view.offset() as u128 + view.length() as u128,
                    view.buffer().index(),
                    data.len()
                )
            })?;
        if count == 0 {
            return Ok(Vec::new());
        }
        let end =
            (count as u128 - 1) * stride as u128 + accessor.offset() as u128 + element as u128;
        if end > view_bytes.len() as u128 {
            return Err(format!(
                "accessor {index}: its {count} elements end at byte {end}, past the end of buffer view {} ({} bytes)",
                view.index(),
                view_bytes.len()
            ));
        }
        Ok((0..count)
            .map(|i| {
                let start = accessor.offset() + i * stride;
                decode(&view_bytes[start..start + element])
            })
            .collect())
    }
}

/// What a file that is not a regular file is, for a message.
fn file_kind(kind: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a named pipe";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if kind.is_dir() {
        "a folder"
    } else {
        "not a file"
    }
}

/// `path` opened for reading; on Unix without waiting for a writer, should it
/// have become a named pipe since it was looked at.
fn open_without_waiting(path: &Path) -> std::io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(rustix::fs::OFlags::NONBLOCK.bits() as i32);
    }
    options.open(path)
}

/// The bytes of a base64 `data:` URI.
fn data_uri(index: usize, uri: &str) -> Result<Vec<u8>, String> {
    let Some((header, payload)) = uri.split_once(',') else {
        return Err(format!("buffer {index}: its data: URI has no ','"));
    };
    if !header.ends_with(";base64") {
        return Err(format!(
            "buffer {index}: its data: URI is not base64, the only encoding read"
        ));
    }
    let engine = base64::engine::GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        base64::engine::GeneralPurposeConfig::new()
            .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
    );
    check_memory(
        || format!("buffer {index} (its data: URI)"),
        (payload.len() as u64 / 4 + 1) * 3,
    )
    .map_err(|e| e.to_string())?;
    engine
        .decode(payload)
        .map_err(|e| format!("buffer {index}: its data: URI is not valid base64: {e}"))
}
