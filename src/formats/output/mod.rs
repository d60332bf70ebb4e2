//! Where an output goes, and writing it so that nothing is lost.
//!
//! - A regular file (or a new name) is written through a temporary sibling that is
//!   renamed over it only once complete, so a failure leaves the old file whole.
//! - An existing file that its user may not write (read-only, or someone else's)
//!   is refused, as `cp` refuses it, although a rename could replace it
//!   ([`protect`] has the rule).
//! - A symbolic link is followed: its target is replaced the same way, and the
//!   link stays a link.
//! - A character device or a named pipe (`/dev/null`, `/dev/stdout`, a FIFO) is
//!   written directly: renaming over it would replace the node itself.
//! - A directory, a block device or a socket is refused.
//! - An output that is the same file as an input is refused ([`refuse_same_file`]).
//! - Outputs that belong together (a mesh and its cage) are replaced together or
//!   not at all ([`OutputSet`]); two of them naming one file are refused.
//!
//! While a temporary file is being written it is listed, so that a process ended
//! by a signal can remove it ([`remove_unfinished_outputs`]).

mod protect;
mod set;

pub use set::OutputSet;

use super::error::{shown_path, WriteError};
pub use crate::budget::human_bytes;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Links followed before giving up, as the kernel's own limit for path lookup.
const MAX_LINKS: usize = 40;

/// How an output path is written.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OutputTarget {
    /// A regular file or a new name, with links followed: replaced by rename.
    File(PathBuf),
    /// A character device or a named pipe: written in place.
    Stream(PathBuf),
}

impl OutputTarget {
    /// The path that is finally written, links followed.
    pub fn path(&self) -> &Path {
        match self {
            OutputTarget::File(path) | OutputTarget::Stream(path) => path,
        }
    }
}

fn invalid(message: String) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidInput, message)
}

/// Follow `path`'s symbolic links to what an output there would write.
pub fn resolve_output(path: &Path) -> Result<OutputTarget, WriteError> {
    let wrap = |source| WriteError {
        path: path.to_owned(),
        source,
    };
    let mut current = path.to_owned();
    for _ in 0..=MAX_LINKS {
        let metadata = match std::fs::symlink_metadata(&current) {
            Ok(metadata) => metadata,
            Err(error) if error.kind() == std::io::ErrorKind::NotFound => {
                return Ok(OutputTarget::File(current))
            }
            Err(error) => return Err(wrap(error)),
        };
        let file_type = metadata.file_type();
        if file_type.is_symlink() {
            let target = std::fs::read_link(&current).map_err(wrap)?;
            current = match current.parent() {
                Some(parent) if target.is_relative() => parent.join(target),
                _ => target,
            };
            continue;
        }
        if file_type.is_file() {
            return Ok(OutputTarget::File(current));
        }
        if file_type.is_dir() {
            return Err(wrap(invalid("it is a directory".into())));
        }
        #[cfg(unix)]
        {
            use std::os::unix::fs::FileTypeExt;
            if file_type.is_char_device() || file_type.is_fifo() {
                return Ok(OutputTarget::Stream(current));
            }
            if file_type.is_block_device() {
                return Err(wrap(invalid(
                    "it is a block device, which pmvc never writes".into(),
                )));
            }
        }
        return Err(wrap(invalid(
            "it is neither a regular file nor a device or pipe".into(),
        )));
    }
    Err(wrap(invalid(format!(
        "more than {MAX_LINKS} symbolic links to follow"
    ))))
}

/// Refuse, before any work, an output that [`PendingOutput::create`] would
/// refuse by what is there now: a folder, a block device, a file its user may
/// not write. Nothing is created.
pub fn refuse_unwritable(path: &Path) -> Result<(), WriteError> {
    match resolve_output(path)? {
        OutputTarget::File(target) => protect::refuse_protected(path, &target),
        OutputTarget::Stream(_) => Ok(()),
    }
}

/// Refuse `output` when it is, or links to, the same file as one of `inputs`:
/// replacing an input with a result computed from it loses the input.
pub fn refuse_same_file(output: &Path, inputs: &[&Path]) -> Result<(), WriteError> {
    let target = resolve_output(output)?;
    let Ok(written) = std::fs::metadata(target.path()) else {
        return Ok(()); // a new file is nobody's input
    };
    for input in inputs {
        let Ok(read) = std::fs::metadata(input) else {
            continue;
        };
        if same_file(&written, &read, target.path(), input) {
            return Err(WriteError {
                path: output.to_owned(),
                source: invalid(format!(
                    "it is the input {}, which pmvc never overwrites; choose another output",
                    shown_path(input)
                )),
            });
        }
    }
    Ok(())
}

#[cfg(unix)]
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata, _: &Path, _: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    // A device (`/dev/null` as input and output) is no file to lose.
    a.is_file() && (a.dev(), a.ino()) == (b.dev(), b.ino())
}

