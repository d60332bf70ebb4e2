//! Compute pipelines for the binding kernels and the bind group layout they share.

use super::GpuError;

use super::backend_choice::{self, Work};
use super::shader_source::compose;
use crate::coords::Method;
use crate::geometry::Cage;
use std::sync::OnceLock;

/// The families that have a GPU kernel. The rest bind on the CPU whatever the
/// backend, so a new family needs no change here until it gets a kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    Mvc,
    Pmvc,
    Green,
}

impl Kernel {
    pub fn of(method: Method) -> Option<Kernel> {
        match method {
            Method::Mvc => Some(Kernel::Mvc),
            Method::Pmvc => Some(Kernel::Pmvc),
            Method::Green => Some(Kernel::Green),
            _ => None,
        }
    }

    /// The kernel that binds `method` on `cage` (the cage the family binds, see
    /// `BindOptions::cage_to_bind`). MVC on a cage with quads is QMVC and Green
    /// is QGC, which have none: those binds run on the CPU.
    pub fn for_cage(method: Method, cage: &Cage) -> Option<Kernel> {
        Self::of_work(method, cage.has_quads())
    }

    /// [`Kernel::for_cage`] from the method and whether the cage keeps patches.
    pub fn of_work(method: Method, patches: bool) -> Option<Kernel> {
        match Self::of(method) {
            Some(Kernel::Mvc | Kernel::Green) if patches => None,
            kernel => kernel,
        }
    }
}

const PMVC_SOURCE: &str = include_str!("../../shaders/bind_pmvc.wgsl");
const PMVC_TILES_SOURCE: &str = include_str!("../../shaders/bind_pmvc_tiles.wgsl");
const MVC_SOURCE: &str = include_str!("../../shaders/bind_mvc.wgsl");
const GREEN_SOURCE: &str = include_str!("../../shaders/bind_green.wgsl");

/// The shared files are compiled in, so only a broken build can fail here.
fn composed(name: &str, source: &str) -> String {
    compose(name, source).unwrap_or_else(|error| panic!("{error}"))
}

/// The binding kernels' WGSL with imports resolved, by file name; PMVC's with
/// its patch code, as the quad pipeline compiles it.
pub fn kernel_sources() -> [(&'static str, String); 4] {
    [
        ("bind_pmvc.wgsl", composed("bind_pmvc.wgsl", PMVC_SOURCE)),
        (
            "bind_pmvc_tiles.wgsl",
            composed("bind_pmvc_tiles.wgsl", PMVC_TILES_SOURCE),
        ),
        ("bind_mvc.wgsl", composed("bind_mvc.wgsl", MVC_SOURCE)),
        ("bind_green.wgsl", composed("bind_green.wgsl", GREEN_SOURCE)),
    ]
}

/// PMVC's kernel for cages of triangles: the patch functions stubbed out, so
/// that the driver never compiles code that cannot run (about 0.06 s more on
/// lavapipe).
pub fn pmvc_triangles_source() -> String {
    let source = PMVC_SOURCE.replace("#import pmvc_patches", "#import pmvc_no_patches");
    composed("bind_pmvc.wgsl", &source)
}

// These three are written into the WGSL by `shader_source` (import `bind_constants`).
/// Invocations per workgroup in both kernels.
pub(super) const WORKGROUP_SIZE: u32 = 64;
/// Texels of the PMVC kernel's shared depth buffer.
pub(super) const BAND_TEXELS: u32 = 1024;
/// Status bit the kernels set for rows the CPU must redo.
pub(super) const FALLBACK: u32 = 1;
/// Cage vertices whose sums fit the tile kernel's workgroup memory (8 KiB; with
/// its chunk of triangles it stays under the 16 KiB every device offers).
pub(super) const TILES_MAX_VERTICES: u32 = 2048;

/// Which PMVC kernel binds a cage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PmvcKernel {
    /// Tiles where the cage allows it (triangles only, at most 2,048 vertices),
    /// else bands.
    #[default]
    Auto,
    /// `shaders/bind_pmvc_tiles.wgsl`: invocations own texels.
    Tiles,
    /// `shaders/bind_pmvc.wgsl`: invocations own primitives, the face in bands.
    Bands,
}

