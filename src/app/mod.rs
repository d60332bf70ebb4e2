//! The desktop editor: an eframe/egui application that binds a mesh to a cage in
//! the background, deforms it on the GPU every frame, and edits the cage. Laid
//! out as egui's demo app is: one state struct, one file per panel. Files
//! depend downwards only: the editor on the panels, the panels on [`ctx`] and
//! the vocabulary, never the other way (no import circle between files).
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
//!   place after the panels each frame; [`commands`]: every change of the
//!   model. Actions and commands are the vocabulary the panels, the viewport,
//!   the model and the editor share, in leaf files that import none of them.
//! - `posing`: the posing tools applied to the document (the viewport's
//!   transforms and the Posing tools panel); `options`: how the editor starts.
//! - [`cage_generation`]: File > Generate cage…, a cage generated in the
//!   background and proposed over the mesh before it replaces the cage.
//! - [`compare`]: what the views compare and how the mesh is coloured.
//! - [`scenes`]: the bundled scenes; [`widgets`]: the colour bar and hover box.

pub mod actions;
pub mod bind_queue;
mod binding;
pub mod cage_generation;
pub mod commands;
pub mod compare;
pub mod ctx;
pub mod editor;
mod exports;
mod file_objects;
mod files;
mod focus;
pub mod model;
mod offscreen;
mod options;
pub mod pose_tools;
mod posing;
mod readouts;
pub mod recent;
pub mod recovery;
pub mod scenes;
mod screenshot;
mod scripted_drag;
pub mod session;
pub mod session_checks;
mod session_json;
mod session_paths;
pub mod shortcuts;
pub mod timeline;
pub mod ui;
mod viewport;
pub mod views;
pub mod widgets;

pub use actions::FileRole;
pub use editor::EditorApp;
pub use model::document;
pub use offscreen::run_offscreen;
use options::editor_device_descriptor;
pub use options::{BindOn, EditorError, EditorOptions, SCRIPTED_WINDOW_SIZE};
pub use viewport::{axes_rect, TransformKind};

use std::path::PathBuf;

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
