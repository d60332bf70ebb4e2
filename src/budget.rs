//! Sizes checked before they are allocated, and inputs read with a limit.
//!
//! Every allocation that grows with an input or a parameter (voxel grids, weights
//! matrices, file contents, headers' declared shapes) is predicted first and
//! passed to [`check_memory`], so that a bad input or parameter is refused with
//! both sizes instead of aborting the process. Inputs that are not regular files
//! (devices, pipes) have no size to check and are read through [`read_limited`].

use std::io::Read;
use std::path::Path;

/// An allocation refused before it was made.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{what} would need {}", sizes_text(*.needed, *.available))]
pub struct TooLarge {
    /// What was to be allocated, e.g. "the voxel grid (4096 × 4096 × 4096)".
    pub what: String,
    pub needed: u64,
    /// What the process could still get; `None` where the size is past what any
    /// allocation can be (more than `isize::MAX` bytes).
    pub available: Option<u64>,
}

/// "3.6 GiB, but only 3.5 GiB of memory is available", with as many digits as
/// it takes for the two sizes to read differently.
fn sizes_text(needed: u64, available: Option<u64>) -> String {
    let Some(available) = available else {
        return format!(
            "{}, more than this machine can address",
            human_bytes(needed)
        );
    };
    let mut digits = 1;
    let (mut needed_text, mut available_text) = (human_bytes(needed), human_bytes(available));
    while needed_text == available_text && needed != available && digits < 12 {
        digits += 1;
        needed_text = bytes_with_digits(needed, digits);
        available_text = bytes_with_digits(available, digits);
    }
    if needed_text == available_text && needed != available {
        (needed_text, available_text) = (format!("{needed} bytes"), format!("{available} bytes"));
    }
    format!("{needed_text}, but only {available_text} of memory is available")
}

/// `count` items of `each` bytes, saturating: a product that overflows is
/// refused by [`check_memory`] as unaddressable rather than wrapping to a small
/// size.
pub fn bytes_for(count: u64, each: u64) -> u64 {
    count.saturating_mul(each)
}

/// Refuse an allocation of `needed` bytes, described by `what`, when it is more
/// than an allocation can be or more than the process can still get
/// ([`available_memory`]).
pub fn check_memory(what: impl FnOnce() -> String, needed: u64) -> Result<(), TooLarge> {
    if needed > isize::MAX as u64 {
        return Err(TooLarge {
            what: what(),
            needed,
            available: None,
        });
    }
    match available_memory() {
        Some(available) if needed > available => Err(TooLarge {
            what: what(),
            needed,
            available: Some(available),
        }),
        _ => Ok(()),
    }
}

/// Memory the process can still get: the kernel's estimate of what is available
/// without swapping, plus free swap, and no more than the address-space limit
/// (`ulimit -v`) leaves. `None` where neither is known.
pub fn available_memory() -> Option<u64> {
    let system = system_available();
    let limited = address_space_left();
    match (system, limited) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

#[cfg(target_os = "linux")]
fn system_available() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kib = |key: &str| -> Option<u64> {
        let line = meminfo.lines().find(|line| line.starts_with(key))?;
        line[key.len()..]
            .trim()
            .trim_end_matches("kB")
            .trim()
            .parse()
            .ok()
    };
    Some((kib("MemAvailable:")? + kib("SwapFree:").unwrap_or(0)) * 1024)
}

/// The soft address-space limit less what the process has mapped already.
#[cfg(target_os = "linux")]
fn address_space_left() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|line| line.starts_with("Max address space"))?;
    let soft: u64 = line["Max address space".len()..]
        .split_whitespace()
        .next()?
        .parse()
        .ok()?; // "unlimited" does not parse: no limit
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let mapped_kib: u64 = status
        .lines()
        .find(|line| line.starts_with("VmSize:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()?;
    Some(soft.saturating_sub(mapped_kib * 1024))
}

#[cfg(not(target_os = "linux"))]
fn system_available() -> Option<u64> {
    None
}

#[cfg(not(target_os = "linux"))]
fn address_space_left() -> Option<u64> {
    None
}

/// Read a whole input of at most `limit` bytes. A regular file's size is checked
/// before anything is read; anything else (a device such as `/dev/zero`, a pipe)
/// is read until it ends or passes the limit, whichever comes first. Either way
/// the contents must also fit in memory ([`check_memory`]).
pub fn read_limited(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    read_up_to(path, limit, false)
}

/// [`read_limited`] for a text format: an input that is not a regular file is
/// also read no further than its first NUL byte, which no text holds, so that
/// `/dev/zero` ends after one read instead of at the limit. The bytes returned
/// then end with that NUL.
pub fn read_limited_text(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    read_up_to(path, limit, true)
}

fn read_up_to(path: &Path, limit: u64, stop_at_nul: bool) -> std::io::Result<Vec<u8>> {
    let file = std::fs::File::open(path)?;
    let metadata = file.metadata()?;
    if metadata.is_dir() {
        return Err(invalid_data("it is a folder, not a file".to_owned()));
    }
    let expected = if metadata.is_file() {
        if metadata.len() > limit {
            return Err(over_limit(Some(metadata.len()), limit));
        }
        metadata.len()
    } else {
        limit
    };
    check_memory(|| "reading the file".to_owned(), expected)
        .map_err(|error| invalid_data(error.to_string()))?;
    let mut bytes = Vec::with_capacity(if metadata.is_file() {
        expected as usize
    } else {
        0
    });
    let mut reader = file.take(limit.saturating_add(1));
    if stop_at_nul && !metadata.is_file() {
        let mut chunk = vec![0u8; 1 << 16];
        loop {
            let count = match reader.read(&mut chunk) {
                Ok(count) => count,
                Err(error) if error.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(error) => return Err(error),
            };
            let read = &chunk[..count];
            bytes.extend_from_slice(read);
            if count == 0 || read.contains(&0) {
                break;
            }
        }
    } else {
        reader.read_to_end(&mut bytes)?;
    }
    if bytes.len() as u64 > limit {
        return Err(over_limit(None, limit));
    }
    Ok(bytes)
}

fn over_limit(size: Option<u64>, limit: u64) -> std::io::Error {
    invalid_data(match size {
        Some(size) => format!(
            "it is {}, more than the {} this kind of file may be",
            human_bytes(size),
            human_bytes(limit)
        ),
        None => format!(
            "it goes on past {} (the most this kind of file may be) and is not a regular file",
            human_bytes(limit)
        ),
    })
}

fn invalid_data(message: String) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidData, message)
}

