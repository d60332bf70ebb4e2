//! The binding kernels' compiled pipelines, kept on disk between runs.
//!
//! wgpu hands out the driver's pipeline cache as opaque bytes
//! ([`wgpu::PipelineCache::get_data`]); they are only safe to give back to the
//! same adapter and wgpu version. So the file wraps them in a header of our own,
//! checked before wgpu sees a byte:
//!
//! | bytes | field |
//! |---|---|
//! | 8 | magic `PMVCPLC\0` |
//! | 4 | format version (little-endian u32) |
//! | 4 | length of the adapter key (u32) |
//! | n | adapter key, UTF-8 ([`adapter_key`]) |
//! | 8 | length of wgpu's data (u64) |
//! | 8 | FNV-1a 64 checksum of wgpu's data |
//! | … | wgpu's data |
//!
//! A file that fails any check is ignored (the caller shows a notice) and
//! replaced by the next write; nothing here fails a bind.

use crate::budget::read_limited;
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 8] = b"PMVCPLC\0";
const FORMAT_VERSION: u32 = 1;
/// The wgpu release whose pipeline data the files hold; part of the adapter key,
/// since another wgpu cannot read it (checked against Cargo.toml by a test).
pub const WGPU_MAJOR: u32 = 30;
/// A cache file larger than this is not one of ours (three kernels' pipelines
/// are a few hundred KiB on the drivers measured).
const MAX_FILE_BYTES: u64 = 64 << 20;
const FIXED_HEADER: usize = 8 + 4 + 4 + 8 + 8;

/// What was found on disk for an adapter.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CacheLoad {
    /// The adapter or its backend keeps no pipeline cache (only Vulkan does in wgpu).
    Unsupported,
    /// No cache folder could be named (no `PMVC_CACHE_DIR`, `XDG_CACHE_HOME` or `HOME`).
    NoFolder,
    /// No file yet: the first run on this adapter compiles and writes one.
    Missing(PathBuf),
    /// A file for this adapter and wgpu: its data.
    Hit(PathBuf, Vec<u8>),
    /// A file that cannot be used, and why.
    Ignored(PathBuf, String),
}

impl CacheLoad {
    /// One line for `pmvc info` and `--verbose`.
    pub fn describe(&self) -> String {
        match self {
            CacheLoad::Unsupported => {
                "not kept for this adapter (wgpu keeps one for Vulkan only)".into()
            }
            CacheLoad::NoFolder => {
                "no cache folder (set PMVC_CACHE_DIR, XDG_CACHE_HOME or HOME)".into()
            }
            CacheLoad::Missing(path) => format!(
                "{}: none yet (written after the first GPU bind)",
                path.display()
            ),
            CacheLoad::Hit(path, data) => format!(
                "{}: hit ({} bytes for this adapter)",
                path.display(),
                data.len()
            ),
            CacheLoad::Ignored(path, why) => format!("{}: ignored ({why})", path.display()),
        }
    }

    pub fn is_hit(&self) -> bool {
        matches!(self, CacheLoad::Hit(..))
    }

    /// The file the cache is written to, if any.
    pub fn path(&self) -> Option<&Path> {
        match self {
            CacheLoad::Missing(path) | CacheLoad::Hit(path, _) | CacheLoad::Ignored(path, _) => {
                Some(path)
            }
            CacheLoad::Unsupported | CacheLoad::NoFolder => None,
        }
    }
}

/// The folder pipeline caches go in: `$PMVC_CACHE_DIR`, else `$XDG_CACHE_HOME/pmvc`,
/// else `~/.cache/pmvc`. Relative `XDG_CACHE_HOME` values are ignored, as the
/// XDG specification says.
pub fn cache_folder() -> Option<PathBuf> {
    let set = |name: &str| std::env::var_os(name).filter(|value| !value.is_empty());
    if let Some(folder) = set("PMVC_CACHE_DIR") {
        return Some(PathBuf::from(folder));
    }
    if let Some(xdg) = set("XDG_CACHE_HOME").map(PathBuf::from) {
        if xdg.is_absolute() {
            return Some(xdg.join("pmvc"));
        }
    }
    set("HOME").map(|home| PathBuf::from(home).join(".cache").join("pmvc"))
}

/// What identifies whose data a cache file holds: wgpu's per-device key, the
/// adapter's name and driver, and the wgpu release. `None` where wgpu keeps
/// no pipeline cache for the backend.
pub fn adapter_key(info: &wgpu::AdapterInfo) -> Option<String> {
    let device_key = wgpu::util::pipeline_cache_key(info)?;
    Some(format!(
        "{device_key}; {}; {} {}; wgpu {WGPU_MAJOR}",
        info.name, info.driver, info.driver_info
    ))
}

/// The file of an adapter's cache in `folder`.
fn cache_file(folder: &Path, info: &wgpu::AdapterInfo) -> Option<PathBuf> {
    let name = wgpu::util::pipeline_cache_key(info)?;
    Some(folder.join(format!("{name}.bin")))
}

