//! Where a bind runs: the device each request may use, and for `auto` a cost
//! model that predicts the CPU's and the GPU's time for the work and takes the
//! faster. The command line, Python and the editor all decide here.

use super::kernels::{Kernel, PmvcKernel};
use super::{Backend, GpuContext, GpuError};
use crate::coords::{BindOptions, Method};
use crate::geometry::Cage;
use std::sync::{Arc, OnceLock};

/// What the user asked for: `auto`, `cpu` or `gpu`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BackendRequest {
    /// The faster of the two by [`predict`], on a hardware adapter only.
    Auto,
    Cpu,
    /// Any adapter, a software one included.
    Gpu,
}

impl BackendRequest {
    pub const NAMES: [&'static str; 3] = ["auto", "cpu", "gpu"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "auto" => Some(Self::Auto),
            "cpu" => Some(Self::Cpu),
            "gpu" => Some(Self::Gpu),
            _ => None,
        }
    }
}

/// The device a request may bind on, opened once per process: none for `cpu`;
/// for `auto` a hardware adapter's, or none (without listing the adapters where
/// the system has no GPU device node, [`GpuContext::new_hardware`]); for `gpu`
/// the adapter policy's choice or its error.
pub fn device_for(request: BackendRequest) -> Result<Option<Arc<GpuContext>>, GpuError> {
    static ANY: OnceLock<Result<Arc<GpuContext>, GpuError>> = OnceLock::new();
    static HARDWARE: OnceLock<Option<Arc<GpuContext>>> = OnceLock::new();
    match request {
        BackendRequest::Cpu => Ok(None),
        BackendRequest::Gpu => ANY
            .get_or_init(|| GpuContext::new().map(Arc::new))
            .clone()
            .map(Some),
        BackendRequest::Auto => Ok(HARDWARE
            .get_or_init(|| GpuContext::new_hardware().ok().flatten().map(Arc::new))
            .clone()),
    }
}

/// The adapter's kind, as far as speed goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AdapterClass {
    Discrete,
    /// Integrated, virtual or unknown hardware.
    Integrated,
    /// A rasteriser on the CPU's own cores (lavapipe, llvmpipe, WARP).
    Software,
}

impl AdapterClass {
    pub fn of(device_type: wgpu::DeviceType) -> Self {
        match device_type {
            wgpu::DeviceType::DiscreteGpu => Self::Discrete,
            wgpu::DeviceType::Cpu => Self::Software,
            _ => Self::Integrated,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Discrete => "discrete",
            Self::Integrated => "integrated",
            Self::Software => "software",
        }
    }
}

/// The size of a bind, as the model reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Work {
    pub method: Method,
    pub points: usize,
    /// PMVC's cube-map texels per point (6·R²); 0 for the other families.
    pub texels: usize,
    pub cage_triangles: usize,
    pub cage_vertices: usize,
    /// Quads the family binds as bilinear patches (0 when they are split).
    pub cage_quads: usize,
    pub cpu_threads: usize,
    /// Exact PMVC ([`BindOptions::pmvc_exact`]), which has no GPU kernel.
    pub pmvc_exact: bool,
}

impl Work {
    /// `points` bound to `cage` with `options`, on this process's CPU threads.
    pub fn of(options: BindOptions, points: usize, cage: &Cage) -> Self {
        let texels = if options.method == Method::Pmvc && !options.pmvc_exact() {
            let side = options.resolution as usize;
            6 * side * side
        } else {
            0
        };
        Self {
            method: options.method,
            points,
            texels,
            cage_triangles: cage.triangles().len(),
            cage_vertices: cage.vertex_count(),
            cage_quads: match options.split_applied(cage) {
                None => cage.quads().len(),
                Some(_) => 0,
            },
            cpu_threads: rayon::current_num_threads(),
            pmvc_exact: options.pmvc_exact(),
        }
    }

    /// The GPU kernel for this work, if any ([`Kernel::for_cage`]).
    pub fn kernel(&self) -> Option<Kernel> {
        if self.pmvc_exact {
            return None;
        }
        Kernel::of_work(self.method, self.cage_quads > 0)
    }

    /// Why this work has no GPU kernel, when it has none.
    pub fn no_kernel_reason(&self) -> Option<&'static str> {
        match (self.kernel(), Kernel::of(self.method)) {
            (Some(_), _) => None,
            (None, _) if self.pmvc_exact => {
                Some("exact PMVC integrate on the CPU: they have no GPU kernel")
            }
            (None, Some(Kernel::Green)) => {
                Some("Green on a cage with quads is QGC, which has no GPU kernel")
            }
            (None, Some(_)) => Some("MVC on a cage with quads is QMVC, which has no GPU kernel"),
            (None, None) => Some("this family has no GPU kernel"),
        }
    }
}

