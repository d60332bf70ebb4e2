//! The wgpu device and the binding kernels. Never imports egui: the editor hands in
//! its own device, and the command line makes one.
//!
//! - [`GpuContext`]: device, queue and adapter facts, made here ([`GpuContext::new`],
//!   adapter policy in its doc) or handed in ([`GpuContext::from_device`]).
//! - [`Binder`]: a bind on a background thread, CPU or GPU, with progress and cancel;
//!   [`Binder::bind_blocking`] for synchronous callers and benchmarks.
//! - [`backend_choice`]: where a bind runs (`auto`, `cpu`, `gpu`), one rule for the
//!   command line, Python and the editor, with `auto`'s cost model.
//! - [`pipeline_cache`]: the compiled kernels kept on disk between runs.
//! - Kernels in `shaders/bind_pmvc.wgsl` (quads as bilinear patches through
//!   `shaders/shared/pmvc_patches.wgsl`), `shaders/bind_mvc.wgsl` (triangles
//!   only: MVC on quads is QMVC, bound on the CPU) and `shaders/bind_green.wgsl`.

pub mod backend_choice;
mod binder;
mod context;
pub mod kernels;
pub mod pipeline_cache;
pub mod shader_source;

pub use backend_choice::{BackendRequest, Decision};
pub use binder::{
    Backend, BatchSize, BindConfig, BindError, BindHandle, BindInput, BindOutput, BindStats,
    Binder, GpuWeights,
};
pub use context::{adapters_report, GpuContext, DEFAULT_BACKENDS};
pub use kernels::PmvcKernel;

/// Why a GPU operation failed. Device loss and out-of-memory end up here, never in a panic.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum GpuError {
    #[error("no GPU adapter available: {0}")]
    NoAdapter(String),
    #[error("could not open the GPU device: {0}")]
    RequestDevice(String),
    #[error("the GPU device was lost: {0}")]
    DeviceLost(String),
    #[error("the GPU ran out of memory: {0}")]
    OutOfMemory(String),
    #[error("GPU validation error: {0}")]
    Validation(String),
    #[error("internal GPU error: {0}")]
    Internal(String),
    #[error("{what} needs {needed} bytes, more than the adapter's limit of {limit} bytes")]
    TooLarge {
        what: &'static str,
        needed: u64,
        limit: u64,
    },
    #[error("reading results back from the GPU failed: {0}")]
    Readback(String),
}

impl From<wgpu::Error> for GpuError {
    fn from(error: wgpu::Error) -> Self {
        match error {
            wgpu::Error::OutOfMemory { source } => GpuError::OutOfMemory(source.to_string()),
            wgpu::Error::Validation { description, .. } => GpuError::Validation(description),
            wgpu::Error::Internal { description, .. } => GpuError::Internal(description),
        }
    }
}