impl PmvcKernel {
    /// Whether `work` binds with the tile kernel. `Auto` takes it for cages of
    /// triangles that fit it where the cost model predicts it faster
    /// ([`backend_choice::tiles_predicted_faster`]); `Tiles` on a cage it cannot
    /// take is refused.
    pub fn takes_tiles(self, work: &Work) -> Result<bool, String> {
        let patches = work.cage_quads > 0;
        let vertices = work.cage_vertices;
        let fits = !patches && vertices <= TILES_MAX_VERTICES as usize;
        match self {
            PmvcKernel::Auto => Ok(fits && backend_choice::tiles_predicted_faster(work)),
            PmvcKernel::Bands => Ok(false),
            PmvcKernel::Tiles if fits => Ok(true),
            PmvcKernel::Tiles if patches => Err(format!(
                "the tile kernel takes cages of triangles only; this one keeps {} quads \
                 as bilinear patches (bind it with the band kernel, or split its quads)",
                work.cage_quads
            )),
            PmvcKernel::Tiles => Err(format!(
                "the tile kernel takes cages of at most {TILES_MAX_VERTICES} vertices; \
                 this one has {vertices} (bind it with the band kernel)"
            )),
        }
    }

    const ALL: [PmvcKernel; 3] = [PmvcKernel::Auto, PmvcKernel::Tiles, PmvcKernel::Bands];

    /// The name `--pmvc-kernel` and Python's `pmvc_kernel=` take.
    pub fn name(self) -> &'static str {
        match self {
            PmvcKernel::Auto => "auto",
            PmvcKernel::Tiles => "tiles",
            PmvcKernel::Bands => "bands",
        }
    }

    /// The one check of a kernel's name, whatever its source.
    pub fn parse(text: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|kernel| kernel.name() == text)
            .ok_or_else(|| format!("unknown PMVC kernel '{text}' (expected auto, tiles or bands)"))
    }
}

/// Uniform block of both kernels: `Params` in `shaders/shared/bind_params.wgsl`
/// (layouts compared by `tests/gpu/shader_layouts.rs`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Params {
    pub point_count: u32,
    pub triangle_count: u32,
    pub vertex_count: u32,
    pub resolution: u32,
    pub band_rows: u32,
    pub max_missed: u32,
    pub incidence_offsets: u32,
    pub incidence_entries: u32,
}

pub(crate) struct Kernels {
    pub layout: wgpu::BindGroupLayout,
    /// PMVC for cages of triangles up to [`TILES_MAX_VERTICES`].
    pub pmvc_tiles: wgpu::ComputePipeline,
    pub mvc: wgpu::ComputePipeline,
    pub green: wgpu::ComputePipeline,
    /// PMVC's band kernel, for larger cages of triangles and for cages with
    /// quads (patches among the primitives), each compiled on the first bind
    /// that needs it: compiled with the others, the quad pipeline made every
    /// bind's start about 0.4 s longer on lavapipe.
    bands: BandPipelines,
}

/// What compiling the band pipelines later needs.
struct BandPipelines {
    device: wgpu::Device,
    layout: wgpu::PipelineLayout,
    cache: Option<wgpu::PipelineCache>,
    triangles: OnceLock<Result<wgpu::ComputePipeline, GpuError>>,
    quads: OnceLock<Result<wgpu::ComputePipeline, GpuError>>,
}

/// `module`'s entry point as a pipeline with `constants` for its overrides.
fn compute_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    label: &str,
    constants: &[(&str, f64)],
    cache: Option<&wgpu::PipelineCache>,
) -> wgpu::ComputePipeline {
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        module,
        entry_point: Some("main"),
        compilation_options: wgpu::PipelineCompilationOptions {
            constants,
            ..Default::default()
        },
        cache,
    })
}

