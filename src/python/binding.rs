//! `bind` and `deform`. The work runs on its own thread with the GIL released,
//! so other Python threads (and other binds) run meanwhile; the calling thread
//! wakes every [`POLL`] to report progress and to check for Ctrl-C, which
//! cancels the work through its cancel flag and raises `KeyboardInterrupt`
//! once the work has stopped (within one block of rows or one GPU batch).

use super::arguments::{flag, shown, text};
use super::arrays::positions;
use super::bind_arguments::{
    bind_options, dtype_argument, method_argument, method_from, pmvc_kernel_from,
};
use super::errors::{backend_warning, error, Kind};
use super::scene::{cage_argument, PyCage};
use super::weights::PyWeights;
use crate::coords::{
    bind_cpu_f64, AnyWeights, BindOptions, BindProgress, Dtype, DtypeError, Method, Parameter,
};
use crate::formats::metadata::{class_codes, BindRecord, WeightsMetadata};
use crate::gpu::backend_choice::{decide_and_open, BackendRequest, Decision, Work};
use crate::gpu::{Backend, BindConfig, BindError, BindInput, Binder, PmvcKernel};
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How often a waiting call reports progress and checks for signals.
const POLL: Duration = Duration::from_millis(50);

/// How a long call is observed and stopped.
pub(super) struct Interruptible<'a, 'py> {
    /// Ask the work to stop early.
    pub cancel: &'a (dyn Fn() + Sync),
    /// The user's `progress(done, total)` callback.
    pub progress: Option<&'a Bound<'py, PyAny>>,
    /// The work's `(done, total)` now.
    pub done: &'a (dyn Fn() -> (usize, usize) + Sync),
}

/// Run `work` on a thread of its own with the GIL released. Every [`POLL`] the
/// caller reports progress (when it moved: `(0, total)` first, `(total, total)`
/// last on success) and checks for signals; a signal or an exception from the
/// callback cancels the work and is raised once it has stopped.
pub(super) fn run_interruptible<T: Send>(
    py: Python<'_>,
    task: Interruptible<'_, '_>,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    if let Some(callback) = task.progress.filter(|callback| !callback.is_callable()) {
        return Err(error(
            Kind::Input,
            format!(
                "progress: {} is not callable; pass a function of (done, total)",
                callback.get_type().name()?
            ),
        ));
    }
    let finished = AtomicBool::new(false);
    let mut failure: Option<PyErr> = None;
    let mut reported: Option<usize> = None;
    let mut report = |done: usize, total: usize| -> PyResult<()> {
        if let Some(callback) = task.progress {
            if reported != Some(done) {
                reported = Some(done);
                callback.call1((done, total))?;
            }
        }
        Ok(())
    };
    let (_, total) = (task.done)();
    report(0, total)?;
    let outcome = std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let result = work();
            finished.store(true, Ordering::Release);
            result
        });
        loop {
            py.detach(|| {
                let started = Instant::now();
                while !finished.load(Ordering::Acquire) && started.elapsed() < POLL {
                    std::thread::sleep(Duration::from_millis(2));
                }
            });
            if finished.load(Ordering::Acquire) {
                break;
            }
            if failure.is_none() {
                let (done, total) = (task.done)();
                let checked = py.check_signals().and_then(|()| report(done, total));
                if let Err(raised) = checked {
                    (task.cancel)();
                    failure = Some(raised);
                }
            }
        }
        // The worker has finished; joining does not wait.
        worker.join()
    });
    if let Some(raised) = failure {
        return Err(raised);
    }
    let result = outcome.map_err(|_| error(Kind::Bind, "internal error: the work panicked"))?;
    let (_, total) = (task.done)();
    report(total, total)?;
    Ok(result)
}

/// Where a bind of `points` to `cage` runs for "auto", "cpu" or "gpu": the
/// command line's rule ([`crate::gpu::backend_choice`]). Devices are opened once
/// per process.
fn choose_backend(
    py: Python<'_>,
    choice: &str,
    options: BindOptions,
    points: usize,
    cage: &PyCage,
) -> PyResult<Decision> {
    let request = BackendRequest::from_name(choice).ok_or_else(|| {
        error(
            Kind::Parameter,
            format!("backend \"{choice}\" is not one of \"auto\", \"cpu\", \"gpu\""),
        )
    })?;
    let work = Work::of(options, points, &cage.cage);
    if request != BackendRequest::Cpu {
        // Before any GPU probe: libwayland's complaint about a missing
        // XDG_RUNTIME_DIR would otherwise reach stderr once per probe.
        py.import("pmvc._environment")?
            .call_method0("ensure_runtime_dir")?;
    }
    py.detach(|| decide_and_open(request, &work))
        .map_err(|cause| error(Kind::Backend, format!("backend \"{choice}\": {cause}")))
}

