//! Outputs replaced together or not at all: a mesh and the cage made for it.

use super::{folder_of, resolve_output, Finished, OutputTarget, PendingOutput, WriteSeek, Written};
use crate::formats::{shown_path, WriteError};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Outputs that belong together. Each is written to its own temporary file, and
/// only when all of them are complete are they renamed over their targets, one
/// right after another. What is guaranteed:
///
/// - a failure while writing any of them (a full disk, a missing folder) leaves
///   every target as it was;
/// - a failure renaming one of them puts back those already renamed: until all
///   are renamed, each existing target is kept under a second name in its folder
///   (a hard link, or a copy where the file system has none), which is then
///   renamed back over the new file; a target that did not exist is removed;
/// - a device or pipe among them is written in place when its turn comes: it has
///   no earlier content to keep.
///
/// Not covered: the process ending without running its code (power loss,
/// `kill -9`) between two renames, which are microseconds apart; the earlier
/// version then stays beside its file as `.pmvc-*.old`.
pub struct OutputSet {
    outputs: Vec<PendingOutput>,
}

impl OutputSet {
    /// Open every output by the module's rules (their temporary files exist from
    /// now on), refusing two outputs that name one file, however spelled.
    pub fn create(paths: &[&Path]) -> Result<OutputSet, WriteError> {
        let mut identities: Vec<Option<Identity>> = Vec::with_capacity(paths.len());
        for (index, path) in paths.iter().enumerate() {
            let identity = identity(path)?;
            let earlier = identity.as_ref().and_then(|id| {
                identities[..index]
                    .iter()
                    .position(|e| e.as_ref() == Some(id))
            });
            if let Some(earlier) = earlier {
                return Err(WriteError {
                    path: path.to_path_buf(),
                    source: std::io::Error::new(
                        std::io::ErrorKind::InvalidInput,
                        format!(
                            "it is the same file as the output {}; each output needs a file of its own",
                            shown_path(paths[earlier])
                        ),
                    ),
                });
            }
            identities.push(identity);
        }
        let outputs = paths
            .iter()
            .map(|path| PendingOutput::create(path))
            .collect::<Result<_, _>>()?;
        Ok(OutputSet { outputs })
    }

    /// An error unless output `index`'s file system has room for `bytes` more
    /// ([`PendingOutput::check_space`]).
    pub fn check_space(&self, index: usize, bytes: u64) -> Result<(), WriteError> {
        self.outputs
            .get(index)
            .map_or(Ok(()), |output| output.check_space(bytes))
    }

    /// Write output `index` with `write(index, out)`, for each in order, then
    /// replace the targets by the rules above.
    pub fn finish(
        self,
        mut write: impl FnMut(usize, &mut dyn Write) -> std::io::Result<()>,
    ) -> Result<(), WriteError> {
        self.finish_into(false, |index, out| write(index, out))
    }

    /// [`Self::finish`] for outputs that seek back while written (zip archives).
    pub fn finish_seekable(
        self,
        write: impl FnMut(usize, &mut dyn WriteSeek) -> std::io::Result<()>,
    ) -> Result<(), WriteError> {
        self.finish_into(true, write)
    }

    fn finish_into(
        self,
        seeks: bool,
        mut write: impl FnMut(usize, &mut dyn WriteSeek) -> std::io::Result<()>,
    ) -> Result<(), WriteError> {
        let mut files = Vec::with_capacity(self.outputs.len());
        for (index, output) in self.outputs.into_iter().enumerate() {
            if let Written::File(finished) = output.write(seeks, |out| write(index, out))? {
                files.push(finished);
            }
        }
        let mut kept = Vec::with_capacity(files.len());
        for finished in &files {
            kept.push(keep_earlier(finished)?);
        }
        let mut replaced = Vec::with_capacity(files.len());
        for (finished, earlier) in files.into_iter().zip(kept) {
            let (path, target) = (finished.path.clone(), finished.target.clone());
            if let Err(error) = finished.commit() {
                return Err(put_back(replaced, error));
            }
            replaced.push(Replaced {
                path,
                target,
                earlier,
            });
        }
        // Dropping `replaced` removes the earlier versions.
        Ok(())
    }
}

