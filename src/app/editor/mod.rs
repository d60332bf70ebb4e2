//! The editor application: the shell that holds the model, the bind queue,
//! the views and the panels, and brings them together each frame. Its fields
//! are private to this module: panels see only a [`PanelContext`] and send
//! actions, which the one runner (`runner.rs`) carries out; the panes draw
//! through a [`ViewportContext`]. `frame.rs` is the frame loop, `gpu.rs` the GPU
//! copy (uploads driven by the model's changes, and what the GPU drew, read
//! back), and `api.rs` the thin wrappers that tests and scripts call.

mod api;
mod frame;
mod gpu;
mod runner;
mod unsaved;

use super::actions::Action;
use super::bind_queue::BindQueue;
use super::binding::{self, Binding};
use super::cage_generation::CageGeneration;
use super::commands::{Command, SessionView};
use super::compare::ViewSettings;
use super::document::Document;
use super::exports::ImageRequest;
use super::files::{Cameras, Replacement, SceneChange};
use super::focus::KeyboardFocus;
use super::model::{Model, Outcome, Swapped};
use super::options::{BindOn, EditorOptions};
use super::recent::RecentFiles;
use super::recovery::Recovery;
use super::scenes::{self, BundledScene};
use super::screenshot::ScreenshotState;
use super::ui::drop_dialog::DropDialog;
use super::ui::file_dialog::FileDialogs;
use super::ui::named_poses::PoseBlend;
use super::ui::notices::Notices;
use super::ui::pose_panel::PosePanel;
use super::ui::recovery_dialog::RecoveryDialog;
use super::ui::shortcuts_help::ShortcutsHelp;
use super::ui::statistics::StatisticsPanel;
use super::ui::timeline::TimelinePanel;
use super::ui::unsaved_dialog::UnsavedDialog;
use super::views::Views;
use crate::coords::{BindOptions, Method, Weights};
use crate::gpu::{Backend, BackendRequest, GpuContext};
use crate::render::viewport::MSAA_SAMPLES;
use crate::render::ViewportRenderer;
use eframe::egui_wgpu;
use glam::DVec3;
use std::path::PathBuf;
use std::sync::Arc;

// `editor::FileRole` stays a path to the type, which is vocabulary (`actions.rs`).
pub use super::actions::FileRole;

/// The wgpu handles the editor needs outside paint callbacks (uploads, readback).
pub(super) struct GpuHandles {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub renderer: Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>,
    /// A bind's weights and their copy already on this device, for the upload
    /// of those weights once the model has them.
    pub resident_weights: Option<(Arc<Weights>, wgpu::Buffer)>,
}

pub struct EditorApp {
    gpu: Option<GpuHandles>,
    /// The document, its undo log, the gesture under way and the save point.
    model: Model,
    /// The bind queue and the options the families are bound with.
    binding: Binding,
    /// What the viewport shows and keeps: view settings, cameras, read-outs.
    views: Views,
    panels: Panels,
    files: FileState,
    run: RunState,
    /// What the panels and shortcuts asked for, run by `runner.rs`.
    actions: Vec<Action>,
}

/// The panels, each owning its state.
#[derive(Default)]
struct Panels {
    notices: Notices,
    statistics: StatisticsPanel,
    /// The Poses section: names being typed, the blend slider.
    named_poses: PoseBlend,
    /// The Posing tools section: pivot, symmetry, soft selection, 3D cursor.
    pose_tools: PosePanel,
    /// The system's or the in-window file dialog.
    file_dialogs: FileDialogs,
    /// Quitting or opening another scene asks first when work is unsaved.
    unsaved: UnsavedDialog,
    /// A file dropped on the window, waiting for the user to say what it is.
    drop: DropDialog,
    /// File > Generate cage…: its window, job and proposal.
    cage_window: CageGeneration,
    /// The first run's line saying what to look at, until it is dismissed.
    first_run_hint: bool,
    /// Help > Shortcuts.
    shortcuts_help: ShortcutsHelp,
    /// Work an earlier editor autosaved and left behind, offered at start-up.
    recovery: RecoveryDialog,
    /// The Timeline section: playing and scrubbing the keys.
    timeline: TimelinePanel,
}

