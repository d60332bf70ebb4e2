//! A bind as a job: CPU (via [`coords::bind_cpu`]) or GPU, on a background thread,
//! with monotone progress, cancellation and no partial results.
//!
//! GPU binds run in batches of rows sized to about [`DEFAULT_BATCH_TARGET`] each on
//! the adapter in use (each batch is timed and the next one resized), so progress
//! moves smoothly and a cancel takes effect within one batch. Every batch is read
//! back into the CPU matrix and/or copied into a resident GPU matrix, so device
//! buffers stay within `max_storage_buffer_binding_size` whatever the mesh size.
//!
//! The GPU computes the rows of `Inside` points. The CPU (f64, [`coords::weights_at`])
//! fills the rows of points on the surface or outside, and redoes the rows the
//! kernels flag: PMVC points whose rays escape, MVC points too close to a cage
//! vertex, triangle or triangle plane for f32, Green rows that miss their
//! identities (Σφ = 1, the rest pose) by more than f32 rounding.
//!
//! On a cage with quads, PMVC's kernel takes them as bilinear patches; MVC there
//! is QMVC, which has no kernel, so such a bind runs on the CPU whatever the
//! backend ([`crate::gpu::kernels::Kernel::for_cage`]); Green coordinates bind
//! the cage's triangles, as on the CPU.

mod buffers;
mod gpu_bind;
mod topology;

use super::context::GpuContext;
use super::kernels::PmvcKernel;
use super::GpuError;
use crate::coords::{self, BindOptions, BindProgress, Weights};
use crate::geometry::{Cage, PointClass};
use glam::DVec3;
use gpu_bind::GpuBind;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Wall time per GPU batch that adaptive batching aims for.
pub const DEFAULT_BATCH_TARGET: Duration = Duration::from_millis(75);

/// Where a bind runs.
#[derive(Clone, Debug)]
pub enum Backend {
    Cpu,
    Gpu(Arc<GpuContext>),
}

/// How many rows each GPU batch binds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BatchSize {
    /// Time each batch and resize the next towards this wall time.
    Adaptive { target: Duration },
    /// Exactly this many rows per batch (clamped to the device limits); for tests.
    Fixed(usize),
}

impl Default for BatchSize {
    fn default() -> Self {
        BatchSize::Adaptive {
            target: DEFAULT_BATCH_TARGET,
        }
    }
}

/// What a bind keeps, and how it batches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BindConfig {
    /// Read the weights back into [`BindOutput::weights`].
    pub cpu_weights: bool,
    /// Keep the weights in a GPU storage buffer ([`BindOutput::gpu_weights`]); GPU
    /// backend only.
    pub gpu_buffer: bool,
    pub batch: BatchSize,
    /// Which PMVC kernel binds (`Auto`: the tile kernel where the cage allows it).
    pub pmvc_kernel: PmvcKernel,
}

impl Default for BindConfig {
    fn default() -> Self {
        Self {
            cpu_weights: true,
            gpu_buffer: false,
            batch: BatchSize::default(),
            pmvc_kernel: PmvcKernel::Auto,
        }
    }
}

/// Everything a bind reads. The points, their classes and the cage are shared, so
/// one prepared scene serves the binds of every method without copies.
#[derive(Clone, Debug)]
pub struct BindInput {
    pub points: Arc<[DVec3]>,
    /// From [`BindOptions::classify`] for the same points, cage and options:
    /// against the cage bound, its quads split if the options split them.
    pub classes: Arc<[PointClass]>,
    pub cage: Arc<Cage>,
    pub options: BindOptions,
}

impl BindInput {
    /// Classify `points` against the cage `options` bind (the slow part of
    /// preparing a bind; [`BindOptions::classify`]) and bind them with `options`.
    pub fn classify(points: Arc<[DVec3]>, cage: Arc<Cage>, options: BindOptions) -> Self {
        let classes = options.classify(&cage, &points).classes;
        Self {
            points,
            classes: classes.into(),
            cage,
            options,
        }
    }

    /// The same points and cage with other options. The classes are kept: they
    /// must split the cage's quads as `options` do
    /// ([`BindOptions::split_applied`]).
    pub fn with_options(&self, options: BindOptions) -> Self {
        Self {
            options,
            ..self.clone()
        }
    }
}