/// How much of the GPU's start is still to pay before its first batch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pipelines {
    /// Compiled in this process already.
    Ready,
    /// To compile, from a pipeline cache found on disk.
    CacheHit,
    /// To compile from nothing.
    Cold,
}

/// The device's side of the model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuState {
    pub class: AdapterClass,
    pub pipelines: Pipelines,
    /// Seconds still to pay to open the device: 0 once it is open (it always is
    /// when the model runs: the editor's, or the one opened while inputs loaded).
    pub start_s: f64,
}

impl GpuState {
    pub fn of(context: &GpuContext) -> Self {
        let pipelines = if context.kernels_ready() {
            Pipelines::Ready
        } else if context.pipeline_cache().is_hit() {
            Pipelines::CacheHit
        } else {
            Pipelines::Cold
        };
        Self {
            class: AdapterClass::of(context.info.device_type),
            pipelines,
            start_s: 0.0,
        }
    }
}

/// Microseconds per point: `fixed + per_texel·texels + per_triangle·triangles`.
#[derive(Clone, Copy, Debug)]
struct PointCost {
    fixed: f64,
    per_texel: f64,
    per_triangle: f64,
}

impl PointCost {
    fn micros(&self, work: &Work) -> f64 {
        self.fixed
            + self.per_texel * work.texels as f64
            + self.per_triangle * work.cage_triangles as f64
    }
}

/// One family's costs: the CPU path on one effective thread, a discrete GPU,
/// and a software adapter's time as a multiple of the CPU path's.
#[derive(Clone, Copy, Debug)]
struct FamilyCosts {
    kernel: Kernel,
    cpu: PointCost,
    discrete: PointCost,
    software_vs_cpu: f64,
    /// A cage of bilinear patches' time per point against the same cage split,
    /// on the CPU path and on a GPU (1 where quads are never patches here).
    patches_vs_split: Patches,
}

/// Time per point on patches ÷ on the split cage.
#[derive(Clone, Copy, Debug)]
struct Patches {
    cpu: f64,
    gpu: f64,
    software: f64,
}

impl Patches {
    const NONE: Patches = Patches {
        cpu: 1.0,
        gpu: 1.0,
        software: 1.0,
    };

    /// `ratio` scaled by the share of the cage's triangles that are halves of
    /// patches, so that a cage with a few quads costs nearly its split.
    fn factor(ratio: f64, work: &Work) -> f64 {
        if work.cage_triangles == 0 {
            return 1.0;
        }
        let share = (2 * work.cage_quads) as f64 / work.cage_triangles as f64;
        1.0 + (ratio - 1.0) * share.min(1.0)
    }
}

// The model's coefficients, all in one place; recalibrate here when a kernel
// changes (docs/gpu-binding.md, "Device policy", shows the same table).
//
// Sources: `pmvc bench --runs 5` medians, uploads and readbacks included, on an
// NVIDIA H200 with 16 CPU threads (2026-11-26: PMVC 32² Armadillo size 0.087 s
// CPU / 0.035 s GPU, Horse size 0.187 / 0.077, Hand size 0.245 / 0.092, Table 2
// sphere 1523 0.774 / 0.252, MVC Horse size 0.050 / 0.014), the H100 rows of
// docs/benchmarks.md for PMVC 64², and the 2-core rows there for the CPU path
// (Armadillo size PMVC 32² 0.465 s, MVC 0.199 s) and for lavapipe (Armadillo
// size: PMVC by the tile kernel 16-20× the CPU path's time on 2026-11-28, the
// band kernel about 40×; MVC 0.73×). Least-squares by eye over
// those rows; each prediction is within about ±30% of them.
// Green's GPU kernel has no measurement yet: taken as twice MVC's per triangle;
// its CPU path costs about what MVC's does (docs/benchmarks.md, 2026-11-25).
const COSTS: [FamilyCosts; 3] = [
    FamilyCosts {
        kernel: Kernel::Pmvc,
        cpu: PointCost {
            fixed: 22.0,
            per_texel: 0.0027,
            per_triangle: 0.077,
        },
        discrete: PointCost {
            fixed: 0.4,
            per_texel: 0.000_22,
            per_triangle: 0.0025,
        },
        software_vs_cpu: 19.0,
        // `pmvc bench`, 2026-11-28 (docs/benchmarks.md): the 2-core machine's
        // CPU 2.2-3.6 (Ogre, FireHydrant, ManHead) and the H200 host's 16
        // threads 2.4-3.5 (the seven shared models); the H200's band kernel
        // 1.17-1.35 on patches against the same kernel on the split (lavapipe
        // 1.64 on ManHead).
        patches_vs_split: Patches {
            cpu: 3.0,
            gpu: 1.3,
            software: 1.6,
        },
    },
    FamilyCosts {
        kernel: Kernel::Mvc,
        cpu: PointCost {
            fixed: 1.0,
            per_texel: 0.0,
            per_triangle: 0.092,
        },
        discrete: PointCost {
            fixed: 0.02,
            per_texel: 0.0,
            per_triangle: 0.0028,
        },
        // Measured 0.73 in one run ("about as fast on either"); taken as 1 so
        // that a tie stays on the CPU path, whose cores lavapipe would share.
        software_vs_cpu: 1.0,
        patches_vs_split: Patches::NONE,
    },
    FamilyCosts {
        kernel: Kernel::Green,
        cpu: PointCost {
            fixed: 1.0,
            per_texel: 0.0,
            per_triangle: 0.095,
        },
        discrete: PointCost {
            fixed: 0.04,
            per_texel: 0.0,
            per_triangle: 0.0056,
        },
        software_vs_cpu: 1.0,
        patches_vs_split: Patches::NONE,
    },
];