/// Where the scene's files are and go.
#[derive(Default)]
struct FileState {
    recent: RecentFiles,
    /// The session file last opened or saved: File > Save session writes there.
    session_path: Option<PathBuf>,
    /// File > Save image… waiting for the next frame.
    image_request: ImageRequest,
    /// What waits for the answer to "Save changes?".
    waiting: Option<Waiting>,
    /// Autosave of unsaved work, when the run has a recovery folder.
    recovery: Option<Recovery>,
}

/// What the unsaved-work question holds back until it is answered.
enum Waiting {
    Quit,
    /// Another scene, read and checked, to replace the document.
    Open(Box<SceneChange>),
}

/// How this run of the editor goes.
#[derive(Default)]
struct RunState {
    /// `--screenshot` (and `--drag`): a scripted run.
    screenshot: Option<ScreenshotState>,
    focus: KeyboardFocus,
    /// Show no timings, so frames are deterministic (snapshot tests).
    hide_timings: bool,
    /// egui's clock at the start of this frame (autosave times).
    clock: f64,
}

impl EditorApp {
    /// Create the app from eframe's creation context and start binding.
    pub fn new(cc: &eframe::CreationContext<'_>, options: EditorOptions) -> Self {
        // An adapter that cannot run the viewport's shaders draws nothing, and the
        // notice says why, rather than wgpu panicking on the first pipeline.
        let unsupported = cc
            .wgpu_render_state
            .as_ref()
            .and_then(|state| crate::render::check_adapter(&state.adapter, &state.device).err());
        let usable_state = cc
            .wgpu_render_state
            .as_ref()
            .filter(|_| unsupported.is_none());
        let gpu = usable_state.map(|state| {
            let software = state.adapter.get_info().device_type == wgpu::DeviceType::Cpu;
            // PMVC_EDITOR_MSAA=1 or 4 overrides the default (for screenshots).
            let samples = match std::env::var("PMVC_EDITOR_MSAA").as_deref() {
                Ok("1") => 1,
                Ok("4") => MSAA_SAMPLES,
                _ if software => 1,
                _ => MSAA_SAMPLES,
            };
            let renderer = ViewportRenderer::new(&state.device, state.target_format, samples);
            state.renderer.write().callback_resources.insert(renderer);
            GpuHandles {
                device: state.device.clone(),
                queue: state.queue.clone(),
                renderer: Arc::clone(&state.renderer),
                resident_weights: None,
            }
        });
        let request = match options.bind_on {
            BindOn::Auto => BackendRequest::Auto,
            BindOn::Cpu => BackendRequest::Cpu,
            BindOn::Gpu => BackendRequest::Gpu,
        };
        let backend = usable_state.map_or(Backend::Cpu, |state| bind_device(state, request));
        let wake_ctx = cc.egui_ctx.clone();
        // The comb is generated, so it cannot fail to load.
        let (mesh, cage) = (scenes::comb_mesh(), scenes::comb_cage());
        let bind_options = BindOptions::for_method(options.method.unwrap_or(Method::Pmvc));
        let queue = BindQueue::new(backend, request, move || wake_ctx.request_repaint());
        let mut binding = Binding::new(queue, bind_options);
        let refused_parameters = binding::with_asked_parameters(&mut binding, &options);
        let mut app = Self {
            gpu,
            model: Model::new(
                Document::new(BundledScene::Comb.title(), mesh, cage)
                    .bundled_as(BundledScene::Comb),
            ),
            binding,
            views: Views::new(options.view),
            panels: Panels {
                cage_window: CageGeneration::new(cc.egui_ctx.clone()),
                ..Panels::default()
            },
            files: FileState {
                recent: cc.storage.map(RecentFiles::load).unwrap_or_default(),
                recovery: (options.screenshot.is_none())
                    .then_some(options.recovery_dir.as_deref())
                    .flatten()
                    .map(Recovery::new),
                ..FileState::default()
            },
            run: RunState {
                screenshot: options
                    .screenshot
                    .clone()
                    .map(|path| ScreenshotState::new(path, options.drag_handle)),
                focus: KeyboardFocus::default(),
                hide_timings: options.hide_timings,
                clock: 0.0,
            },
            actions: Vec::new(),
        };
        for refused in refused_parameters {
            app.error(refused);
        }
        if let Some(error) = unsupported {
            app.error(error.to_string());
        } else if app.gpu.is_none() {
            app.error("no wgpu device: the viewport cannot draw (run with the wgpu renderer)");
        }
        let opened = app.open_what_was_asked(&options);
        if !opened {
            app.install_document(app.model.document().clone());
        }
        // Opening the files asked for is where editing starts, not an undo step.
        app.model.apply(Command::ForgetHistory);
        if options.demo_pose && !opened {
            let pose = scenes::comb_demo_pose(app.model.document().cage());
            app.model.apply(Command::edit_pose(pose));
            // Bundled, so there is nothing to lose on quitting.
            app.apply(Command::MarkSaved);
            app.panels.first_run_hint = true;
            app.frame_scene();
        }
        if let Some(pose) = &options.pose {
            app.load_pose(pose);
        }
        for &(parameter, value) in &options.deform {
            app.apply(Command::SetDeformParameter { parameter, value });
        }
        app.report_heatmap_out_of_range(&options.view);
        if let Some(note) = app.views.settings.fit_compared() {
            app.error(format!("--compare: {note}"));
        }
        if let Some(dir) = options
            .recovery_dir
            .as_deref()
            .filter(|_| app.files.recovery.is_some())
        {
            app.panels.recovery.offer(super::recovery::left_behind(dir));
        }
        // What was opened above has started its binds; starting again would
        // cancel them, and a cancel pauses binding until the user asks.
        if !opened {
            app.bind_wanted();
        }
        app
    }

