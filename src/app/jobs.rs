//! Background jobs. Binding runs on its own thread so the viewport stays
//! interactive; the UI polls a [`BindJob`] each frame for progress and the result.
//!
//! This is the seam where the GPU binder will plug in: the UI only uses
//! `start`, `done`, `total`, `elapsed`, `estimated_remaining`, `cancel` and `poll`.

use crate::coords::{bind_cpu, BindOptions, BindProgress, Cancelled, Weights};
use crate::geometry::{classify_points, Cage};
use glam::DVec3;
use std::sync::mpsc;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// What a finished bind hands back.
#[derive(Debug)]
pub struct BindOutcome {
    pub weights: Arc<Weights>,
    /// Mesh vertices outside the cage, ascending.
    pub outside: Vec<u32>,
    pub options: BindOptions,
    /// Wall-clock time of classification and binding.
    pub elapsed: Duration,
}

/// A bind running on a background thread.
pub struct BindJob {
    progress: Arc<BindProgress>,
    total: usize,
    started: Instant,
    options: BindOptions,
    receiver: mpsc::Receiver<Result<BindOutcome, Cancelled>>,
}

impl BindJob {
    /// Start binding `points` to `cage`. `wake` is called from the worker when it
    /// finishes (the UI passes `request_repaint`, so an idle window notices).
    pub fn start(
        points: Arc<Vec<DVec3>>,
        cage: Arc<Cage>,
        options: BindOptions,
        wake: impl Fn() + Send + 'static,
    ) -> Self {
        let progress = Arc::new(BindProgress::default());
        let (sender, receiver) = mpsc::channel();
        let total = points.len();
        let worker_progress = Arc::clone(&progress);
        let started = Instant::now();
        std::thread::Builder::new()
            .name("pmvc-bind".into())
            .spawn(move || {
                let classes = classify_points(&cage, &points);
                let result = bind_cpu(&points, &classes.classes, &cage, options, &worker_progress)
                    .map(|weights| BindOutcome {
                        weights: Arc::new(weights),
                        outside: classes.outside,
                        options,
                        elapsed: started.elapsed(),
                    });
                // The receiver is gone when the editor dropped the job; nothing to do.
                let _ = sender.send(result);
                wake();
            })
            .expect("the OS can spawn a thread");
        Self {
            progress,
            total,
            started,
            options,
            receiver,
        }
    }

    pub fn options(&self) -> BindOptions {
        self.options
    }

    /// Mesh vertices bound so far.
    pub fn done(&self) -> usize {
        self.progress.done().min(self.total)
    }

    pub fn total(&self) -> usize {
        self.total
    }

    /// Fraction done, in [0, 1].
    pub fn fraction(&self) -> f32 {
        if self.total == 0 {
            1.0
        } else {
            self.done() as f32 / self.total as f32
        }
    }

    pub fn elapsed(&self) -> Duration {
        self.started.elapsed()
    }

    /// Linear extrapolation from the rate so far; `None` until something is done.
    pub fn estimated_remaining(&self) -> Option<Duration> {
        let done = self.done();
        if done == 0 {
            return None;
        }
        let per_vertex = self.elapsed().as_secs_f64() / done as f64;
        Some(Duration::from_secs_f64(
            per_vertex * (self.total - done) as f64,
        ))
    }

    /// Ask the worker to stop; `poll` then reports `Err(Cancelled)`.
    pub fn cancel(&self) {
        self.progress.cancel();
    }

    pub fn is_cancelling(&self) -> bool {
        self.progress.is_cancelled()
    }

    /// The result, once the worker has finished.
    pub fn poll(&mut self) -> Option<Result<BindOutcome, Cancelled>> {
        match self.receiver.try_recv() {
            Ok(result) => Some(result),
            Err(mpsc::TryRecvError::Empty) => None,
            // The worker panicked: report it as a cancel so the editor stays usable.
            Err(mpsc::TryRecvError::Disconnected) => Some(Err(Cancelled)),
        }
    }

    /// Block until the worker finishes (for tests and `--screenshot`).
    pub fn wait(&mut self, timeout: Duration) -> Option<Result<BindOutcome, Cancelled>> {
        self.receiver.recv_timeout(timeout).ok()
    }
}

impl Drop for BindJob {
    fn drop(&mut self) {
        // A replaced job must not keep the CPU busy.
        self.progress.cancel();
    }
}