/// The tile kernel's discrete-GPU cost per point, µs (PMVC on the cages of
/// triangles it takes; `FamilyCosts::discrete` is the band kernel's). Fitted to
/// `pmvc bench --runs 5 --pmvc-kernels tiles,bands` on an NVIDIA H200
/// (2026-11-28): PMVC 32² Horse size 0.97 µs a point, Armadillo size 1.67, Hand
/// size 2.94, Table 2 spheres of 98 to 800 triangles 1.13 to 4.5; 64² Horse
/// size 2.39. Its cost grows about twice as fast with the cage as the band
/// kernel's, so past about 500 triangles the band kernel is faster.
const PMVC_TILES_DISCRETE: PointCost = PointCost {
    fixed: 0.03,
    per_texel: 0.000_077,
    per_triangle: 0.0048,
};
/// Below this many triangles the tile kernel lost to the band kernel on the
/// H200 (the 12-triangle box cages SpikyBox and WireSphere: 0.083 s against
/// 0.036 s and 0.055 against 0.029), though the model above predicts it faster.
const PMVC_TILES_MIN_TRIANGLES: usize = 16;

/// Whether PMVC on `work`'s cage binds faster by the tile kernel than by the band
/// kernel on a GPU, by the model (for a cage the tile kernel can take).
pub fn tiles_predicted_faster(work: &Work) -> bool {
    let bands = COSTS
        .iter()
        .find(|costs| costs.kernel == Kernel::Pmvc)
        .map_or(f64::INFINITY, |costs| costs.discrete.micros(work));
    work.cage_triangles >= PMVC_TILES_MIN_TRIANGLES && PMVC_TILES_DISCRETE.micros(work) <= bands
}

/// CPU threads scale as `threads^0.8` (16 threads of the H200 host did about
/// 9.2 times one thread's work; 2 threads about 1.7 times).
const CPU_THREAD_EXPONENT: f64 = 0.8;
/// A discrete GPU's time per bind besides its points, its device and its
/// kernels: buffers, the first batch's round trip, and giving the device back at
/// exit. With the two below it makes the 0.18–0.25 s by which the H200's whole
/// `--backend gpu` process exceeded `--backend cpu` on scenes whose binds take
/// 0.02–0.1 s (2026-11-26, docs/benchmarks.md, "Start-up and the pipeline cache").
const GPU_BIND_FIXED_S: f64 = 0.03;
/// An integrated GPU's time per point, in discrete ones' (not measured: a
/// guess to recalibrate when one is).
const INTEGRATED_VS_DISCRETE: f64 = 8.0;
/// Compiling the three binding kernels, in seconds: (no cache, cache hit).
/// Hardware: the H200 machine's first one-point `--backend gpu` bind took 0.75 s,
/// later ones 0.25–0.30 s with the pipeline cache hit, 0.14–0.18 s of each
/// opening the device. Software: lavapipe on the 2-core machine, a one-point
/// bind's whole process 0.15–0.19 s against 0.008 s on the CPU, 0.05 s of it
/// opening the device; Mesa 22.3's lavapipe keeps nothing in its pipeline cache,
/// so a hit saves nothing there (docs/benchmarks.md).
const COMPILE_HARDWARE_S: (f64, f64) = (0.45, 0.05);
const COMPILE_SOFTWARE_S: (f64, f64) = (0.14, 0.14);