#[cfg(not(unix))]
fn same_file(a: &std::fs::Metadata, _: &std::fs::Metadata, pa: &Path, pb: &Path) -> bool {
    a.is_file()
        && matches!(
            (pa.canonicalize(), pb.canonicalize()),
            (Ok(x), Ok(y)) if x == y
        )
}

/// A warning when `path`'s extension is not one of `expected` (lower case, no
/// dot), e.g. weights written to `mesh.obj`. Devices and pipes have no extension
/// to check.
pub fn extension_warning(path: &Path, expected: &[&str], what: &str) -> Option<String> {
    if matches!(resolve_output(path), Ok(OutputTarget::Stream(_))) {
        return None;
    }
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if extension
        .as_deref()
        .is_some_and(|found| expected.contains(&found))
    {
        return None;
    }
    let wanted: Vec<String> = expected.iter().map(|e| format!(".{e}")).collect();
    Some(format!(
        "{}: warning: this file will hold {what}, but its name does not end in {}",
        shown_path(path),
        wanted.join(" or ")
    ))
}

/// Temporary files being written now, for [`remove_unfinished_outputs`].
static UNFINISHED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Remove the temporary files of every write still in progress. For a signal
/// handler that is about to end the process, when destructors will not run.
/// Returns how many were removed.
pub fn remove_unfinished_outputs() -> usize {
    let paths = match UNFINISHED.lock() {
        Ok(paths) => paths.clone(),
        Err(poisoned) => poisoned.into_inner().clone(),
    };
    paths
        .iter()
        .filter(|path| std::fs::remove_file(path).is_ok())
        .count()
}

/// Lists a temporary file in [`UNFINISHED`] while it lives.
struct Listed(PathBuf);

impl Listed {
    fn new(path: &Path) -> Listed {
        if let Ok(mut paths) = UNFINISHED.lock() {
            paths.push(path.to_owned());
        }
        Listed(path.to_owned())
    }
}

impl Drop for Listed {
    fn drop(&mut self) {
        if let Ok(mut paths) = UNFINISHED.lock() {
            paths.retain(|p| p != &self.0);
        }
    }
}

/// An output opened before the work that produces it: its temporary file exists
/// (and is removed on a signal) from the start, so an unwritable folder fails
/// early and the free space can be checked before hours of computing.
pub struct PendingOutput {
    path: PathBuf,
    kind: Pending,
}

enum Pending {
    // Field order matters: the file is deleted before it leaves the list.
    File {
        temporary: tempfile::NamedTempFile,
        target: PathBuf,
        _listed: Listed,
    },
    Stream(PathBuf),
}

impl PendingOutput {
    /// Resolve `path` by the module's rules, refuse a file its user may not
    /// write, and create its temporary file.
    pub fn create(path: &Path) -> Result<PendingOutput, WriteError> {
        let wrap = |source| WriteError {
            path: path.to_owned(),
            source,
        };
        let target = match resolve_output(path)? {
            OutputTarget::Stream(device) => {
                return Ok(PendingOutput {
                    path: path.to_owned(),
                    kind: Pending::Stream(device),
                })
            }
            OutputTarget::File(target) => target,
        };
        protect::refuse_protected(path, &target)?;
        let mut builder = tempfile::Builder::new();
        builder.prefix(".pmvc-").suffix(".tmp");
        // Temporary files are private; the result should have the permissions of
        // the file it replaces, or those of an ordinary new file.
        #[cfg(unix)]
        let permissions = std::fs::metadata(&target)
            .map(|m| m.permissions())
            .unwrap_or_else(|_| {
                use std::os::unix::fs::PermissionsExt;
                std::fs::Permissions::from_mode(0o644)
            });
        #[cfg(unix)]
        builder.permissions(permissions);
        let folder = folder_of(&target);
        let temporary = builder.tempfile_in(folder).map_err(|error| {
            // tempfile names its random file in the error; the user's folder matters.
            match error.kind() {
                std::io::ErrorKind::NotFound => wrap(std::io::Error::new(
                    error.kind(),
                    format!("its folder {} does not exist", shown_path(folder)),
                )),
                _ => wrap(error),
            }
        })?;
        let listed = Listed::new(temporary.path());
        Ok(PendingOutput {
            path: path.to_owned(),
            kind: Pending::File {
                temporary,
                target,
                _listed: listed,
            },
        })
    }

    /// An error unless the file system has room for `bytes` more. Devices and
    /// pipes have no limit to check.
    pub fn check_space(&self, bytes: u64) -> Result<(), WriteError> {
        let Pending::File { target, .. } = &self.kind else {
            return Ok(());
        };
        match free_space(folder_of(target)) {
            Some(free) if free < bytes => Err(WriteError {
                path: self.path.clone(),
                source: std::io::Error::new(
                    std::io::ErrorKind::StorageFull,
                    format!(
                        "it needs {}, but its file system has {} free",
                        human_bytes(bytes),
                        human_bytes(free)
                    ),
                ),
            }),
            _ => Ok(()),
        }
    }

