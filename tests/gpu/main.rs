//! The GPU binding kernels against the CPU bind, on the test device (lavapipe on
//! CI), and the WGSL shaders validated and their bind group layouts checked with
//! naga (`ui-tests`). Without an adapter the GPU tests print "not run", unless
//! `PMVC_REQUIRE_GPU=1`.

#[path = "../gpu_support/mod.rs"]
mod gpu_support;

mod gpu_binding;
mod gpu_cage_shapes;
mod gpu_pmvc_kernels;
mod gpu_quads;
#[cfg(feature = "ui-tests")]
mod shader_layouts;
#[cfg(feature = "ui-tests")]
mod shaders_validate;
