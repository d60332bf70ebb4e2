//! The desktop editor: an eframe/egui application that binds a mesh to a cage in
//! the background, deforms it on the GPU every frame, and edits the cage. Laid
//! out as egui's demo app is: one state struct, one file per panel.
//!
//! - [`model`]: everything undoable (the [`document`], the one undo log, the
//!   gesture under way, the save point), changed only through `Model::apply`.
//! - [`bind_queue`]: binding in the background, one job at a time.
//! - [`editor`]: the [`EditorApp`] shell that holds the parts and runs the
//!   frame: its action runner, its GPU copy and the tests' thin wrappers.
//! - `binding`: the bind options and which families to bind; `files`: what
//!   opening and saving read and write, as values.
//! - `views` and `viewport`: the panes' state, input, picking and drawing,
//!   `readouts` the CPU values behind them; `ui`: menu, toolbar, side panel,
//!   quality table, dialogs, notices and statistics, each a panel.
//! - [`ctx`]: what a panel sees; [`actions`]: what it asks for, run in one
//!   place after the panels each frame.
//! - [`cage_generation`]: File > Generate cage…, a cage generated in the
//!   background and proposed over the mesh before it replaces the cage.
//! - [`compare`]: what the views compare and how the mesh is coloured.
//! - [`scenes`]: the bundled scenes; [`widgets`]: the colour bar and hover box.

pub mod actions;
pub mod bind_queue;
mod binding;
pub mod cage_generation;
pub mod compare;
pub mod ctx;
pub mod editor;
mod exports;
mod files;
mod focus;
pub mod model;
mod offscreen;
pub mod pose_tools;
mod readouts;
pub mod recent;
pub mod recovery;
pub mod scenes;
mod screenshot;
mod scripted_drag;
pub mod session;
pub mod session_checks;
pub mod shortcuts;
pub mod timeline;
pub mod ui;
mod viewport;
pub mod views;
pub mod widgets;

pub use editor::{EditorApp, FileRole};
pub use model::document;
pub use offscreen::run_offscreen;
pub use viewport::{axes_rect, TransformKind};

use std::path::PathBuf;

/// How the editor starts (the `pmvc edit` arguments).
#[derive(Clone, Debug, Default)]
pub struct EditorOptions {
    /// Mesh to open instead of the default scene; without `cage` it opens in a
    /// loose box and the Generate cage window offers a cage.
    pub mesh: Option<PathBuf>,
    pub cage: Option<PathBuf>,
    /// A session to open (instead of `mesh` and `cage`).
    pub session: Option<PathBuf>,
    /// A pose (cage OBJ with the same vertex count) applied once loaded.
    pub pose: Option<PathBuf>,
    /// PMVC cube-map resolution; `None` for the default.
    pub resolution: Option<u32>,
    /// Harmonic grid (cells along the cage's longest side); `None` for the default.
    pub grid: Option<u32>,
    /// Split the cage's quads along a diagonal (`--triangulate`); `None` keeps
    /// the session's setting, or bilinear patches.
    pub triangulate: Option<crate::coords::QuadSplit>,
    /// Coordinates to bind with; `None` for PMVC.
    pub method: Option<crate::coords::Method>,
    /// Save a PNG of the window once the first bind finishes, then quit.
    pub screenshot: Option<PathBuf>,
    /// In that scripted run, first drag the handle of this cage vertex (0-based)
    /// with the pointer and report the frame time while dragging (`--drag`).
    pub drag_handle: Option<usize>,
    /// Where binding runs.
    pub bind_on: BindOn,
    /// The views and colouring to start with (`--view`, `--heatmap`, `--negativity`).
    pub view: compare::ViewSettings,
    /// Show no timings (bind and elapsed times), so that frames are deterministic
    /// (snapshot tests).
    pub hide_timings: bool,
    /// Autosave unsaved work here, and offer what an editor left here at start-up
    /// (`None`: no autosave, as in tests and scripted runs).
    pub recovery_dir: Option<PathBuf>,
    /// Start the bundled comb in its demonstration pose (`scenes::comb_demo_pose`),
    /// with a line saying what to look at: what `pmvc` with no arguments opens.
    pub demo_pose: bool,
}

impl EditorOptions {
    /// The first run (`pmvc`, `cargo run --release`): the comb with its middle
    /// finger pulled up, MVC and PMVC side by side with the distance between them,
    /// so that MVC's pull on the neighbouring fingers shows at once.
    pub fn first_run() -> Self {
        let mut options = Self {
            demo_pose: true,
            ..Self::default()
        };
        options.view.layout = compare::Layout::SideBySide;
        options.view.difference_pane = true;
        options
    }
}

/// Where the editor binds. On a GPU it binds on the editor's own device, and the
/// vertex shader reads the weights where the bind left them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BindOn {
    /// Each bind on the editor's GPU or the CPU, whichever is predicted faster
    /// for it (`gpu::backend_choice`).
    #[default]
    Auto,
    Cpu,
    Gpu,
}

/// The editor could not run, or a scripted run (`--screenshot`) reported errors.
#[derive(Debug, thiserror::Error)]
pub enum EditorError {
    #[error("the editor window failed: {0}")]
    Window(String),
    #[error("--offscreen: {0}")]
    Offscreen(String),
    #[error("--screenshot: {} error(s) in the run: {}", .0.len(), .0.join("; "))]
    ScriptedRun(Vec<String>),
}

/// The window of a scripted run and of a first start, in points.
pub const SCRIPTED_WINDOW_SIZE: [f32; 2] = [1280.0, 800.0];

/// The device the editor asks for: the adapter's own limits, not wgpu's portable
/// defaults (weight matrices beyond 128 MiB on GPUs that allow them, and storage
/// buffers in the vertex stage on GL drivers that have them).
fn editor_device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    wgpu::DeviceDescriptor {
        label: Some("pmvc editor"),
        required_limits: adapter.limits(),
        ..Default::default()
    }
}

/// Open the editor window and run until it is closed.
pub fn run_editor(options: EditorOptions) -> Result<(), EditorError> {
    let mut native_options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("pmvc editor")
            .with_inner_size(SCRIPTED_WINDOW_SIZE)
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        // A scripted run's window is always the size asked for, whatever size
        // the last session's window had.
        persist_window: options.screenshot.is_none(),
        ..Default::default()
    };
    if let eframe::egui_wgpu::WgpuSetup::CreateNew(setup) =
        &mut native_options.wgpu_options.wgpu_setup
    {
        setup.device_descriptor = std::sync::Arc::new(editor_device_descriptor);
    }
    let mut options = options;
    if options.screenshot.is_none() && options.recovery_dir.is_none() {
        options.recovery_dir = std::env::var_os("PMVC_RECOVERY_DIR")
            .map(PathBuf::from)
            .or_else(|| eframe::storage_dir("pmvc editor").map(|dir| dir.join("recovery")));
    }
    let failures: std::sync::Arc<std::sync::Mutex<Vec<String>>> = Default::default();
    let failures_of_run = std::sync::Arc::clone(&failures);
    eframe::run_native(
        "pmvc editor",
        native_options,
        Box::new(move |cc| {
            let mut app = EditorApp::new(cc, options);
            app.share_scripted_failures(failures_of_run);
            Ok(Box::new(app))
        }),
    )
    .map_err(|error| EditorError::Window(error.to_string()))?;
    let failures = failures.lock().map(|list| list.clone()).unwrap_or_default();
    if failures.is_empty() {
        Ok(())
    } else {
        Err(EditorError::ScriptedRun(failures))
    }
}