/// Look for the cache of the adapter `info` describes. Never fails: a file that
/// cannot be read or used is [`CacheLoad::Ignored`] with the reason.
pub fn load(info: &wgpu::AdapterInfo) -> CacheLoad {
    let (Some(key), Some(folder)) = (adapter_key(info), cache_folder()) else {
        return if adapter_key(info).is_none() {
            CacheLoad::Unsupported
        } else {
            CacheLoad::NoFolder
        };
    };
    let Some(path) = cache_file(&folder, info) else {
        return CacheLoad::Unsupported;
    };
    match std::fs::symlink_metadata(&path) {
        // No file, or no folder that could hold one: the write says why.
        Err(error)
            if matches!(
                error.kind(),
                std::io::ErrorKind::NotFound | std::io::ErrorKind::NotADirectory
            ) =>
        {
            return CacheLoad::Missing(path)
        }
        Err(error) => return CacheLoad::Ignored(path, error.to_string()),
        Ok(metadata) if !metadata.file_type().is_file() => {
            return CacheLoad::Ignored(path, "not a regular file; left alone".into())
        }
        Ok(_) => {}
    }
    let bytes = match read_limited(&path, MAX_FILE_BYTES) {
        Ok(bytes) => bytes,
        Err(error) => return CacheLoad::Ignored(path, error.to_string()),
    };
    match decode(&bytes, &key) {
        Ok(data) => {
            let data = data.to_vec();
            CacheLoad::Hit(path, data)
        }
        Err(why) => CacheLoad::Ignored(path, why),
    }
}

/// Write `data` as the cache of the adapter whose key is `key`, to `path`:
/// through a temporary file and a rename, never through a symbolic link or onto
/// anything but a regular file. The error says why it was not written.
pub fn store(path: &Path, key: &str, data: &[u8]) -> Result<(), String> {
    if let Some(folder) = path.parent() {
        std::fs::create_dir_all(folder).map_err(|error| error.to_string())?;
    }
    match std::fs::symlink_metadata(path) {
        Ok(metadata) if !metadata.file_type().is_file() => {
            return Err("not a regular file; left alone".into())
        }
        _ => {}
    }
    let bytes = encode(key, data);
    crate::formats::write_atomically(path, |out| out.write_all(&bytes))
        .map_err(|error| error.to_string())
}

/// A cache file's bytes: the header of the module documentation, then `data`.
pub fn encode(key: &str, data: &[u8]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(FIXED_HEADER + key.len() + data.len());
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&(key.len() as u32).to_le_bytes());
    bytes.extend_from_slice(key.as_bytes());
    bytes.extend_from_slice(&(data.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&fnv1a(data).to_le_bytes());
    bytes.extend_from_slice(data);
    bytes
}

/// wgpu's data in a cache file, or why the file cannot be used for `key`.
pub fn decode<'a>(bytes: &'a [u8], key: &str) -> Result<&'a [u8], String> {
    let mut rest = bytes;
    let mut take = |count: usize| -> Option<&'a [u8]> {
        let (head, tail) = (rest.get(..count)?, rest.get(count..)?);
        rest = tail;
        Some(head)
    };
    let not_ours = || "not a pmvc pipeline cache".to_string();
    let truncated = || format!("truncated: {} bytes end inside its header", bytes.len());
    if take(MAGIC.len()).ok_or_else(not_ours)? != MAGIC {
        return Err(not_ours());
    }
    let word = |field: Option<&[u8]>| {
        field
            .and_then(|b| b.try_into().ok())
            .map(u32::from_le_bytes)
    };
    let long = |field: Option<&[u8]>| {
        field
            .and_then(|b| b.try_into().ok())
            .map(u64::from_le_bytes)
    };
    let version = word(take(4)).ok_or_else(truncated)?;
    if version != FORMAT_VERSION {
        return Err(format!(
            "format version {version}; this pmvc reads version {FORMAT_VERSION}"
        ));
    }
    let key_len = word(take(4)).ok_or_else(truncated)? as usize;
    let stored_key = take(key_len).ok_or_else(truncated)?;
    if stored_key != key.as_bytes() {
        return Err(format!(
            "made for another adapter or wgpu version: {:?}, not {key:?}",
            String::from_utf8_lossy(stored_key)
        ));
    }
    let data_len = long(take(8)).ok_or_else(truncated)?;
    let checksum = long(take(8)).ok_or_else(truncated)?;
    if data_len != rest.len() as u64 {
        return Err(format!(
            "truncated or padded: its header says {data_len} bytes of data, the file holds {}",
            rest.len()
        ));
    }
    if fnv1a(rest) != checksum {
        return Err("corrupt: the checksum of its data does not match".into());
    }
    Ok(rest)
}

/// FNV-1a, 64 bits: enough to tell a damaged file, not meant against forgery
/// (the file is the user's own).
fn fnv1a(data: &[u8]) -> u64 {
    data.iter().fold(0xcbf2_9ce4_8422_2325, |hash, &byte| {
        (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const KEY: &str = "wgpu_pipeline_cache_vulkan_1_2; test; driver 1; wgpu 30";

    #[test]
    fn a_file_round_trips_and_each_damage_has_its_reason() {
        let data = b"opaque driver bytes".to_vec();
        let file = encode(KEY, &data);
        assert_eq!(decode(&file, KEY), Ok(&data[..]));

        let reason = |bytes: &[u8], key: &str| decode(bytes, key).expect_err("refused");
        assert!(reason(b"hello", KEY).contains("not a pmvc pipeline cache"));
        assert!(reason(&file[..10], KEY).contains("truncated"));
        assert!(reason(&file[..file.len() - 3], KEY).contains("truncated"));
        assert!(reason(&file, "another adapter").contains("another adapter"));
        let mut flipped = file.clone();
        *flipped.last_mut().expect("data") ^= 1;
        assert!(reason(&flipped, KEY).contains("checksum"));
        let mut newer = file.clone();
        newer[8] = 2;
        assert!(reason(&newer, KEY).contains("format version 2"));
    }

    #[test]
    fn the_wgpu_release_in_the_key_is_the_one_built_against() {
        let manifest = include_str!("../../Cargo.toml");
        let wanted = format!("wgpu = {{ version = \"{WGPU_MAJOR}\"");
        assert!(
            manifest.contains(&wanted),
            "Cargo.toml's wgpu is not {WGPU_MAJOR}: update WGPU_MAJOR"
        );
    }
}
