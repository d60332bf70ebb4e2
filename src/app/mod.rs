//! The desktop editor: an eframe/egui application that binds a mesh to a cage in
//! the background, deforms it on the GPU every frame, and edits the cage.
//!
//! - [`editor`]: the application state and its UI; talks only to [`jobs`] and
//!   [`crate::render`].
//! - [`compare`]: what the views compare (MVC, PMVC, their difference) and how the
//!   mesh is coloured; the read-outs behind colour bars and the hover box.
//! - [`scene`]: the loaded mesh, cage, pose and weights, and the pose history.
//! - [`jobs`]: binding on a background thread with progress and cancel.
//! - [`scenes`]: the bundled scenes and their generators.
//! - [`widgets`]: the colour bar and the hover box drawn over the views.

pub mod compare;
pub mod editor;
pub mod jobs;
pub mod scene;
pub mod scenes;
pub mod widgets;

pub use editor::EditorApp;

use std::path::PathBuf;

/// How the editor starts (the `pmvc edit` arguments).
#[derive(Clone, Debug, Default)]
pub struct EditorOptions {
    /// Mesh to open instead of the default scene (needs `cage` too).
    pub mesh: Option<PathBuf>,
    pub cage: Option<PathBuf>,
    /// A pose (cage OBJ with the same vertex count) applied once loaded.
    pub pose: Option<PathBuf>,
    /// PMVC cube-map resolution; `None` for the default.
    pub resolution: Option<u32>,
    /// Coordinates to bind with; `None` for PMVC.
    pub method: Option<crate::coords::Method>,
    /// Save a PNG of the window once the first bind finishes, then quit.
    pub screenshot: Option<PathBuf>,
    /// Where binding runs.
    pub bind_on: BindOn,
    /// The views and colouring to start with (`--view`, `--heatmap`, `--negativity`).
    pub view: compare::ViewSettings,
}

/// Where the editor binds. On a GPU it binds on the editor's own device, and the
/// vertex shader reads the weights where the bind left them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BindOn {
    /// A hardware GPU if the editor runs on one, else the CPU.
    #[default]
    Auto,
    Cpu,
    Gpu,
}

/// Open the editor window and run until it is closed.
/// The editor window could not run.
#[derive(Debug, thiserror::Error)]
#[error("the editor window failed: {0}")]
pub struct EditorError(String);

pub fn run_editor(options: EditorOptions) -> Result<(), EditorError> {
    let mut native_options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("pmvc editor")
            .with_inner_size([1280.0, 800.0])
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    if let eframe::egui_wgpu::WgpuSetup::CreateNew(setup) =
        &mut native_options.wgpu_options.wgpu_setup
    {
        // The adapter's own limits, not wgpu's portable defaults: weight matrices
        // beyond 128 MiB on GPUs that allow them, and storage buffers in the vertex
        // stage on GL drivers that have them (the viewport needs both kinds).
        setup.device_descriptor = std::sync::Arc::new(|adapter| wgpu::DeviceDescriptor {
            label: Some("pmvc editor"),
            required_limits: adapter.limits(),
            ..Default::default()
        });
    }
    eframe::run_native(
        "pmvc editor",
        native_options,
        Box::new(move |cc| Ok(Box::new(EditorApp::new(cc, options)))),
    )
    .map_err(|error| EditorError(error.to_string()))
}
