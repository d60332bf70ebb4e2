//! Binding in the background, one job at a time, so the viewport stays
//! interactive.
//!
//! The queue holds the current scene prepared once: the points and the cage in
//! `Arc`s, and the points' inside/outside classes, computed by the first job that
//! binds the cage's quads one way (as patches, or split along a diagonal:
//! classes are taken against the cage bound, [`BindOptions::classify`]) and
//! shared by every later one that binds them the same way. Each job runs [`crate::gpu::Binder::bind_blocking`]
//! on a thread of its own with a shared [`BindProgress`], and calls the editor's
//! wake callback when it ends, so nothing polls. Dropping or replacing a job
//! cancels it.

use crate::coords::{BindOptions, BindProgress, Method, QuadSplit, WeightQuality, Weights};
use crate::geometry::{Cage, PointClass};
use crate::gpu::backend_choice::{decide, BackendRequest, Work};
use crate::gpu::{Backend, BindConfig, BindError, BindInput, Binder};
use crate::render::weight_chunks::ChunkLimits;
use glam::DVec3;
use std::collections::VecDeque;
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

/// What a finished bind hands back.
#[derive(Debug)]
pub struct BindOutcome {
    pub weights: Arc<Weights>,
    /// Mesh vertices outside the cage bound (its quads split if the job split
    /// them), ascending.
    pub outside: Arc<[u32]>,
    /// Wall-clock time of classification (for the first job) and binding.
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
    #[error("binding {method} failed: {source}")]
    Failed { method: Method, source: BindError },
    #[error("the binding thread could not start: {0}")]
    ThreadSpawn(String),
    #[error("the binding thread stopped without a result")]
    Vanished,
}

/// A job that ended, with the options it ran with.
#[derive(Debug)]
pub struct Finished {
    pub options: BindOptions,
    pub result: Result<BindOutcome, JobError>,
    /// Whether it ran on the GPU (`auto` may put a job on the CPU).
    pub on_gpu: bool,
}

/// Each point's class and the points outside, shared by every job of a scene
/// that binds the cage's quads the same way.
type Classified = (Arc<[PointClass]>, Arc<[u32]>);

/// The classes of a scene, one entry per way its quads were bound
/// ([`BindOptions::split_applied`]): at most three.
type ClassesBySplit = Vec<(Option<QuadSplit>, Classified)>;

/// The scene every job binds, prepared once.
#[derive(Clone)]
struct Prepared {
    points: Arc<[DVec3]>,
    cage: Arc<Cage>,
    /// Filled in by the first job that classifies the points for its split.
    classes: Arc<Mutex<ClassesBySplit>>,
}

struct Running {
    options: BindOptions,
    on_gpu: bool,
    progress: Arc<BindProgress>,
    started: Instant,
    receiver: mpsc::Receiver<Result<BindOutcome, JobError>>,
}

/// A snapshot of the running job, for the progress bar.
#[derive(Clone, Copy, Debug)]
pub struct JobStatus {
    pub options: BindOptions,
    pub done: usize,
    pub total: usize,
    pub fraction: f32,
    pub elapsed: Duration,
    /// Linear extrapolation from the rate so far; `None` until something is done.
    pub remaining: Option<Duration>,
    pub cancelling: bool,
}

type Wake = Arc<dyn Fn() + Send + Sync>;

pub struct BindQueue {
    /// The editor's device, or the CPU (asked for, none usable, or after a failure).
    backend: Backend,
    request: BackendRequest,
    wake: Wake,
    prepared: Option<Prepared>,
    running: Option<Running>,
    pending: VecDeque<BindOptions>,
    /// Jobs started so far.
    started: usize,
    /// (done, total) of the last job when it ended.
    last_progress: Option<(usize, usize)>,
}