    /// Open the session, pair or mesh `pmvc edit` was given; true when one opened.
    fn open_what_was_asked(&mut self, options: &EditorOptions) -> bool {
        match (&options.mesh, &options.cage, &options.session) {
            (_, _, Some(session)) => {
                let opened = self.open_session(session);
                if opened {
                    self.command_line_over_session(options);
                }
                opened
            }
            (Some(mesh), Some(cage), None) => {
                let objects = super::files::ObjectNames {
                    mesh: options.mesh_object.as_deref(),
                    cage: options.cage_object.as_deref(),
                };
                self.open_pair_now(mesh, cage, objects)
            }
            (Some(mesh), None, None) => {
                let change = super::files::open_mesh_alone(mesh, options.mesh_object.as_deref());
                self.change_scene(change)
            }
            (None, None, None) => false,
            _ => {
                self.error("give a mesh with the cage; showing the default scene");
                false
            }
        }
    }

    /// What `pmvc edit --session` was told beside the session wins over it.
    fn command_line_over_session(&mut self, options: &EditorOptions) {
        self.views.settings =
            super::session::view_with_overrides(self.views.settings, options.view);
        if let Some(method) = options.method {
            self.binding.set_active_method(method);
        }
        for refused in binding::with_asked_parameters(&mut self.binding, options) {
            self.error(refused);
        }
    }

    /// `--heatmap` or `--heatmap-triangle` beyond the cage is said, and the
    /// nearest one shown.
    fn report_heatmap_out_of_range(&mut self, asked: &ViewSettings) {
        let cage_vertices = self.model.document().pose().len();
        if asked.heat_vertex >= cage_vertices {
            self.error(format!(
                "--heatmap {}: the cage has {cage_vertices} vertices (0 to {}); showing vertex {}",
                asked.heat_vertex,
                cage_vertices.saturating_sub(1),
                self.views.settings.heat_vertex
            ));
        }
        let cage_triangles = self.model.document().cage().triangle_count();
        if let Some(shown) = asked.heat_triangle.filter(|&t| t >= cage_triangles) {
            self.error(format!(
                "--heatmap-triangle {shown}: the cage has {cage_triangles} triangles (0 to {}); showing triangle {}",
                cage_triangles.saturating_sub(1),
                self.views.settings.heat_triangle.unwrap_or(0)
            ));
        }
    }

    fn error(&mut self, text: impl Into<String>) {
        let text = text.into();
        log::warn!("{text}");
        if let Some(screenshot) = &self.run.screenshot {
            screenshot.record_failure(&text);
        }
        self.panels.notices.error(text);
    }

