//! Viewport drawing for the editor through egui_wgpu paint callbacks. Each
//! renderer is paired with its WGSL file in `shaders/render_*.wgsl`:
//! - [`mesh`]: the deformed mesh (deformation in the vertex shader) and readback;
//! - [`cage`]: the cage's edges and handles;
//! - [`viewport`]: buffers, the offscreen target and compositing into egui;
//! - [`camera`]: the orbit camera and screen projection (no GPU);
//! - [`colormap`]: the heatmaps' colour maps, CPU twins of the shader's (no GPU).

pub mod cage;
pub mod camera;
pub mod colormap;
pub mod mesh;
pub mod viewport;

pub use camera::{OrbitCamera, ScreenProjection};
pub use viewport::{
    check_adapter, Colouring, FrameParams, ReadBack, RenderError, SceneUpload, Shading,
    ViewportCallback, ViewportRenderer, MAX_VIEWS,
};
