//! How the editor starts and how a run fails: the `pmvc edit` options, where
//! binding runs, and the device the editor asks for. A leaf below the editor,
//! which reads these, and `mod.rs`, which starts it.

use super::compare;
use std::path::PathBuf;

/// How the editor starts (the `pmvc edit` arguments).
#[derive(Clone, Debug, Default)]
pub struct EditorOptions {
    /// Mesh to open instead of the default scene; without `cage` it opens in a
    /// loose box and the Generate cage window offers a cage.
    pub mesh: Option<PathBuf>,
    pub cage: Option<PathBuf>,
    /// The objects of those files to read (`--mesh-object`, `--cage-object`);
    /// `None`: each file's default.
    pub mesh_object: Option<String>,
    pub cage_object: Option<String>,
    /// A session to open (instead of `mesh` and `cage`).
    pub session: Option<PathBuf>,
    /// A pose (cage OBJ with the same vertex count) applied once loaded.
    pub pose: Option<PathBuf>,
    /// PMVC cube-map resolution; `None` for the default.
    pub resolution: Option<u32>,
    /// Harmonic grid (cells along the cage's longest side); `None` for the default.
    pub grid: Option<u32>,
    /// Deformation settings (Somigliana's bulging γ and local blend, as their
    /// specs hold them) applied once loaded, each an undo step like `pose`;
    /// those not listed keep their values.
    pub deform: Vec<(crate::coords::Parameter, u32)>,
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
pub(super) fn editor_device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    wgpu::DeviceDescriptor {
        label: Some("pmvc editor"),
        required_limits: adapter.limits(),
        ..Default::default()
    }
}