/// What makes two outputs one file: the same file, or for a new name the same
/// folder and name. Devices and pipes have none: two outputs may share one.
#[derive(PartialEq)]
enum Identity {
    #[cfg(unix)]
    File(u64, u64),
    Name(PathBuf),
}

fn identity(path: &Path) -> Result<Option<Identity>, WriteError> {
    let target = match resolve_output(path)? {
        OutputTarget::Stream(_) => return Ok(None),
        OutputTarget::File(target) => target,
    };
    #[cfg(unix)]
    if let Ok(metadata) = std::fs::metadata(&target) {
        use std::os::unix::fs::MetadataExt;
        return Ok(Some(Identity::File(metadata.dev(), metadata.ino())));
    }
    if let Ok(existing) = target.canonicalize() {
        return Ok(Some(Identity::Name(existing)));
    }
    let folder = folder_of(&target);
    let folder = folder.canonicalize().unwrap_or_else(|_| folder.to_owned());
    Ok(Some(Identity::Name(match target.file_name() {
        Some(name) => folder.join(name),
        None => target,
    })))
}

/// A target renamed over, and its earlier version when it had one.
struct Replaced {
    path: PathBuf,
    target: PathBuf,
    earlier: Option<tempfile::NamedTempFile<()>>,
}

/// Keep the regular file at `finished`'s target under a second name beside it,
/// so that it can be put back.
fn keep_earlier(finished: &Finished) -> Result<Option<tempfile::NamedTempFile<()>>, WriteError> {
    let target = &finished.target;
    if !std::fs::symlink_metadata(target).is_ok_and(|m| m.is_file()) {
        return Ok(None);
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix(".pmvc-").suffix(".old");
    let folder = folder_of(target);
    builder
        .make_in(folder, |kept| std::fs::hard_link(target, kept))
        .or_else(|_| builder.make_in(folder, |kept| copy_new(target, kept)))
        .map(Some)
        .map_err(|source| WriteError {
            path: finished.path.clone(),
            source: std::io::Error::new(
                source.kind(),
                format!("cannot keep its earlier version while the outputs are replaced: {source}"),
            ),
        })
}

/// Copy `from` to the new file `to` with its permissions; nothing is left at
/// `to` when that fails.
fn copy_new(from: &Path, to: &Path) -> std::io::Result<()> {
    let mut source = std::fs::File::open(from)?;
    let mut copy = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(to)?;
    let copied = std::io::copy(&mut source, &mut copy)
        .and_then(|_| copy.set_permissions(source.metadata()?.permissions()))
        .and_then(|()| copy.sync_all());
    if copied.is_err() {
        let _ = std::fs::remove_file(to);
    }
    copied
}

/// Undo the renames in `replaced` after `error`, newest first; the error says
/// what was put back, or where an earlier version is when it could not be.
fn put_back(replaced: Vec<Replaced>, error: WriteError) -> WriteError {
    let mut notes = Vec::new();
    for Replaced {
        path,
        target,
        earlier,
    } in replaced.into_iter().rev()
    {
        let shown = shown_path(&path);
        match earlier {
            Some(earlier) => match earlier.persist(&target) {
                Ok(()) => notes.push(format!("{shown} was put back as it was")),
                Err(failed) => {
                    let kept = failed.file.keep().map(|(_, kept)| shown_path(&kept));
                    notes.push(format!(
                        "{shown} could not be put back ({}); its earlier version is {}",
                        failed.error,
                        kept.unwrap_or_else(|_| "lost".to_owned())
                    ));
                }
            },
            None => match std::fs::remove_file(&target) {
                Ok(()) => notes.push(format!("{shown}, new, was removed again")),
                Err(failed) => notes.push(format!(
                    "{shown} is new and could not be removed again ({failed})"
                )),
            },
        }
    }
    if notes.is_empty() {
        return error;
    }
    WriteError {
        path: error.path,
        source: std::io::Error::new(
            error.source.kind(),
            format!("{}; {}", error.source, notes.join("; ")),
        ),
    }
}