    fn info(&mut self, text: impl Into<String>) {
        self.panels.notices.info(text);
    }

    /// Report an outcome: the notice, or the error.
    fn report(&mut self, result: Result<String, String>) -> bool {
        match result {
            Ok(text) => {
                self.info(text);
                true
            }
            Err(text) => {
                self.error(text);
                false
            }
        }
    }

    fn with_renderer<R>(
        &self,
        f: impl FnOnce(&mut ViewportRenderer, &wgpu::Device, &wgpu::Queue) -> R,
    ) -> Option<R> {
        let gpu = self.gpu.as_ref()?;
        let mut renderer = gpu.renderer.write();
        let viewport = renderer.callback_resources.get_mut::<ViewportRenderer>()?;
        Some(f(viewport, &gpu.device, &gpu.queue))
    }

    /// The families the views need, the active one first.
    fn wanted_methods_now(&self) -> Vec<Method> {
        binding::wanted_methods(self.binding.active_method(), &self.views.settings)
    }

    // ---- the document and its GPU copy ----------------------------------------

    /// Make `document` current: the bind queue and the views start afresh on it,
    /// and the camera frames it. Not undoable: for the start-up scene.
    fn install_document(&mut self, document: Document) {
        self.model
            .apply(Command::InstallDocument(Box::new(document)));
        self.document_swapped(true);
    }

    /// Make a scene change read from files (or an error) current, with its
    /// notices; true when it was made.
    /// Replace the document by `change` and bind it.
    pub(super) fn apply_scene_change(&mut self, change: SceneChange) {
        for note in change.notes {
            self.info(note);
        }
        self.replace_document_then_bind(change.replacement);
        // Save session writes where this scene came from: a session file, or
        // for anything else opened, a name the user gives.
        match change.session {
            Some(path) => self.files.session_path = Some(path),
            None if !change.same_session => self.files.session_path = None,
            None => {}
        }
        if let Some(entry) = change.recent {
            self.files.recent.remember(entry);
        }
        if let Some(done) = change.done {
            self.info(done);
        }
        if change.offer_cage {
            let vertices = self.model.document().cage().vertex_count();
            self.panels.cage_window.open_window(vertices);
        }
        // Another scene's files are on disk: nothing of it is unsaved yet; and
        // the first run's line about the comb no longer describes it.
        if !change.same_session {
            self.apply(Command::MarkSessionSaved);
            self.panels.first_run_hint = false;
        }
    }

    /// Replace the whole document, as one undo step, and bind it: the one way
    /// opening files, sessions and scenes and editing the cage change it.
    fn replace_document_then_bind(&mut self, replacement: Replacement) {
        let Replacement {
            document,
            action,
            cameras,
            settings,
        } = replacement;
        let kept = self.views.viewport.cameras();
        // Undo brings back the view settings a session replaces, too.
        let view = settings.is_some().then(|| self.session_view());
        self.apply(Command::ReplaceDocument {
            document: Box::new(document),
            action,
            view,
        });
        self.document_swapped(true);
        match cameras {
            Cameras::Frame => {}
            Cameras::Keep => self.views.viewport.set_cameras(kept),
            // Relative to the origin the new document set.
            Cameras::Session(cameras) => self.views.viewport.set_first_cameras(&cameras),
        }
        if let Some((bind_options, view)) = settings {
            self.binding.replace_options(bind_options);
            self.views.settings = view;
            // A session's pose is on disk: quitting keeps it.
            self.apply(Command::MarkSessionSaved);
        }
        self.bind_wanted();
    }

    /// The view settings a session holds, as shown now.
    fn session_view(&self) -> SessionView {
        SessionView {
            bind_options: self.binding.options,
            view: self.views.settings,
            cameras: self.views.viewport.cameras(),
        }
    }

    /// Change the model; a pose refused (of another length) is reported.
    fn apply(&mut self, command: Command) -> super::model::Applied {
        let applied = self.model.apply(command);
        if let Outcome::Refused(why) = &applied.outcome {
            log::warn!("refused: {why}");
        }
        applied
    }