/// `1.5 GiB`: sizes in messages, binary units.
pub fn human_bytes(bytes: u64) -> String {
    bytes_with_digits(bytes, 1)
}

/// [`human_bytes`] with `digits` after the point.
fn bytes_with_digits(bytes: u64, digits: usize) -> String {
    const UNITS: [&str; 5] = ["bytes", "KiB", "MiB", "GiB", "TiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} bytes")
    } else {
        format!("{value:.digits$} {}", UNITS[unit])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_that_round_alike_are_printed_with_the_digits_that_tell_them_apart() {
        let refused = |needed, available| {
            TooLarge {
                what: "the grid".to_owned(),
                needed,
                available: Some(available),
            }
            .to_string()
        };
        let gib = 1u64 << 30;
        // 3.6 GiB both, one slightly more: the one-digit form would read alike.
        let text = refused(3_900_000_000, 3_880_000_000);
        assert_eq!(
            text,
            "the grid would need 3.63 GiB, but only 3.61 GiB of memory is available"
        );
        assert_eq!(
            refused(2 * gib, gib),
            "the grid would need 2.0 GiB, but only 1.0 GiB of memory is available"
        );
        assert_eq!(
            refused(3 * gib + 1, 3 * gib),
            "the grid would need 3.000000001 GiB, but only 3.000000000 GiB of memory is available"
        );
    }

    #[test]
    fn a_size_past_any_allocation_is_refused_without_asking_the_system() {
        let error = check_memory(|| "a test grid".to_owned(), u64::MAX).unwrap_err();
        assert_eq!(error.available, None);
        assert!(error.to_string().contains("a test grid"), "{error}");
        assert!(error.to_string().contains("address"), "{error}");
    }

    #[test]
    fn a_small_allocation_passes() {
        check_memory(|| unreachable!("only described when refused"), 1 << 10).unwrap();
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn the_system_reports_what_is_available() {
        let available = available_memory().expect("/proc/meminfo is readable on Linux");
        let error = check_memory(
            || "twice what is free".to_owned(),
            available.saturating_mul(2),
        )
        .unwrap_err();
        assert!(error.available.is_some(), "{error}");
    }

    #[test]
    fn products_saturate_instead_of_wrapping() {
        assert_eq!(bytes_for(1 << 40, 1 << 40), u64::MAX);
        assert_eq!(bytes_for(3, 4), 12);
    }

    #[cfg(unix)]
    #[test]
    fn a_device_is_read_only_up_to_the_limit() {
        let error = read_limited(Path::new("/dev/zero"), 1 << 16).unwrap_err();
        assert_eq!(error.kind(), std::io::ErrorKind::InvalidData);
        assert!(error.to_string().contains("not a regular file"), "{error}");
    }

    #[cfg(unix)]
    #[test]
    fn text_from_a_device_stops_at_its_first_nul() {
        let bytes = read_limited_text(Path::new("/dev/zero"), 1 << 30).unwrap();
        assert!(bytes.len() <= 1 << 16, "{} bytes", bytes.len());
        assert_eq!(bytes.last(), Some(&0));
    }

    #[test]
    fn a_regular_file_over_the_limit_is_refused_before_it_is_read() {
        let folder = tempfile::tempdir().unwrap();
        let path = folder.path().join("big.obj");
        std::fs::write(&path, vec![b'v'; 100]).unwrap();
        let error = read_limited(&path, 99).unwrap_err();
        assert!(error.to_string().contains("100 bytes"), "{error}");
        assert_eq!(read_limited(&path, 100).unwrap().len(), 100);
        assert!(read_limited(folder.path(), 100).is_err());
    }
}