    /// Write the output and, for a file, rename it over the target.
    pub fn finish(
        self,
        write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
    ) -> Result<(), WriteError> {
        self.finish_into(false, |out| write(out))
    }

    /// [`Self::finish`] for formats that seek back (zip archives): a file is
    /// written in place; a device or pipe gets the bytes built in memory first.
    pub fn finish_seekable(
        self,
        write: impl FnOnce(&mut dyn WriteSeek) -> std::io::Result<()>,
    ) -> Result<(), WriteError> {
        self.finish_into(true, write)
    }

    fn finish_into(
        self,
        seeks: bool,
        write: impl FnOnce(&mut dyn WriteSeek) -> std::io::Result<()>,
    ) -> Result<(), WriteError> {
        self.write(seeks, write)?.commit()
    }

    /// Write the output: a file's temporary file completely (made durable), a
    /// device or pipe in place.
    fn write(
        self,
        seeks: bool,
        write: impl FnOnce(&mut dyn WriteSeek) -> std::io::Result<()>,
    ) -> Result<Written, WriteError> {
        let path = self.path;
        let wrap = |source| WriteError {
            path: path.clone(),
            source,
        };
        match self.kind {
            Pending::Stream(device) => {
                let file = open_stream(&device).map_err(wrap)?;
                let mut buffered = std::io::BufWriter::new(file);
                if seeks {
                    // A pipe cannot seek: build the bytes first.
                    let mut bytes = std::io::Cursor::new(Vec::new());
                    write(&mut bytes).map_err(wrap)?;
                    buffered.write_all(bytes.get_ref()).map_err(wrap)?;
                } else {
                    write(&mut buffered).map_err(wrap)?;
                }
                buffered.flush().map_err(wrap)?;
                Ok(Written::Stream)
            }
            Pending::File {
                mut temporary,
                target,
                _listed,
            } => {
                {
                    let mut buffered = std::io::BufWriter::new(temporary.as_file_mut());
                    write(&mut buffered).map_err(wrap)?;
                    buffered.flush().map_err(wrap)?;
                }
                temporary.as_file().sync_all().map_err(wrap)?;
                Ok(Written::File(Finished {
                    path,
                    temporary,
                    target,
                    _listed,
                }))
            }
        }
    }
}

/// An output whose bytes are all written.
enum Written {
    /// A device or pipe: nothing left to do.
    Stream,
    /// A file: its temporary file waits to be renamed over the target.
    File(Finished),
}

impl Written {
    fn commit(self) -> Result<(), WriteError> {
        match self {
            Written::Stream => Ok(()),
            Written::File(finished) => finished.commit(),
        }
    }
}

/// A complete temporary file and the file it replaces.
struct Finished {
    path: PathBuf,
    // Field order matters: the file is deleted before it leaves the list.
    temporary: tempfile::NamedTempFile,
    target: PathBuf,
    _listed: Listed,
}

impl Finished {
    /// Rename the temporary file over the target.
    fn commit(self) -> Result<(), WriteError> {
        let Finished {
            path,
            temporary,
            target,
            _listed,
        } = self;
        temporary.persist(&target).map_err(|error| WriteError {
            path,
            source: error.error,
        })?;
        Ok(())
    }
}

/// A writer that can also seek (an archive's central directory needs it).
pub trait WriteSeek: Write + std::io::Seek {}
impl<T: Write + std::io::Seek> WriteSeek for T {}

/// Write an output by the rules in the module documentation.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), WriteError> {
    PendingOutput::create(path)?.finish(write)
}

/// Open a device or named pipe for writing. Opening a named pipe that no
/// program reads waits until one does: say so first, instead of hanging with
/// no word.
fn open_stream(device: &Path) -> std::io::Result<std::fs::File> {
    #[cfg(unix)]
    {
        use rustix::fs::OFlags;
        use std::os::unix::fs::OpenOptionsExt;
        let without_waiting = std::fs::OpenOptions::new()
            .write(true)
            .custom_flags(OFlags::NONBLOCK.bits() as i32)
            .open(device);
        match without_waiting {
            Ok(file) => {
                let flags = rustix::fs::fcntl_getfl(&file)? - OFlags::NONBLOCK;
                rustix::fs::fcntl_setfl(&file, flags)?;
                return Ok(file);
            }
            Err(error) if error.raw_os_error() == Some(rustix::io::Errno::NXIO.raw_os_error()) => {
                eprintln!(
                    "pmvc: waiting for a program to read the named pipe {}",
                    shown_path(device)
                );
            }
            Err(_) => {}
        }
    }
    std::fs::OpenOptions::new().write(true).open(device)
}

fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    }
}

#[cfg(unix)]
fn free_space(folder: &Path) -> Option<u64> {
    let stats = rustix::fs::statvfs(folder).ok()?;
    Some(stats.f_bavail.saturating_mul(stats.f_frsize))
}

#[cfg(not(unix))]
fn free_space(_: &Path) -> Option<u64> {
    None
}

#[cfg(all(test, unix))]
mod tests;
