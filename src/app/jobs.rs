//! Background jobs. Binding runs on its own thread so the viewport stays
//! interactive; the UI polls a [`BindJob`] each frame for progress and the result.
//!
//! The bind itself goes through [`crate::gpu::Binder`]: on the editor's own wgpu
//! device when that is a hardware GPU, on the CPU otherwise (a software adapter
//! such as lavapipe binds several times slower than the CPU path, see
//! docs/gpu-binding.md). The job's thread first classifies the points, then
//! forwards the binder's progress and the editor's cancel.

use crate::coords::{BindOptions, WeightQuality, Weights};
use crate::geometry::{classify_points, Cage};
use crate::gpu::{Backend, BindConfig, BindError, BindInput, Binder};
use glam::DVec3;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How often the job's thread forwards progress and cancel requests.
const POLL_INTERVAL: Duration = Duration::from_millis(15);

/// What a finished bind hands back.
#[derive(Debug)]
pub struct BindOutcome {
    pub weights: Arc<Weights>,
    /// Mesh vertices outside the cage, ascending.
    pub outside: Vec<u32>,
    pub options: BindOptions,
    /// Wall-clock time of classification and binding.
    pub elapsed: Duration,
    /// Where it ran, e.g. "CPU" or the GPU's name.
    pub device: String,
    /// The same weights left in GPU memory by a bind on the editor's own device,
    /// for the vertex shader to read without a round trip through the CPU.
    pub resident: Option<wgpu::Buffer>,
    /// Measured on the job's thread, so the UI never stalls on it.
    pub quality: WeightQuality,
}

/// Why a bind produced no weights.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    #[error("binding was cancelled")]
    Cancelled,
    #[error("binding failed: {0}")]
    Failed(String),
}

/// Progress and cancel shared between the UI and the job's thread.
#[derive(Debug, Default)]
struct Shared {
    done: AtomicUsize,
    cancel: AtomicBool,
}

/// A bind running on a background thread. Dropping it cancels the bind.
pub struct BindJob {
    shared: Arc<Shared>,
    total: usize,
    started: Instant,
    options: BindOptions,
    receiver: mpsc::Receiver<Result<BindOutcome, JobError>>,
}

impl BindJob {
    /// Start binding `points` to `cage` on `backend`. `wake` is called from the
    /// worker when it finishes (the UI passes `request_repaint`, so an idle window
    /// notices).
    pub fn start(
        points: Arc<Vec<DVec3>>,
        cage: Arc<Cage>,
        options: BindOptions,
        backend: Backend,
        wake: impl Fn() + Send + 'static,
    ) -> Self {
        let shared = Arc::new(Shared::default());
        let (sender, receiver) = mpsc::channel();
        let total = points.len();
        let worker = Arc::clone(&shared);
        let started = Instant::now();
        let spawned = std::thread::Builder::new()
            .name("pmvc-bind-job".into())
            .spawn(move || {
                let result = run(&points, &cage, options, backend, &worker, started);
                // The receiver is gone when the editor dropped the job; nothing to do.
                let _ = sender.send(result);
                wake();
            });
        let (fallback_sender, fallback_receiver) = mpsc::channel();
        let receiver = match spawned {
            Ok(_) => receiver,
            Err(error) => {
                let _ = fallback_sender.send(Err(JobError::Failed(format!(
                    "could not start the binding thread: {error}"
                ))));
                fallback_receiver
            }
        };
        Self {
            shared,
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
        self.shared.done.load(Ordering::Relaxed).min(self.total)
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
        self.shared.cancel.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelling(&self) -> bool {
        self.shared.cancel.load(Ordering::Relaxed)
    }

    /// The result, once the worker has finished.
    pub fn poll(&mut self) -> Option<Result<BindOutcome, JobError>> {
        match self.receiver.try_recv() {
            Ok(result) => Some(result),
            Err(mpsc::TryRecvError::Empty) => None,
            Err(mpsc::TryRecvError::Disconnected) => {
                Some(Err(JobError::Failed("the binding thread stopped".into())))
            }
        }
    }

    /// Block until the worker finishes (for tests and `--screenshot`).
    pub fn wait(&mut self, timeout: Duration) -> Option<Result<BindOutcome, JobError>> {
        self.receiver.recv_timeout(timeout).ok()
    }
}

impl Drop for BindJob {
    fn drop(&mut self) {
        // A replaced job must not keep the CPU or GPU busy.
        self.cancel();
    }
}

fn run(
    points: &[DVec3],
    cage: &Cage,
    options: BindOptions,
    backend: Backend,
    shared: &Shared,
    started: Instant,
) -> Result<BindOutcome, JobError> {
    let classes = classify_points(cage, points);
    if shared.cancel.load(Ordering::Relaxed) {
        return Err(JobError::Cancelled);
    }
    // CPU weights serve export and hover read-outs; on a GPU the renderer reads the
    // resident copy.
    let gpu_buffer = matches!(backend, Backend::Gpu(_));
    let binder = Binder::new(backend).with_config(BindConfig {
        cpu_weights: true,
        gpu_buffer,
        ..Default::default()
    });
    let mut handle = binder.start(BindInput {
        points: points.to_vec(),
        classes: classes.classes,
        cage: cage.clone(),
        options,
    });
    let result = loop {
        if shared.cancel.load(Ordering::Relaxed) {
            handle.cancel();
        }
        shared.done.store(handle.progress().0, Ordering::Relaxed);
        if let Some(result) = handle.try_take() {
            break result;
        }
        std::thread::sleep(POLL_INTERVAL);
    };
    match result {
        Ok(output) => {
            shared.done.store(points.len(), Ordering::Relaxed);
            let weights = output
                .weights
                .ok_or_else(|| JobError::Failed("the binder returned no weights".into()))?;
            let elapsed = started.elapsed();
            let quality = WeightQuality::measure(&weights, points, &cage.positions);
            Ok(BindOutcome {
                quality,
                weights: Arc::new(weights),
                outside: classes.outside,
                options,
                elapsed,
                device: output.stats.device,
                resident: output.gpu_weights.map(|resident| resident.buffer),
            })
        }
        Err(BindError::Cancelled) => Err(JobError::Cancelled),
        Err(error) => Err(JobError::Failed(error.to_string())),
    }
}