/// Dense row-major f32 weights (same layout as [`Weights`]) in a GPU buffer with
/// `STORAGE | COPY_SRC | COPY_DST` usage.
#[derive(Clone, Debug)]
pub struct GpuWeights {
    pub buffer: wgpu::Buffer,
    pub rows: usize,
    pub cols: usize,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct BindStats {
    /// Wall time of the whole bind, uploads and readbacks included.
    pub elapsed: Duration,
    pub batches: usize,
    /// Rows computed by the GPU kernels.
    pub gpu_rows: usize,
    /// Rows computed on the CPU: on the surface, outside, or flagged by a kernel.
    pub cpu_rows: usize,
    /// Time from each batch's submission until its status was read back: the
    /// kernel, its copies and the wait, against the host's share of `elapsed`.
    pub gpu_wait: Duration,
    /// Where it ran.
    pub device: String,
}

#[derive(Debug)]
pub struct BindOutput {
    pub weights: Option<Weights>,
    pub gpu_weights: Option<GpuWeights>,
    pub stats: BindStats,
}

#[derive(Debug, thiserror::Error)]
pub enum BindError {
    #[error("binding was cancelled")]
    Cancelled,
    #[error(transparent)]
    Gpu(#[from] GpuError),
    #[error("invalid bind input: {0}")]
    InvalidInput(String),
    #[error("the GPU kernels support cube-map resolutions up to {max}, not {asked}")]
    ResolutionTooHigh { asked: u32, max: u32 },
    #[error("{method} has no GPU kernel; bind it on the CPU")]
    NoGpuKernel { method: coords::Method },
    #[error("a GPU bind must keep its weights on the CPU, the GPU or both")]
    NothingKept,
    #[error("could not start the binding thread: {0}")]
    ThreadSpawn(String),
    #[error("the binding thread panicked")]
    Panicked,
    #[error(transparent)]
    Harmonic(coords::harmonic::HarmonicError),
}

impl From<coords::Cancelled> for BindError {
    fn from(_: coords::Cancelled) -> Self {
        BindError::Cancelled
    }
}

impl From<coords::BindFailure> for BindError {
    fn from(failure: coords::BindFailure) -> Self {
        match failure {
            coords::BindFailure::Cancelled(_) => BindError::Cancelled,
            coords::BindFailure::Harmonic(error) => BindError::Harmonic(error),
            coords::BindFailure::Parameter(error) => BindError::InvalidInput(error.to_string()),
            coords::BindFailure::TooLarge(error) => BindError::InvalidInput(error.to_string()),
            coords::BindFailure::Somigliana(error) => BindError::InvalidInput(error.to_string()),
        }
    }
}

/// Starts binds on a backend.
#[derive(Clone, Debug)]
pub struct Binder {
    pub backend: Backend,
    pub config: BindConfig,
}

impl Binder {
    pub fn new(backend: Backend) -> Self {
        Self {
            backend,
            config: BindConfig::default(),
        }
    }

    pub fn with_config(mut self, config: BindConfig) -> Self {
        self.config = config;
        self
    }

    /// Start binding on a background thread.
    pub fn start(&self, input: BindInput) -> BindHandle {
        self.start_with_wake(input, || {})
    }

    /// Start binding on a background thread; `wake` runs on that thread once the
    /// result is ready (the editor passes its repaint request, so nothing polls).
    pub fn start_with_wake(
        &self,
        input: BindInput,
        wake: impl FnOnce() + Send + 'static,
    ) -> BindHandle {
        let progress = Arc::new(BindProgress::new(input.points.len()));
        let worker_progress = Arc::clone(&progress);
        let backend = self.backend.clone();
        let config = self.config;
        let thread = std::thread::Builder::new()
            .name("pmvc-bind".into())
            .spawn(move || {
                let result = run(&input, &backend, config, &worker_progress);
                wake();
                result
            });
        match thread {
            Ok(thread) => BindHandle {
                progress,
                thread: Some(thread),
                early: None,
            },
            Err(error) => BindHandle {
                progress,
                thread: None,
                early: Some(Err(BindError::ThreadSpawn(error.to_string()))),
            },
        }
    }