/// Bind ``points`` to ``cage`` with one family: a :class:`Weights` whose
/// ``matrix`` is float32 (n, columns), bit-for-bit what ``pmvc bind`` writes;
/// ``dtype=numpy.float64`` keeps every row as computed, in float64 (on the CPU;
/// not for harmonic coordinates, solved in float32 on their grid), as ``pmvc
/// bind --dtype f64``.
///
/// ``method`` is a family id (see :func:`families`); ``resolution`` is PMVC's
/// cube-map resolution (or ``"exact"``: no cube map, the visible cage
/// integrated in closed form on the CPU), ``grid`` the grid of harmonic
/// coordinates, BBW and LBC (``None``: the family's default, 64 for harmonic
/// coordinates, 32 for BBW and LBC), ``poisson_ratio`` Somigliana coordinates'
/// Poisson ratio (default 0); each is read only by its family. A cage's quads are bilinear patches (MVC on them is QMVC);
/// ``triangulate="shorter"`` or ``"longer"`` splits them along that diagonal
/// first, as before quads were patches (Green coordinates on patches are QGC). ``backend`` is ``"auto"`` (the CPU, or a hardware GPU where it
/// is predicted faster for this bind), ``"cpu"`` or ``"gpu"``; families without
/// a GPU kernel bind on the CPU. ``pmvc_kernel`` is PMVC's GPU kernel:
/// ``"auto"``, ``"tiles"`` or ``"bands"`` (as ``pmvc bind --pmvc-kernel``).
/// ``progress``, if given, is called with ``(done, total)`` rows, from
/// ``(0, total)`` to ``(total, total)``. ``strict=True`` raises InputError,
/// before binding, when points lie outside the cage (as ``pmvc bind
/// --strict``). ``cage`` is a :class:`Cage` or libigl's ``(V, F)`` pair. The
/// GIL is released while binding; Ctrl-C cancels within about a second.
#[pyfunction]
#[pyo3(
    signature = (points, cage, method=None, resolution=None, grid=None, poisson_ratio=None, backend=None, progress=None, triangulate=None, pmvc_kernel=None, strict=None, dtype=None),
    text_signature = "(points, cage, method='pmvc', resolution=32, grid=None, poisson_ratio=0.0, backend='auto', progress=None, triangulate=None, pmvc_kernel='auto', strict=False, dtype='float32')"
)]
#[allow(clippy::too_many_arguments)]
pub(super) fn bind<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    cage: &Bound<'py, PyAny>,
    method: Option<Bound<'py, PyAny>>,
    resolution: Option<Bound<'py, PyAny>>,
    grid: Option<Bound<'py, PyAny>>,
    poisson_ratio: Option<Bound<'py, PyAny>>,
    backend: Option<Bound<'py, PyAny>>,
    progress: Option<Bound<'py, PyAny>>,
    triangulate: Option<Bound<'py, PyAny>>,
    pmvc_kernel: Option<Bound<'py, PyAny>>,
    strict: Option<Bound<'py, PyAny>>,
    dtype: Option<Bound<'py, PyAny>>,
) -> PyResult<PyWeights> {
    let method = method_argument(method.as_ref())?;
    let options = bind_options(
        method,
        resolution.as_ref(),
        grid.as_ref(),
        poisson_ratio.as_ref(),
        triangulate.as_ref(),
    )?;
    let how = HowToBind::from_arguments(
        "bind",
        backend.as_ref(),
        pmvc_kernel.as_ref(),
        strict.as_ref(),
        dtype.as_ref(),
    )?;
    let cage = cage_argument(cage)?;
    let points = positions(points, "points")?;
    bind_points(py, points, &cage, options, &how, progress.as_ref())
}

/// Where and by which GPU kernel a bind runs, and whether points outside the
/// cage are an error, as `bind` and `deform` were told.
pub(super) struct HowToBind {
    pub backend: String,
    pub pmvc_kernel: PmvcKernel,
    pub strict: bool,
    pub dtype: Dtype,
}