    /// After the document was swapped: the bind queue and the views start afresh
    /// on it, and the camera frames it if asked.
    fn document_swapped(&mut self, frame: bool) {
        let document = self.model.document();
        self.binding.queue.set_scene(
            document.mesh().positions.as_slice().into(),
            Arc::clone(document.cage()),
        );
        self.views.readouts.clear();
        // A drag or a transform under way belonged to the old document.
        self.views.viewport.reset_interaction();
        self.views.viewport.modal = None;
        let cage_vertices = document.pose().len();
        let settings = &mut self.views.settings;
        settings.heat_vertex = settings.heat_vertex.min(cage_vertices.saturating_sub(1));
        let cage_triangles = document.cage().triangle_count();
        settings.heat_triangle =
            (settings.heat_triangle).map(|triangle| triangle.min(cage_triangles.saturating_sub(1)));
        self.binding.paused = false;
        // Before framing: the cameras are relative to the new document's origin.
        self.views.viewport.set_origin(self.document_origin());
        if frame {
            self.frame_scene();
        }
        self.sync_gpu();
    }

    /// Show a document back from the undo log with the weights it had (uploaded
    /// by [`Self::sync_gpu`], as every change is), without binding again, and the
    /// view settings its step kept.
    fn reinstate_document(&mut self, swapped: &Swapped) {
        self.document_swapped(!swapped.same_mesh);
        if let Some(view) = swapped.view {
            self.binding.replace_options(view.bind_options);
            self.views.settings = view.view;
            self.views.viewport.set_cameras(view.cameras);
        }
        self.binding
            .sync_parameters_with_weights(self.model.document());
    }

    /// Bind the methods the views show, the active one first, replacing any
    /// running bind.
    fn bind_wanted(&mut self) {
        self.binding.start(&self.views.settings);
    }

    /// Undo the last step: a pose edit, or an action that replaced the document
    /// (opening a file or a session, switching scenes, subdividing, resting the cage).
    fn undo_step(&mut self) {
        let applied = self.apply(Command::Undo(self.session_view()));
        if let Some(swapped) = applied.swapped {
            self.reinstate_document(&swapped);
            self.info(format!("undid: {}", swapped.action));
        }
    }

    /// Redo what undo reversed last.
    fn redo_step(&mut self) {
        let applied = self.apply(Command::Redo(self.session_view()));
        if let Some(swapped) = applied.swapped {
            self.reinstate_document(&swapped);
            self.info(format!("redid: {}", swapped.action));
        }
    }

    fn frame_scene_now(&mut self) {
        let (centre, radius) = self.model.document().bounding_sphere();
        self.views.viewport.frame(centre, radius);
    }

    /// Frame the selected handles (F), or the whole scene when none is selected.
    /// A single handle is framed with room around it: a tenth of the cage.
    fn frame_selection_now(&mut self) {
        let document = self.model.document();
        let pose = document.pose();
        let selected: Vec<DVec3> = document.selection().iter().map(|&i| pose[i]).collect();
        if selected.is_empty() {
            self.frame_scene_now();
            return;
        }
        let (lo, hi) = crate::geometry::bounds_of(&selected);
        let radius = ((hi - lo).length() / 2.0).max(0.1 * document.cage().diagonal());
        self.views.viewport.frame((lo + hi) / 2.0, radius);
    }

    /// Lock all views to one camera (the first view's) or give each its own.
    fn lock_cameras(&mut self, locked: bool) {
        if locked != self.views.settings.cameras_locked {
            self.views.settings.cameras_locked = locked;
            self.views.viewport.unify_cameras();
        }
    }
}

/// The editor's own device, which binds without a start-up of its own, unless
/// the CPU is asked for; for `auto` the queue decides per job whether to use it
/// ([`crate::gpu::backend_choice`]).
fn bind_device(state: &egui_wgpu::RenderState, request: BackendRequest) -> Backend {
    if request == BackendRequest::Cpu {
        return Backend::Cpu;
    }
    Backend::Gpu(Arc::new(GpuContext::from_device(
        state.device.clone(),
        state.queue.clone(),
        state.adapter.get_info(),
    )))
}
