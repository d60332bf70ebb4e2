//! Compute pipelines for the binding kernels and the bind group layout they share.

use super::GpuError;

use super::shader_source::compose;
use crate::coords::Method;
use crate::geometry::Cage;

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
    /// `BindOptions::cage_to_bind`). MVC on a cage with quads is QMVC, which has
    /// none: those binds run on the CPU.
    pub fn for_cage(method: Method, cage: &Cage) -> Option<Kernel> {
        Self::of_work(method, cage.has_quads())
    }

    /// [`Kernel::for_cage`] from the method and whether the cage keeps patches.
    pub fn of_work(method: Method, patches: bool) -> Option<Kernel> {
        match Self::of(method) {
            Some(Kernel::Mvc) if patches => None,
            kernel => kernel,
        }
    }
}

const PMVC_SOURCE: &str = include_str!("../../shaders/bind_pmvc.wgsl");
const MVC_SOURCE: &str = include_str!("../../shaders/bind_mvc.wgsl");
const GREEN_SOURCE: &str = include_str!("../../shaders/bind_green.wgsl");

/// The binding kernels' WGSL with imports resolved, by file name.
pub fn kernel_sources() -> [(&'static str, String); 3] {
    // The shared files are compiled in, so only a broken build can fail here.
    let composed = |name, source| compose(name, source).unwrap_or_else(|error| panic!("{error}"));
    [
        ("bind_pmvc.wgsl", composed("bind_pmvc.wgsl", PMVC_SOURCE)),
        ("bind_mvc.wgsl", composed("bind_mvc.wgsl", MVC_SOURCE)),
        ("bind_green.wgsl", composed("bind_green.wgsl", GREEN_SOURCE)),
    ]
}

// These three are written into the WGSL by `shader_source` (import `bind_constants`).
/// Invocations per workgroup in both kernels.
pub(super) const WORKGROUP_SIZE: u32 = 64;
/// Texels of the PMVC kernel's shared depth buffer.
pub(super) const BAND_TEXELS: u32 = 1024;
/// Status bit the kernels set for rows the CPU must redo.
pub(super) const FALLBACK: u32 = 1;

/// Uniform block of both kernels: `Params` in `shaders/shared/bind_params.wgsl`
/// (layouts compared by `tests/shader_layouts.rs`).
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
    pub pmvc: wgpu::ComputePipeline,
    /// PMVC on a cage with quads: primitives of four corner slots, patches among them.
    pub pmvc_quads: wgpu::ComputePipeline,
    pub mvc: wgpu::ComputePipeline,
    pub green: wgpu::ComputePipeline,
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
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
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
        let [(_, pmvc_source), (_, mvc_source), (_, green_source)] = kernel_sources();
        let module = |label: &str, source: String| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            })
        };
        // `constants`: the pipeline's override values (bind_pmvc's CORNERS).
        let pipeline = |label: &str, module: &wgpu::ShaderModule, constants: &[(&str, f64)]| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: Some(&pipeline_layout),
                module,
                entry_point: Some("main"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants,
                    ..Default::default()
                },
                cache,
            })
        };
        let pmvc_module = module("bind_pmvc", pmvc_source);
        let pmvc = pipeline("bind_pmvc", &pmvc_module, &[]);
        let pmvc_quads = pipeline("bind_pmvc quads", &pmvc_module, &[("CORNERS", 4.0)]);
        let mvc = pipeline("bind_mvc", &module("bind_mvc", mvc_source), &[]);
        let green = pipeline("bind_green", &module("bind_green", green_source), &[]);
        if let Some(error) = pollster::block_on(memory.pop()) {
            return Err(error.into());
        }
        if let Some(error) = pollster::block_on(validation.pop()) {
            return Err(error.into());
        }
        Ok(Self {
            layout,
            pmvc,
            pmvc_quads,
            mvc,
            green,
        })
    }
}