impl HowToBind {
    /// `backend=`, `pmvc_kernel=`, `strict=` and `dtype=` of `function` (None:
    /// the defaults).
    fn from_arguments<'py>(
        function: &str,
        backend: Option<&Bound<'py, PyAny>>,
        pmvc_kernel: Option<&Bound<'py, PyAny>>,
        strict: Option<&Bound<'py, PyAny>>,
        dtype: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        let given =
            |value: Option<&Bound<'py, PyAny>>| value.filter(|value| !value.is_none()).cloned();
        let backend = match given(backend) {
            Some(value) => text(&value, &format!("{function}: backend"))?,
            None => "auto".to_owned(),
        };
        let pmvc_kernel = match given(pmvc_kernel) {
            Some(value) => pmvc_kernel_from(
                function,
                &text(&value, &format!("{function}: pmvc_kernel"))?,
            )?,
            None => PmvcKernel::Auto,
        };
        let strict = match given(strict) {
            Some(value) => flag(&value, &format!("{function}: strict"))?,
            None => false,
        };
        let dtype = match given(dtype) {
            Some(value) => dtype_argument(&value, function)?,
            None => Dtype::Float32,
        };
        Ok(Self {
            backend,
            pmvc_kernel,
            strict,
            dtype,
        })
    }
}