/// The model's two predictions for a bind, in seconds, and its choice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prediction {
    /// The CPU path; `None` for a family the model has no figures for.
    pub cpu_s: Option<f64>,
    /// The GPU, start still to pay included; `None` for a family without a kernel.
    pub gpu_s: Option<f64>,
    pub work: Work,
    pub gpu: GpuState,
}

impl Prediction {
    /// Whether the GPU is predicted faster. A family without a kernel or without
    /// figures binds on the CPU.
    pub fn gpu_wins(&self) -> bool {
        matches!((self.cpu_s, self.gpu_s), (Some(cpu), Some(gpu)) if gpu < cpu)
    }

    /// One line: both predictions and what they rest on.
    pub fn explain(&self) -> String {
        if self.gpu_s.is_none() {
            return match self.work.no_kernel_reason() {
                Some(reason) if Kernel::of(self.work.method).is_some() => reason.to_owned(),
                _ => format!("{} has no GPU kernel", self.work.method.name()),
            };
        }
        let seconds =
            |s: Option<f64>| s.map_or_else(|| "not modelled".into(), |s| format!("{s:.3} s"));
        let pipelines = match self.gpu.pipelines {
            Pipelines::Ready => "kernels compiled",
            Pipelines::CacheHit => "pipeline cache hit",
            Pipelines::Cold => "no pipeline cache: kernels compiled from nothing",
        };
        let start = if self.gpu.start_s > 0.0 {
            format!(
                "; at best, with {:.2} s to open the device",
                self.gpu.start_s
            )
        } else {
            String::new()
        };
        // Which PMVC kernel the GPU's time is for (software adapters are
        // modelled from the CPU path, whichever kernel runs).
        let kernel = match (self.work.kernel(), self.gpu.class) {
            (Some(Kernel::Pmvc), AdapterClass::Software) => "",
            (Some(Kernel::Pmvc), _) => match PmvcKernel::Auto.takes_tiles(&self.work) {
                Ok(true) => "PMVC tile kernel, ",
                _ => "PMVC band kernel, ",
            },
            _ => "",
        };
        format!(
            "predicted CPU {} ({} threads), GPU {} ({}, {kernel}{pipelines}{start})",
            seconds(self.cpu_s),
            self.work.cpu_threads,
            seconds(self.gpu_s),
            self.gpu.class.name(),
        )
    }
}

/// The model: the CPU's and the GPU's time for `work` on a device in `gpu`'s state.
pub fn predict(work: &Work, gpu: &GpuState) -> Prediction {
    let costs = work
        .kernel()
        .and_then(|kernel| COSTS.iter().find(|costs| costs.kernel == kernel));
    let Some(costs) = costs else {
        return Prediction {
            cpu_s: None,
            gpu_s: None,
            work: *work,
            gpu: *gpu,
        };
    };
    let points = work.points as f64;
    let threads = (work.cpu_threads.max(1) as f64).powf(CPU_THREAD_EXPONENT);
    let cpu_patches = Patches::factor(costs.patches_vs_split.cpu, work);
    let gpu_patches = Patches::factor(costs.patches_vs_split.gpu, work);
    let cpu_s = cpu_patches * points * costs.cpu.micros(work) * 1e-6 / threads;
    let (cold, warm) = match gpu.class {
        AdapterClass::Software => COMPILE_SOFTWARE_S,
        _ => COMPILE_HARDWARE_S,
    };
    let compile_s = match gpu.pipelines {
        Pipelines::Ready => 0.0,
        Pipelines::CacheHit => warm,
        Pipelines::Cold => cold,
    };
    let tiles = costs.kernel == Kernel::Pmvc && PmvcKernel::Auto.takes_tiles(work).unwrap_or(false);
    let per_point = if tiles {
        PMVC_TILES_DISCRETE.micros(work)
    } else {
        costs.discrete.micros(work)
    };
    let gpu_points = gpu_patches * points * per_point * 1e-6;
    let run_s = match gpu.class {
        AdapterClass::Discrete => GPU_BIND_FIXED_S + gpu_points,
        AdapterClass::Integrated => GPU_BIND_FIXED_S + INTEGRATED_VS_DISCRETE * gpu_points,
        AdapterClass::Software => {
            let software_patches = Patches::factor(costs.patches_vs_split.software, work);
            costs.software_vs_cpu * cpu_s * software_patches / cpu_patches
        }
    };
    Prediction {
        cpu_s: Some(cpu_s),
        gpu_s: Some(gpu.start_s + compile_s + run_s),
        work: *work,
        gpu: *gpu,
    }
}