impl BindQueue {
    /// A queue binding on `backend` as `request` says: for `auto`, each job on
    /// the device or the CPU, whichever [`crate::gpu::backend_choice`] predicts
    /// faster for it. `wake` is called from a job's thread when it ends (the
    /// editor passes its repaint request).
    pub fn new(
        backend: Backend,
        request: BackendRequest,
        wake: impl Fn() + Send + Sync + 'static,
    ) -> Self {
        Self {
            backend,
            request,
            wake: Arc::new(wake),
            prepared: None,
            running: None,
            pending: VecDeque::new(),
            started: 0,
            last_progress: None,
        }
    }

    pub fn backend(&self) -> &Backend {
        &self.backend
    }

    /// Bind on the CPU from now on (after a GPU failure: the CPU path always works).
    pub fn fall_back_to_cpu(&mut self) {
        self.backend = Backend::Cpu;
    }

    /// Bind `points` to `cage` from now on; running and queued jobs are dropped.
    pub fn set_scene(&mut self, points: Arc<[DVec3]>, cage: Arc<Cage>) {
        self.cancel();
        self.running = None;
        self.prepared = Some(Prepared {
            points,
            cage,
            classes: Arc::new(Mutex::new(Vec::new())),
        });
    }

    /// Queue a bind with `options` unless the same weights are running or queued.
    /// Returns whether it was queued.
    pub fn request(&mut self, options: BindOptions) -> bool {
        let on_the_way = self
            .running
            .as_ref()
            .is_some_and(|r| r.options.same_weights_as(&options) && !r.progress.is_cancelled())
            || self.pending.iter().any(|o| o.same_weights_as(&options));
        if on_the_way {
            return false;
        }
        self.pending.push_back(options);
        self.launch_next();
        true
    }

    /// Queue `options` before everything else (a retry after a failure).
    pub fn request_first(&mut self, options: BindOptions) {
        self.pending.push_front(options);
        self.launch_next();
    }

    /// Whether a bind of `method` is running or queued.
    pub fn is_binding_method(&self, method: Method) -> bool {
        self.running
            .as_ref()
            .is_some_and(|r| r.options.method == method)
            || self.pending.iter().any(|o| o.method == method)
    }

    /// Drop the queued binds of `method` and cancel its running one.
    pub fn drop_method(&mut self, method: Method) {
        self.pending.retain(|o| o.method != method);
        if let Some(running) = &self.running {
            if running.options.method == method {
                running.progress.cancel();
            }
        }
    }

    /// Cancel the running bind and those queued after it.
    pub fn cancel(&mut self) {
        self.pending.clear();
        if let Some(running) = &self.running {
            running.progress.cancel();
        }
    }

    /// A bind is running or queued.
    pub fn is_busy(&self) -> bool {
        self.running.is_some() || !self.pending.is_empty()
    }

    pub fn status(&self) -> Option<JobStatus> {
        let running = self.running.as_ref()?;
        let (done, total) = (running.progress.done(), running.progress.total());
        let elapsed = running.started.elapsed();
        let remaining = (done > 0).then(|| {
            Duration::from_secs_f64(elapsed.as_secs_f64() / done as f64 * (total - done) as f64)
        });
        Some(JobStatus {
            options: running.options,
            done,
            total,
            fraction: running.progress.fraction(),
            elapsed,
            remaining,
            cancelling: running.progress.is_cancelled(),
        })
    }

    /// Jobs started so far.
    pub fn jobs_started(&self) -> usize {
        self.started
    }

    /// (done, total) of the last job when it ended.
    pub fn last_progress(&self) -> Option<(usize, usize)> {
        self.last_progress
    }

    /// The job that ended since the last call, if any; the next one starts.
    pub fn poll(&mut self) -> Option<Finished> {
        let running = self.running.take()?;
        let result = match running.receiver.try_recv() {
            Ok(result) => result,
            Err(mpsc::TryRecvError::Empty) => {
                self.running = Some(running);
                return None;
            }
            Err(mpsc::TryRecvError::Disconnected) => Err(JobError::Vanished),
        };
        Some(self.finish(running, result))
    }