/// Bind already-checked points; `bind` and `deform` share it.
pub(super) fn bind_points(
    py: Python<'_>,
    points: Vec<glam::DVec3>,
    cage: &PyCage,
    options: BindOptions,
    how: &HowToBind,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyWeights> {
    let dtype = how.dtype;
    dtype
        .check_family(options.method)
        .map_err(|cause| error(Kind::Parameter, format!("bind: {cause}")))?;
    // Float64 weights are computed on the CPU: no GPU is opened for them.
    let backend_asked = match dtype {
        Dtype::Float32 => how.backend.as_str(),
        Dtype::Float64 => {
            if how.backend == "gpu" {
                backend_warning(py, &format!("bind: {}", DtypeError::NotOnGpu))?;
            }
            // Still checked, so that a bad name is an error whatever the dtype.
            BackendRequest::from_name(&how.backend).ok_or_else(|| {
                error(
                    Kind::Parameter,
                    format!(
                        "backend \"{}\" is not one of \"auto\", \"cpu\", \"gpu\"",
                        how.backend
                    ),
                )
            })?;
            "cpu"
        }
    };
    let decision = choose_backend(py, backend_asked, options, points.len(), cage)?;
    let pmvc_kernel = how.pmvc_kernel;
    let on_gpu = decision.on_gpu(options.method);
    if backend_asked == "gpu" && !on_gpu {
        let label = match options.parameter() {
            Some((spec, value)) => format!(
                "{} {}",
                options.family_name(&cage.cage),
                (spec.format)(value)
            ),
            None => options.family_name(&cage.cage),
        };
        backend_warning(
            py,
            &format!("bind: {label} has no GPU kernel; it was bound on the CPU (backend \"gpu\" was asked for)"),
        )?;
    }
    let backend = decision.backend;
    let device = backend.clone();
    let rows = points.len();
    let columns = options.columns(&cage.cage);
    let size = dtype.size();
    crate::budget::check_memory(
        || format!("the weights ({rows} rows × {columns} columns × {size} bytes)"),
        crate::budget::bytes_for(rows as u64, (size * columns) as u64),
    )
    .map_err(|cause| error(Kind::TooLarge, format!("bind: {cause}")))?;
    let points: Arc<[glam::DVec3]> = points.into();
    let shared = BindProgress::new(rows);
    let task = Interruptible {
        cancel: &|| shared.cancel(),
        progress,
        done: &|| (shared.done(), rows),
    };
    let cage_arc = Arc::clone(&cage.cage);
    let bound_points = Arc::clone(&points);
    let strict = how.strict;
    let (classes, outside, result) = run_interruptible(py, task, || {
        let classified = options.classify(&cage_arc, &bound_points);
        let classes: Arc<[_]> = classified.classes.into();
        if strict && !classified.outside.is_empty() {
            return (classes, classified.outside, None);
        }
        let result = match dtype {
            Dtype::Float32 => {
                let input = BindInput {
                    points: Arc::clone(&bound_points),
                    classes: Arc::clone(&classes),
                    cage: cage_arc,
                    options,
                };
                Binder::new(backend)
                    .with_config(BindConfig {
                        pmvc_kernel,
                        ..BindConfig::default()
                    })
                    .bind_blocking(&input, &shared)
                    .and_then(|output| {
                        let weights = output.weights.ok_or(BindError::NothingKept)?;
                        Ok((
                            AnyWeights::F32(weights),
                            output.stats.device,
                            output.stats.elapsed,
                        ))
                    })
            }
            Dtype::Float64 => {
                let started = Instant::now();
                bind_cpu_f64(&bound_points, &classes, &cage_arc, options, &shared)
                    .map(|weights| {
                        (
                            AnyWeights::F64(weights),
                            "CPU".to_owned(),
                            started.elapsed(),
                        )
                    })
                    .map_err(BindError::from)
            }
        };
        (classes, classified.outside, Some(result))
    })?;
    let Some(result) = result else {
        return Err(outside_error(&outside, rows));
    };
    if let Backend::Gpu(context) = &device {
        for notice in context.take_notices() {
            backend_warning(py, &format!("bind: {notice}"))?;
        }
    }
    let (weights, device_name, elapsed) = result.map_err(|cause| bind_error(&cause))?;
    let cage_file = cage
        .path
        .as_deref()
        .map(|path| path.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut metadata = WeightsMetadata::new(&BindRecord {
        options,
        cage: &cage.cage,
        points: &points,
        classes: &classes,
        backend: if on_gpu { "gpu" } else { "cpu" },
        device: &device_name,
        seconds: elapsed.as_secs_f64(),
        mesh_file: "",
        cage_file: &cage_file,
        mesh_object: None,
        cage_object: cage.object.as_deref(),
        weights_file: Path::new(""),
    });
    metadata.dtype = dtype.id().to_owned();
    let codes = class_codes(&classes);
    Ok(PyWeights::new(
        super::weights::matrix_array(py, weights)?,
        numpy::PyArray1::from_vec(py, codes).unbind(),
        metadata,
        options,
    ))
}

/// `strict=True` with points outside the cage: the command line's `--strict`
/// error.
pub(super) fn outside_error(outside: &[u32], rows: usize) -> PyErr {
    error(
        Kind::Input,
        format!(
            "points: {} (strict=True)",
            crate::coords::outside_summary(outside, rows)
        ),
    )
}

fn bind_error(cause: &BindError) -> PyErr {
    use crate::coords::harmonic::HarmonicError;
    use crate::gpu::GpuError;
    let kind = match cause {
        BindError::InvalidInput(_) | BindError::ResolutionTooHigh { .. } => Kind::Parameter,
        BindError::Harmonic(
            HarmonicError::NotEnoughMemory { .. } | HarmonicError::GridTooLarge { .. },
        )
        | BindError::Gpu(GpuError::OutOfMemory(_) | GpuError::TooLarge { .. }) => Kind::TooLarge,
        _ => Kind::Bind,
    };
    error(kind, format!("bind: {cause}"))
}

/// The points moved by the cage's move from ``cage`` to ``deformed_vertices``,
/// float64 (n, 3): what ``pmvc deform`` writes.
///
/// With ``weights`` (from :func:`bind` or :func:`load_weights`), those are
/// applied; they must have been bound for these points and this cage. Without,
/// ``method`` (default ``"pmvc"``) is bound first, with ``resolution``,
/// ``grid``, ``backend``, ``progress``, ``triangulate``, ``pmvc_kernel`` and
/// ``strict`` as :func:`bind` takes them (``strict=True`` with ``weights``
/// refuses weights with rows outside the cage). ``cage`` is a :class:`Cage` or
/// libigl's ``(V, F)`` pair. Each point moves by Σₖ wₖ dₖ, dₖ the move of
/// column k's vector (a cage vertex's position, or for Green coordinates a
/// triangle's scaled normal), summed in float64. ``bulging`` (Somigliana
/// coordinates' γ, 0 to 10, default 0) and ``local_blend`` (their local/global
/// blend, 0 to 1, default 0: the global variant) are read when deforming, so
/// they may be given with ``weights``; the other families ignore them. With a
/// local blend the blocks of each point are normalised by the blended frames
/// (``families()`` lists each family's ``deform_parameters``).
#[pyfunction]
#[pyo3(
    signature = (points, cage, deformed_vertices, weights=None, method=None, **parameters),
    text_signature = "(points, cage, deformed_vertices, weights=None, method='pmvc', **parameters)"
)]
pub(super) fn deform<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    cage: &Bound<'py, PyAny>,
    deformed_vertices: &Bound<'py, PyAny>,
    weights: Option<Bound<'py, PyAny>>,
    method: Option<Bound<'py, PyAny>>,
    parameters: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    // Read when deforming, so given with weights too: `strict` and every
    // family's deformation settings (Somigliana's bulging and local blend).
    let deform_settings = || (Parameter::ALL.into_iter()).filter(|p| p.read_when_deforming());
    let deforming: Vec<&str> = std::iter::once("strict")
        .chain(deform_settings().map(Parameter::id))
        .collect();
    const BINDING: [&str; 9] = [
        "resolution",
        "grid",
        "poisson_ratio",
        "backend",
        "progress",
        "triangulate",
        "pmvc_kernel",
        "strict",
        "dtype",
    ];
    let weights = match weights.filter(|value| !value.is_none()) {
        Some(value) => Some(value.cast_into::<PyWeights>().map_err(|refused| {
            error(
                Kind::Input,
                format!(
                    "deform: weights: {} is not a pmvc.Weights (from bind or load_weights)",
                    shown(refused.into_inner().as_any())
                ),
            )
        })?),
        None => None,
    };
    let parameter = |name: &str| -> PyResult<Option<Bound<'py, PyAny>>> {
        parameters.map_or(Ok(None), |given| given.get_item(name))
    };
    if let Some(given) = parameters {
        for key in given.keys() {
            let key: String = key.extract()?;
            let deforms = deforming.contains(&key.as_str());
            if !deforms && !BINDING.contains(&key.as_str()) {
                let known: Vec<&str> = deforming[1..].iter().chain(&BINDING).copied().collect();
                return Err(error(
                    Kind::Parameter,
                    format!(
                        "deform: unknown parameter \"{key}\" (known: {})",
                        known.join(", ")
                    ),
                ));
            }
            if weights.is_some() && !deforms {
                return Err(error(
                    Kind::Parameter,
                    format!("deform: \"{key}\" is for binding, but weights were given"),
                ));
            }
        }
    }
    let how = HowToBind::from_arguments(
        "deform",
        parameter("backend")?.as_ref(),
        parameter("pmvc_kernel")?.as_ref(),
        parameter("strict")?.as_ref(),
        parameter("dtype")?.as_ref(),
    )?;
    let asked = match method.filter(|value| !value.is_none()) {
        Some(value) => Some(method_from(&text(&value, "deform: method")?)?),
        None => None,
    };
    let cage = cage_argument(cage)?;
    let pose = positions(deformed_vertices, "deformed_vertices")?;
    let expected = cage.cage.vertex_count();
    if pose.len() != expected {
        return Err(error(
            Kind::Input,
            format!(
                "deformed_vertices: {} vertices, but the cage has {expected}; a pose must keep the cage's vertices in order",
                pose.len()
            ),
        ));
    }
    let points = positions(points, "points")?;
    let weights: Bound<'py, PyWeights> = match weights {
        Some(given) => {
            let weights = given.get();
            if let Some(asked) = asked {
                if asked != weights.method() {
                    return Err(error(
                        Kind::Weights,
                        format!(
                            "deform: method \"{}\" was asked for, but the weights are {}",
                            asked.id(),
                            weights.method().id()
                        ),
                    ));
                }
            }
            if how.strict {
                weights.check_strict(py)?;
            }
            given
        }
        None => {
            let options = bind_options(
                asked.unwrap_or(Method::Pmvc),
                parameter("resolution")?.as_ref(),
                parameter("grid")?.as_ref(),
                parameter("poisson_ratio")?.as_ref(),
                parameter("triangulate")?.as_ref(),
            )?;
            let progress = parameter("progress")?.filter(|p| !p.is_none());
            Bound::new(
                py,
                bind_points(py, points.clone(), &cage, options, &how, progress.as_ref())?,
            )?
        }
    };
    let mut deform_values = Vec::new();
    for setting in deform_settings() {
        if let Some(given) = parameter(setting.id())?.filter(|value| !value.is_none()) {
            let value = super::bind_arguments::parameter_value(setting, &given)?;
            deform_values.push((setting, value));
        }
    }
    let deformed = weights
        .get()
        .apply(py, &points, &cage, &pose, &deform_values)?;
    super::arrays::positions_array(py, &deformed)
}