/// Where a bind runs, and for `auto` with a device the prediction behind it.
#[derive(Clone, Debug)]
pub struct Decision {
    pub backend: Backend,
    pub prediction: Option<Prediction>,
    /// Why the bind runs on the CPU when no prediction says so.
    pub reason: Option<&'static str>,
    /// The GPU kernel for the work decided on ([`Work::kernel`]); without one
    /// the bind runs on the CPU whatever the backend.
    pub kernel: Option<Kernel>,
}

impl Decision {
    /// Whether GPU kernels compute the weights (a family without one, or MVC on
    /// a cage with quads, binds on the CPU on every backend).
    pub fn on_gpu(&self, method: Method) -> bool {
        matches!(self.backend, Backend::Gpu(_))
            && self.kernel.is_some()
            && Kernel::of(method).is_some()
    }

    /// One line for the user: where and, for `auto`, why.
    pub fn explain(&self) -> String {
        let place = match &self.backend {
            Backend::Gpu(context) if self.kernel.is_some() => format!(
                "GPU {} (device opened in {:.3} s; pipeline cache: {})",
                context.info.name,
                context.opened_in().as_secs_f64(),
                context.pipeline_cache().describe()
            ),
            _ => "CPU".to_owned(),
        };
        match (&self.prediction, self.reason) {
            (Some(prediction), _) => format!("binding on the {place}: {}", prediction.explain()),
            (None, Some(reason)) => format!("binding on the {place}: {reason}"),
            (None, None) => format!("binding on the {place}"),
        }
    }
}

/// Seconds to list the adapters and open a hardware device, before any kernel
/// compiles: 0.14–0.18 s on the H200 machine (`pmvc bind --verbose`, 2026-11-26).
pub const HARDWARE_START_S: f64 = 0.15;

/// The best a hardware GPU could do for `work` with its device still to open: a
/// discrete adapter whose kernels are in the pipeline cache.
pub fn best_gpu_case(work: &Work) -> Prediction {
    predict(
        work,
        &GpuState {
            class: AdapterClass::Discrete,
            pipelines: Pipelines::CacheHit,
            start_s: HARDWARE_START_S,
        },
    )
}

/// The one rule, device included, for callers that have none open yet (the
/// command line, Python): `cpu` loads no driver; `gpu` opens the adapter
/// policy's choice; `auto` binds on the CPU without loading any driver when even
/// [`best_gpu_case`] loses, and otherwise opens a hardware device and [`decide`]s
/// on its real state.
pub fn decide_and_open(request: BackendRequest, work: &Work) -> Result<Decision, GpuError> {
    if request == BackendRequest::Auto {
        let best = best_gpu_case(work);
        if !best.gpu_wins() {
            return Ok(Decision {
                backend: Backend::Cpu,
                prediction: Some(best),
                reason: None,
                kernel: work.kernel(),
            });
        }
    }
    let device = device_for(request)?;
    Ok(decide(request, device.as_ref(), work))
}

/// The one rule: `cpu` binds on the CPU, `gpu` on `device`, `auto` on `device`
/// only where [`predict`] says it is faster than the CPU path for `work`.
pub fn decide(request: BackendRequest, device: Option<&Arc<GpuContext>>, work: &Work) -> Decision {
    let Some(context) = device.filter(|_| request != BackendRequest::Cpu) else {
        return Decision {
            backend: Backend::Cpu,
            prediction: None,
            reason: (request == BackendRequest::Auto).then_some("no hardware GPU adapter"),
            kernel: work.kernel(),
        };
    };
    if request == BackendRequest::Gpu {
        // Kept on a kernel-less family too: the binder then runs on the CPU, and
        // the line says why.
        return Decision {
            backend: Backend::Gpu(Arc::clone(context)),
            prediction: None,
            reason: work.no_kernel_reason(),
            kernel: work.kernel(),
        };
    }
    let prediction = predict(work, &GpuState::of(context));
    Decision {
        backend: if prediction.gpu_wins() {
            Backend::Gpu(Arc::clone(context))
        } else {
            Backend::Cpu
        },
        prediction: Some(prediction),
        reason: None,
        kernel: work.kernel(),
    }
}

#[cfg(test)]
#[path = "backend_choice_tests.rs"]
mod tests;