    /// Block until the running job ends or `timeout` passes (tests, screenshots).
    pub fn wait(&mut self, timeout: Duration) -> Option<Finished> {
        let running = self.running.take()?;
        let result = match running.receiver.recv_timeout(timeout) {
            Ok(result) => result,
            Err(mpsc::RecvTimeoutError::Timeout) => {
                self.running = Some(running);
                return None;
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => Err(JobError::Vanished),
        };
        Some(self.finish(running, result))
    }

    fn finish(&mut self, running: Running, result: Result<BindOutcome, JobError>) -> Finished {
        self.last_progress = Some((running.progress.done(), running.progress.total()));
        if matches!(result, Err(JobError::Cancelled)) {
            self.pending.clear();
        }
        let finished = Finished {
            options: running.options,
            result,
            on_gpu: running.on_gpu,
        };
        if !matches!(finished.result, Err(JobError::Failed { .. })) {
            // After a failure the editor decides (it may retry on the CPU first).
            self.launch_next();
        }
        finished
    }

    /// Start the next queued job if none runs.
    pub fn launch_next(&mut self) {
        if self.running.is_some() {
            return;
        }
        let (Some(prepared), Some(options)) = (self.prepared.clone(), self.pending.pop_front())
        else {
            return;
        };
        let progress = Arc::new(BindProgress::new(prepared.points.len()));
        let (sender, receiver) = mpsc::channel();
        let worker_progress = Arc::clone(&progress);
        let device = match &self.backend {
            Backend::Gpu(context) => Some(context),
            Backend::Cpu => None,
        };
        let work = Work::of(options, prepared.points.len(), &prepared.cage);
        let decision = decide(self.request, device, &work);
        let on_gpu = decision.on_gpu(options.method);
        let backend = decision.backend;
        let wake = Arc::clone(&self.wake);
        let started = Instant::now();
        let spawned = std::thread::Builder::new()
            .name("pmvc-bind-job".into())
            .spawn(move || {
                let result = run(&prepared, options, backend, &worker_progress, started);
                // The receiver is gone when the editor dropped the job; nothing to do.
                let _ = sender.send(result);
                wake();
            });
        let receiver = match spawned {
            Ok(_) => receiver,
            Err(error) => {
                let (sender, receiver) = mpsc::channel();
                let _ = sender.send(Err(JobError::ThreadSpawn(error.to_string())));
                receiver
            }
        };
        self.started += 1;
        self.running = Some(Running {
            options,
            on_gpu,
            progress,
            started,
            receiver,
        });
    }
}

impl Drop for BindQueue {
    fn drop(&mut self) {
        // A closed editor must not keep the CPU or GPU busy.
        self.cancel();
    }
}

fn run(
    prepared: &Prepared,
    options: BindOptions,
    backend: Backend,
    progress: &BindProgress,
    started: Instant,
) -> Result<BindOutcome, JobError> {
    let (classes, outside) = {
        // Held while classifying, so two jobs never classify the same scene twice.
        let mut cached = prepared
            .classes
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        let split = options.split_applied(&prepared.cage);
        match cached.iter().find(|(key, _)| *key == split) {
            Some((_, classified)) => classified.clone(),
            None => {
                let classified = options.classify(&prepared.cage, &prepared.points);
                let classified: Classified = (classified.classes.into(), classified.outside.into());
                cached.push((split, classified.clone()));
                classified
            }
        }
    };
    if progress.is_cancelled() {
        return Err(JobError::Cancelled);
    }
    // CPU weights serve export and hover read-outs; on a GPU the renderer reads the
    // resident copy when it fits one storage binding, and uploads the CPU weights in
    // chunks when it does not, or when the job ran on the CPU.
    let gpu_buffer = match &backend {
        Backend::Gpu(context) => {
            let columns = options.columns(&prepared.cage);
            let rows_per_chunk = ChunkLimits::of(&context.limits).rows_per_chunk(columns);
            prepared.points.len() as u64 <= rows_per_chunk
        }
        Backend::Cpu => false,
    };
    let binder = Binder::new(backend).with_config(BindConfig {
        cpu_weights: true,
        gpu_buffer,
        ..Default::default()
    });
    let input = BindInput {
        points: Arc::clone(&prepared.points),
        classes,
        cage: Arc::clone(&prepared.cage),
        options,
    };
    match binder.bind_blocking(&input, progress) {
        Ok(output) => {
            let weights = output.weights.ok_or(JobError::Failed {
                method: options.method,
                source: BindError::NothingKept,
            })?;
            let quality = WeightQuality::measure_family(
                &weights,
                &prepared.points,
                options.method,
                &options.cage_to_bind(&prepared.cage),
                &outside,
            );
            Ok(BindOutcome {
                quality,
                weights: Arc::new(weights),
                outside,
                elapsed: started.elapsed(),
                device: output.stats.device,
                resident: output.gpu_weights.map(|resident| resident.buffer),
            })
        }
        Err(BindError::Cancelled) => Err(JobError::Cancelled),
        Err(source) => Err(JobError::Failed {
            method: options.method,
            source,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::generalized_winding_number;
    use crate::geometry::procedural_quads::twisted_box;

    /// Points in a shell around the bent sides of [`twisted_box`], where a bent
    /// patch and its two triangles disagree, away from its top and bottom.
    fn shell_points() -> Vec<DVec3> {
        let mut points = Vec::new();
        for a in 0..48 {
            let angle = (a as f64 + 0.37) * std::f64::consts::TAU / 48.0;
            for r in 0..12 {
                let radius = 0.7 + 0.75 * (r as f64 + 0.41) / 12.0;
                for z in 0..8 {
                    let height = 0.3 + 1.4 * (z as f64 + 0.53) / 8.0;
                    points.push(DVec3::new(
                        radius * angle.cos(),
                        radius * angle.sin(),
                        height,
                    ));
                }
            }
        }
        points
    }

    /// A bind that splits the cage's quads reports as outside the points outside
    /// the triangles it bound, not outside the patches it did not use, and its
    /// PMVC rows are never negative elsewhere.
    #[test]
    fn a_split_bind_reports_the_outside_of_the_cage_it_bound() {
        let cage = Arc::new(twisted_box(2.0, 0.6));
        let points: Arc<[DVec3]> = shell_points().into();
        let mut queue = BindQueue::new(Backend::Cpu, BackendRequest::Cpu, || {});
        queue.set_scene(Arc::clone(&points), Arc::clone(&cage));
        let mut differing = 0;
        for split in [QuadSplit::None, QuadSplit::Shorter, QuadSplit::Longer] {
            let options = BindOptions {
                quads: split,
                resolution: 8,
                ..BindOptions::for_method(Method::Pmvc)
            };
            assert!(queue.request(options));
            let finished = queue.wait(Duration::from_secs(120)).expect("the bind ends");
            let outcome = finished.result.expect("the bind succeeds");
            let outside: Vec<u32> = if split == QuadSplit::None {
                crate::geometry::classify_points(&cage, &points).outside
            } else {
                // The split cage's own winding number.
                let bound = cage.split_quads(split);
                (0..points.len() as u32)
                    .filter(|&i| generalized_winding_number(&bound, points[i as usize]) < 0.5)
                    .collect()
            };
            let by_patches = crate::geometry::classify_points(&cage, &points).outside;
            differing += outside.len().abs_diff(by_patches.len());
            let wrong = outside.len().abs_diff(outcome.outside.len());
            assert_eq!(
                &*outcome.outside,
                outside.as_slice(),
                "{split:?}: {wrong} rows off"
            );
            let weights = &outcome.weights;
            for row in (0..points.len()).filter(|&i| outside.binary_search(&(i as u32)).is_err()) {
                let min = weights
                    .row(row)
                    .iter()
                    .copied()
                    .fold(f32::INFINITY, f32::min);
                assert!(min >= 0.0, "{split:?}: row {row} inside has a weight {min}");
            }
        }
        assert!(
            differing >= 100,
            "the splits change only {differing} classes"
        );
    }
}
