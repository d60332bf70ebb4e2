//! Progress and cancellation of a bind, shared with whoever watches it.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Progress and cancellation shared between a running bind and its observers:
/// the one progress type of every bind, CPU or GPU, command line or editor.
#[derive(Debug, Default)]
pub struct BindProgress {
    total: usize,
    done: AtomicUsize,
    cancel: AtomicBool,
}

impl BindProgress {
    /// Progress of a bind of `total` rows.
    pub fn new(total: usize) -> Self {
        Self {
            total,
            ..Self::default()
        }
    }

    /// Rows finished so far; never decreases, never exceeds [`Self::total`] once
    /// a total is set.
    pub fn done(&self) -> usize {
        let done = self.done.load(Ordering::Relaxed);
        if self.total > 0 {
            done.min(self.total)
        } else {
            done
        }
    }

    pub fn total(&self) -> usize {
        self.total
    }

    /// Share done, in [0, 1]; 1 for an empty bind.
    pub fn fraction(&self) -> f32 {
        if self.total == 0 {
            1.0
        } else {
            self.done() as f32 / self.total as f32
        }
    }

    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    pub fn advance(&self, rows: usize) {
        self.done.fetch_add(rows, Ordering::Relaxed);
    }
}

/// The bind was cancelled; no weights were produced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("binding was cancelled")]
pub struct Cancelled;