    /// Bind on the calling thread; for the command line and `pmvc bench` (the
    /// elapsed time in [`BindStats`] includes uploads and readbacks). `progress`
    /// may be shared with a progress bar.
    pub fn bind_blocking(
        &self,
        input: &BindInput,
        progress: &BindProgress,
    ) -> Result<BindOutput, BindError> {
        run(input, &self.backend, self.config, progress)
    }
}

/// A running bind. Dropping it cancels the bind.
#[derive(Debug)]
pub struct BindHandle {
    progress: Arc<BindProgress>,
    thread: Option<JoinHandle<Result<BindOutput, BindError>>>,
    /// A result known before any thread ran.
    early: Option<Result<BindOutput, BindError>>,
}

impl BindHandle {
    /// The bind's progress: rows done of the total, and its cancel flag.
    pub fn progress(&self) -> &Arc<BindProgress> {
        &self.progress
    }

    /// Ask the bind to stop; it ends with [`BindError::Cancelled`] within one batch.
    pub fn cancel(&self) {
        self.progress.cancel();
    }

    pub fn is_finished(&self) -> bool {
        self.thread.as_ref().is_none_or(JoinHandle::is_finished)
    }

    /// The result once finished; `None` while running or after it was taken.
    pub fn try_take(&mut self) -> Option<Result<BindOutput, BindError>> {
        if let Some(result) = self.early.take() {
            return Some(result);
        }
        if !self.thread.as_ref()?.is_finished() {
            return None;
        }
        self.thread.take().map(join)
    }

    /// Wait for the result.
    pub fn wait(mut self) -> Result<BindOutput, BindError> {
        if let Some(result) = self.early.take() {
            return result;
        }
        match self.thread.take() {
            Some(thread) => join(thread),
            // `try_take` already returned the result; waiting again is a caller bug
            // that must not hang.
            None => Err(BindError::Cancelled),
        }
    }
}

impl Drop for BindHandle {
    fn drop(&mut self) {
        if self.thread.is_some() {
            self.progress.cancel();
        }
    }
}

fn join(thread: JoinHandle<Result<BindOutput, BindError>>) -> Result<BindOutput, BindError> {
    thread.join().unwrap_or(Err(BindError::Panicked))
}

fn run(
    input: &BindInput,
    backend: &Backend,
    config: BindConfig,
    progress: &BindProgress,
) -> Result<BindOutput, BindError> {
    validate(input)?;
    let started = Instant::now();
    let options = input.options;
    let patches = input.cage.has_quads() && options.split_applied(&input.cage).is_none();
    let has_kernel = !options.pmvc_exact()
        && crate::gpu::kernels::Kernel::of_work(options.method, patches).is_some();
    match backend {
        Backend::Gpu(_) if has_kernel && !config.cpu_weights && !config.gpu_buffer => {
            Err(BindError::NothingKept)
        }
        Backend::Gpu(context) if has_kernel => {
            let mut output = GpuBind::new(context, input, config)?.run(progress)?;
            output.stats.elapsed = started.elapsed();
            Ok(output)
        }
        // The CPU backend, and families without a GPU kernel on any backend (MVC on
        // quads among them).
        _ => {
            let weights = coords::bind_cpu(
                &input.points,
                &input.classes,
                &input.cage,
                input.options,
                progress,
            )?;
            Ok(BindOutput {
                weights: Some(weights),
                gpu_weights: None,
                stats: BindStats {
                    elapsed: started.elapsed(),
                    batches: 1,
                    gpu_rows: 0,
                    cpu_rows: input.points.len(),
                    gpu_wait: Duration::ZERO,
                    device: "CPU".into(),
                },
            })
        }
    }
}

fn validate(input: &BindInput) -> Result<(), BindError> {
    let invalid = |message: String| Err(BindError::InvalidInput(message));
    if input.points.len() != input.classes.len() {
        return invalid(format!(
            "{} points but {} classes",
            input.points.len(),
            input.classes.len()
        ));
    }
    // The cage was validated when it was built; only the points are checked here.
    let triangles = input.cage.triangle_count();
    let on_missing_triangle = input.classes.iter().any(
        |c| matches!(c, PointClass::OnSurface { triangle, .. } if *triangle as usize >= triangles),
    );
    if on_missing_triangle {
        return invalid("a point is classed on a triangle the cage does not have".into());
    }
    if let Err(error) = input.options.validate() {
        return invalid(error.to_string());
    }
    if let Some(index) = input.points.iter().position(|p| !p.is_finite()) {
        return invalid(format!("point {} is not finite", index + 1));
    }
    Ok(())
}
