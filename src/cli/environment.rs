//! The process environment the GPU stack expects.

/// wgpu probes for a Wayland display when it looks for a GL adapter, and
/// libwayland then prints "error: XDG_RUNTIME_DIR is invalid or not set" if the
/// variable is missing (bare X sessions, containers, CI). It is harmless but
/// reads as a failure, so such a process gets a private runtime directory of its
/// own, `pmvc-runtime-UID` in the temporary directory, as the XDG specification
/// describes one: owned by the user, mode 0700. Called first in `main`, before
/// any thread exists.
pub(super) fn ensure_runtime_dir() {
    #[cfg(target_os = "linux")]
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        if let Some(directory) = private_runtime_dir() {
            std::env::set_var("XDG_RUNTIME_DIR", directory);
        }
    }
}

#[cfg(target_os = "linux")]
fn private_runtime_dir() -> Option<std::path::PathBuf> {
    use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
    let uid = std::fs::metadata("/proc/self").ok()?.uid();
    let directory = std::env::temp_dir().join(format!("pmvc-runtime-{uid}"));
    let _ = std::fs::DirBuilder::new().mode(0o700).create(&directory);
    // Someone else's directory, a link, or one others can enter is not ours to use.
    let metadata = std::fs::symlink_metadata(&directory).ok()?;
    let private =
        metadata.is_dir() && metadata.uid() == uid && metadata.permissions().mode() & 0o077 == 0;
    private.then_some(directory)
}

/// Ctrl-C, SIGTERM and SIGHUP end a process without running destructors, which
/// would leave a half-written output's temporary file behind (hundreds of MiB for
/// a large bind). A watcher thread removes those files, then ends the process
/// with the status the signal would have given it (128 + its number).
pub(super) fn remove_unfinished_outputs_on_signals() {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
            return;
        };
        std::thread::spawn(move || {
            if let Some(signal) = signals.forever().next() {
                crate::formats::remove_unfinished_outputs();
                std::process::exit(128 + signal);
            }
        });
    }
}
