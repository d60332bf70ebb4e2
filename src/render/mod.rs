//! Viewport drawing for the editor through egui_wgpu paint callbacks. Imports
//! run one way: the renderers depend on the leaf [`scene_gpu`], and only the
//! orchestrator [`viewport`] depends on the renderers.
//! - [`scene_gpu`]: formats, the frame uniform, the scene's buffers and layout;
//! - [`draw_order`]: the mesh's triangle and edge indices as drawn (no GPU);
//! - [`weight_chunks`]: weights split by rows over several buffers (a leaf that
//!   [`scene_gpu`] uses);
//! - [`mesh`]: the deformed mesh (deformation in the vertex shader);
//! - [`cage`]: the cage's edges and handles;
//! - [`weight_attributes`]: the first weights columns read as vertex attributes
//!   where the device allows (a leaf that [`scene_gpu`] uses);
//! - [`readback`]: the mesh shader's results read back, for tests and checks;
//! - [`drawn`]: the positions the vertex shader draws, read back;
//! - [`composite`]: offscreen targets and compositing into egui's pass;
//! - [`viewport`]: the orchestrator and the paint callback;
//! - [`shading`]: what a view shows, as plain values (no GPU);
//! - [`camera`]: the orbit camera and screen projection (no GPU);
//! - [`scene_origin`]: the point the f32 scene coordinates are measured from
//!   (no GPU);
//! - [`colormap`]: the heatmaps' colour maps, CPU twins of the shader's (no GPU).
//!
//! Each renderer is paired with its WGSL file in `shaders/render_*.wgsl`.

pub mod cage;
pub mod callback;
pub mod camera;
pub mod colormap;
pub mod composite;
pub mod draw_order;
pub mod drawn;
pub mod mesh;
pub mod normals;
pub mod readback;
pub mod scene_gpu;
pub mod scene_origin;
pub mod shading;
pub mod viewport;
pub mod weight_attributes;
pub mod weight_chunks;

pub use callback::ViewportCallback;
pub use camera::{OrbitCamera, ScreenProjection};
pub use scene_gpu::{FrameUniform, ReadBack};
pub use scene_origin::SceneOrigin;
pub use viewport::{
    check_adapter, Colouring, FrameParams, RenderError, SceneUpload, Shading, ViewportRenderer,
    MAX_VIEWS,
};