/// Run `body` in validation and out-of-memory error scopes.
fn scoped<T>(device: &wgpu::Device, body: impl FnOnce() -> T) -> Result<T, GpuError> {
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let value = body();
    if let Some(error) = pollster::block_on(memory.pop()) {
        return Err(error.into());
    }
    if let Some(error) = pollster::block_on(validation.pop()) {
        return Err(error.into());
    }
    Ok(value)
}

fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl Kernels {
    /// Compile the kernels, through `cache` where the device keeps a pipeline cache.
    pub fn new(
        device: &wgpu::Device,
        cache: Option<&wgpu::PipelineCache>,
    ) -> Result<Self, GpuError> {
        scoped(device, || {
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("pmvc bind"),
                entries: &[
                    wgpu::BindGroupLayoutEntry {
                        binding: 0,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Uniform,
                            has_dynamic_offset: false,
                            min_binding_size: None,
                        },
                        count: None,
                    },
                    storage_entry(1, true),
                    storage_entry(2, true),
                    storage_entry(3, true),
                    storage_entry(4, true),
                    storage_entry(5, false),
                    storage_entry(6, false),
                    storage_entry(7, false),
                ],
            });
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("pmvc bind"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
            let [_, (_, tiles_source), (_, mvc_source), (_, green_source)] = kernel_sources();
            let module = |label: &str, source: String| {
                device.create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(label),
                    source: wgpu::ShaderSource::Wgsl(source.into()),
                })
            };
            let pipeline = |label: &str, module: &wgpu::ShaderModule| {
                compute_pipeline(device, &pipeline_layout, module, label, &[], cache)
            };
            Self {
                pmvc_tiles: pipeline("bind_pmvc_tiles", &module("bind_pmvc_tiles", tiles_source)),
                mvc: pipeline("bind_mvc", &module("bind_mvc", mvc_source)),
                green: pipeline("bind_green", &module("bind_green", green_source)),
                layout,
                bands: BandPipelines {
                    device: device.clone(),
                    layout: pipeline_layout,
                    cache: cache.cloned(),
                    triangles: OnceLock::new(),
                    quads: OnceLock::new(),
                },
            }
        })
    }

    /// PMVC's band pipeline for cages with quads (`CORNERS` = 4 in
    /// shaders/bind_pmvc.wgsl) or of triangles, compiled on first use; and
    /// whether this call compiled it (the pipeline cache then has more to keep).
    pub fn pmvc_bands(&self, patches: bool) -> (Result<&wgpu::ComputePipeline, GpuError>, bool) {
        let mut compiled = false;
        let bands = &self.bands;
        let slot = if patches {
            &bands.quads
        } else {
            &bands.triangles
        };
        let pipeline = slot.get_or_init(|| {
            compiled = true;
            scoped(&bands.device, || {
                let (source, constants, label) = if patches {
                    let source = composed("bind_pmvc.wgsl", PMVC_SOURCE);
                    (source, vec![("CORNERS", 4.0)], "bind_pmvc quads")
                } else {
                    (pmvc_triangles_source(), Vec::new(), "bind_pmvc")
                };
                let module = bands
                    .device
                    .create_shader_module(wgpu::ShaderModuleDescriptor {
                        label: Some(label),
                        source: wgpu::ShaderSource::Wgsl(source.into()),
                    });
                let cache = bands.cache.as_ref();
                compute_pipeline(
                    &bands.device,
                    &bands.layout,
                    &module,
                    label,
                    &constants,
                    cache,
                )
            })
        });
        (pipeline.as_ref().map_err(Clone::clone), compiled)
    }

    /// The pipeline cache the kernels compile through, if the device keeps one.
    pub fn pipeline_cache(&self) -> Option<&wgpu::PipelineCache> {
        self.bands.cache.as_ref()
    }
}

#[cfg(all(test, feature = "ui-tests"))]
mod tests {
    use super::*;

    #[test]
    fn pmvc_for_triangles_validates_without_the_patch_code() {
        let source = pmvc_triangles_source();
        assert!(!source.contains("fn patch_hit") && source.contains("fn is_patch"));
        let module = naga::front::wgsl::parse_str(&source).expect("parses");
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .expect("validates");
    }
}
