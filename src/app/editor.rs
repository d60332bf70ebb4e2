//! The editor application: the state that ties the [`Document`], the
//! [`BindQueue`] and the viewport together, and the frame loop. What happens in
//! each part of the window lives beside it: binding control in `binding.rs`, file
//! actions in `files.rs`, the CPU read-outs behind the views in `readouts.rs`, the
//! viewport in `viewport/`, and one file per panel in `ui/`.

use super::actions::Action;
use super::bind_queue::BindQueue;
use super::cage_generation::CageGeneration;
use super::compare::{HoverReadout, Pane, ViewSettings};
use super::document::Document;
use super::exports::ImageRequest;
use super::model::{Applied, Command, Model, Outcome, Selection, SessionView, Swapped};
use super::pose_tools::PoseToolSettings;
use super::readouts::ReadoutCache;
use super::recent::RecentFiles;
use super::scenes::{self, BundledScene};
use super::screenshot::ScreenshotState;
use super::ui::drop_dialog::DropDialog;
use super::ui::file_dialog::FileDialogs;
use super::ui::named_poses::PoseBlend;
use super::ui::notices::Notices;
use super::ui::quit_dialog::QuitDialog;
use super::ui::statistics::StatisticsPanel;
use super::viewport::ViewportState;
use super::{BindOn, EditorOptions};
use crate::coords::{BindOptions, Method, Weights};
use crate::gpu::{Backend, BackendRequest, GpuContext};
use crate::render::viewport::MSAA_SAMPLES;
use crate::render::{OrbitCamera, ViewportRenderer};
use eframe::egui_wgpu;
use glam::DVec3;
use std::path::PathBuf;
use std::sync::Arc;

/// The wgpu handles the editor needs outside paint callbacks (uploads, readback).
pub(super) struct GpuHandles {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub renderer: Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>,
    /// A bind's weights and their copy already on this device, for the upload
    /// of those weights once the model has them.
    pub resident_weights: Option<(Arc<Weights>, wgpu::Buffer)>,
}

/// Where the cameras go when the document is replaced.
pub(super) enum Cameras {
    /// Frame the new document.
    Frame,
    /// Stay where they are (a cage edit on the same mesh).
    Keep,
    /// A session's cameras.
    Session(Vec<OrbitCamera>),
}

/// A whole-document replacement and what comes with it.
pub(super) struct Replacement {
    pub document: Document,
    /// What undo calls it ("open cage.obj").
    pub action: String,
    pub cameras: Cameras,
    /// A session's bind options and view settings.
    pub settings: Option<(BindOptions, ViewSettings)>,
}

impl Replacement {
    /// `document` replacing the current one by `action`, framed.
    pub(super) fn framed(document: Document, action: impl Into<String>) -> Self {
        Self {
            document,
            action: action.into(),
            cameras: Cameras::Frame,
            settings: None,
        }
    }

    /// `document` replacing the current one by `action`, the cameras kept.
    pub(super) fn in_place(document: Document, action: impl Into<String>) -> Self {
        Self {
            cameras: Cameras::Keep,
            ..Self::framed(document, action)
        }
    }
}

/// Which kind of file is being opened.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileRole {
    Mesh,
    Cage,
}

pub struct EditorApp {
    pub(super) gpu: Option<GpuHandles>,
    /// The document, its undo log, the gesture under way and the save point.
    pub(super) model: Model,
    pub(super) queue: BindQueue,
    /// The method a single view shows (`method`) and every family's parameters.
    pub(super) bind_options: BindOptions,
    /// What the viewport compares and how the mesh is coloured.
    pub(super) view: ViewSettings,
    pub(super) viewport: ViewportState,
    pub(super) readouts: ReadoutCache,
    pub(super) notices: Notices,
    pub(super) statistics: StatisticsPanel,
    pub(super) highlight_outside: bool,
    pub(super) recent: RecentFiles,
    /// The session file last opened or saved: File > Save session writes there.
    pub(super) session_path: Option<PathBuf>,
    /// The rest-to-pose blend slider's state.
    pub(super) pose_blend: PoseBlend,
    /// Pivot, symmetry and soft selection of pose edits.
    pub(super) pose_tools: PoseToolSettings,
    /// File > Save image… waiting for the next frame.
    pub(super) image_request: ImageRequest,
    /// The system's or the in-window file dialog.
    pub(super) file_dialogs: FileDialogs,
    /// Quitting asks first when the pose is unsaved.
    pub(super) quit: QuitDialog,
    pub(super) screenshot: Option<ScreenshotState>,
    /// Frames drawn, up to a limit, for asking for keyboard focus at start.
    pub(super) focus_frames: u32,
    /// After a cancel, views stop asking for binds until the user binds again.
    pub(super) binding_paused: bool,
    /// Show no timings, so frames are deterministic (snapshot tests).
    pub(super) hide_timings: bool,
    /// The first run's line saying what to look at, until it is dismissed.
    pub(super) first_run_hint: bool,
    /// A file dropped on the window, waiting for the user to say what it is.
    pub(super) drop_dialog: DropDialog,
    /// What the panels asked for this frame, run after them (`actions.rs`).
    pub(super) actions: Vec<Action>,
    /// File > Generate cage…: its window, job and proposal.
    pub(super) cage_generation: CageGeneration,
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
        let mut bind_options = BindOptions::for_method(options.method.unwrap_or(Method::Pmvc));
        let refused_parameters = super::binding::with_asked_parameters(&mut bind_options, &options);
        let mut app = Self {
            gpu,
            model: Model::new(
                Document::new(BundledScene::Comb.title(), mesh, cage)
                    .bundled_as(BundledScene::Comb),
            ),
            queue: BindQueue::new(backend, request, move || wake_ctx.request_repaint()),
            bind_options,
            view: options.view,
            viewport: ViewportState::default(),
            readouts: ReadoutCache::default(),
            notices: Notices::default(),
            statistics: StatisticsPanel::default(),
            highlight_outside: false,
            recent: cc.storage.map(RecentFiles::load).unwrap_or_default(),
            session_path: None,
            pose_blend: PoseBlend::default(),
            image_request: ImageRequest::default(),
            pose_tools: PoseToolSettings::default(),
            file_dialogs: FileDialogs::default(),
            quit: QuitDialog::default(),
            screenshot: options
                .screenshot
                .clone()
                .map(|path| ScreenshotState::new(path, options.drag_handle)),
            focus_frames: 0,
            binding_paused: false,
            hide_timings: options.hide_timings,
            first_run_hint: false,
            drop_dialog: DropDialog::default(),
            actions: Vec::new(),
            cage_generation: CageGeneration::new(cc.egui_ctx.clone()),
        };
        for refused in refused_parameters {
            app.error(refused);
        }
        if let Some(error) = unsupported {
            app.error(error.to_string());
        } else if app.gpu.is_none() {
            app.error("no wgpu device: the viewport cannot draw (run with the wgpu renderer)");
        }
        let mut opened = false;
        match (&options.mesh, &options.cage, &options.session) {
            (_, _, Some(session)) => {
                opened = app.open_session(session);
                if opened {
                    app.command_line_over_session(&options);
                }
            }
            (Some(mesh), Some(cage), None) => opened = app.open_pair(mesh, cage),
            (Some(mesh), None, None) => opened = app.open_mesh_alone(mesh),
            (None, None, None) => {}
            _ => app.error("give a mesh with the cage; showing the default scene"),
        }
        if !opened {
            app.install_document(app.model.document().clone());
        }
        // Opening the files asked for is where editing starts, not an undo step.
        app.model.apply(Command::ForgetHistory);
        if options.demo_pose && !opened {
            let pose = scenes::comb_demo_pose(app.model.document().cage());
            app.model.apply(Command::edit_pose(pose));
            // Bundled, so there is nothing to lose on quitting.
            app.mark_pose_saved();
            app.first_run_hint = true;
            app.frame_scene();
        }
        if let Some(pose) = &options.pose {
            app.load_pose(pose);
        }
        let cage_vertices = app.model.document().pose().len();
        if options.view.heat_vertex >= cage_vertices {
            app.error(format!(
                "--heatmap {}: the cage has {cage_vertices} vertices (0 to {}); showing vertex {}",
                options.view.heat_vertex,
                cage_vertices.saturating_sub(1),
                app.view.heat_vertex
            ));
        }
        let cage_triangles = app.model.document().cage().triangle_count();
        if let Some(asked) = options.view.heat_triangle.filter(|&t| t >= cage_triangles) {
            app.error(format!(
                "--heatmap-triangle {asked}: the cage has {cage_triangles} triangles (0 to {}); showing triangle {}",
                cage_triangles.saturating_sub(1),
                app.view.heat_triangle.unwrap_or(0)
            ));
        }
        // What was opened above has started its binds; starting again would
        // cancel them, and a cancel pauses binding until the user asks.
        if !opened {
            app.start_bind();
        }
        app
    }

    // ---- read access, for the panels and for tests ------------------------------

    pub fn document(&self) -> &Document {
        self.model.document()
    }

    pub fn view(&self) -> &ViewSettings {
        &self.view
    }

    pub fn view_mut(&mut self) -> &mut ViewSettings {
        &mut self.view
    }

    /// The camera of the first view, and of every view while they are locked;
    /// its target is in scene coordinates ([`Self::scene_origin`]).
    pub fn camera(&self) -> OrbitCamera {
        self.viewport.camera_of(0, self.view.cameras_locked)
    }

    /// The camera view `pane` is drawn with (in scene coordinates).
    pub fn camera_of(&self, pane: usize) -> OrbitCamera {
        self.viewport.camera_of(pane, self.view.cameras_locked)
    }

    /// The bind options of the method a single view shows.
    pub fn bind_options(&self) -> BindOptions {
        self.bind_options
    }

    /// The options `method` is bound with: its family's current parameters.
    pub fn options_for(&self, method: Method) -> BindOptions {
        BindOptions {
            method,
            ..self.bind_options
        }
    }

    /// Binds started so far (a method switch to bound weights must not add one).
    pub fn bind_count(&self) -> usize {
        self.queue.jobs_started()
    }

    /// (done, total) vertices of the last bind when it ended.
    pub fn last_bind_progress(&self) -> Option<(usize, usize)> {
        self.queue.last_progress()
    }

    /// The weights under the cursor, and the view they were read in.
    pub fn hover_readout(&self) -> Option<&(usize, HoverReadout)> {
        self.viewport.hover_readout.as_ref()
    }

    /// A dialog (file, quit or dropped file) waits for the user.
    pub fn modal_dialog_open(&self) -> bool {
        self.file_dialogs.is_open() || self.quit.is_asking() || self.drop_dialog.is_open()
    }

    /// Use the in-window file dialog (true) or the system's (false).
    pub fn set_in_window_file_dialog(&mut self, in_window: bool) {
        self.file_dialogs.in_window = in_window;
    }

    pub(super) fn error(&mut self, text: impl Into<String>) {
        let text = text.into();
        log::warn!("{text}");
        if let Some(screenshot) = &self.screenshot {
            screenshot.record_failure(&text);
        }
        self.notices.error(text);
    }

    pub(super) fn info(&mut self, text: impl Into<String>) {
        self.notices.info(text);
    }

    pub(super) fn with_renderer<R>(
        &self,
        f: impl FnOnce(&mut ViewportRenderer, &wgpu::Device, &wgpu::Queue) -> R,
    ) -> Option<R> {
        let gpu = self.gpu.as_ref()?;
        let mut renderer = gpu.renderer.write();
        let viewport = renderer.callback_resources.get_mut::<ViewportRenderer>()?;
        Some(f(viewport, &gpu.device, &gpu.queue))
    }

    // ---- the document and its GPU copy ----------------------------------------

    /// Make `document` current: the bind queue and the views start afresh on it,
    /// and the camera frames it. Not undoable: for the start-up scene.
    pub(super) fn install_document(&mut self, document: Document) {
        self.model
            .apply(Command::InstallDocument(Box::new(document)));
        self.document_swapped(true);
    }

    /// Replace the whole document, as one undo step, and bind it: the one way
    /// opening files, sessions and scenes and editing the cage change it.
    pub(super) fn replace_document_then_bind(&mut self, replacement: Replacement) {
        let Replacement {
            document,
            action,
            cameras,
            settings,
        } = replacement;
        let kept = self.viewport.cameras();
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
            Cameras::Keep => self.viewport.set_cameras(kept),
            // Relative to the origin the new document set.
            Cameras::Session(cameras) => self.viewport.set_first_cameras(&cameras),
        }
        if let Some((bind_options, view)) = settings {
            self.bind_options = bind_options;
            self.view = view;
            // A session's pose is on disk: quitting keeps it.
            self.apply(Command::MarkSaved);
        }
        self.start_bind();
    }

    /// The view settings a session holds, as shown now.
    fn session_view(&self) -> SessionView {
        SessionView {
            bind_options: self.bind_options,
            view: self.view,
            cameras: self.viewport.cameras(),
        }
    }

    /// Change the model; a pose refused (of another length) is reported.
    pub(super) fn apply(&mut self, command: Command) -> Applied {
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
        self.queue.set_scene(
            document.mesh().positions.as_slice().into(),
            Arc::clone(document.cage()),
        );
        self.readouts.clear();
        // A drag or a transform under way belonged to the old document.
        self.viewport.reset_interaction();
        self.viewport.modal = None;
        let cage_vertices = document.pose().len();
        self.view.heat_vertex = self.view.heat_vertex.min(cage_vertices.saturating_sub(1));
        let cage_triangles = document.cage().triangle_count();
        self.view.heat_triangle = (self.view.heat_triangle)
            .map(|triangle| triangle.min(cage_triangles.saturating_sub(1)));
        self.binding_paused = false;
        // Before framing: the cameras are relative to the new document's origin.
        self.viewport.set_origin(self.document_origin());
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
            self.bind_options = view.bind_options;
            self.view = view.view;
            self.viewport.set_cameras(view.cameras);
        }
        self.sync_parameters_with_weights();
    }

    // ---- pose editing -----------------------------------------------------------

    /// Undo the last step: a pose edit, or an action that replaced the document
    /// (opening a file or a session, switching scenes, subdividing, resting the cage).
    pub fn undo(&mut self) {
        let applied = self.apply(Command::Undo(self.session_view()));
        if let Some(swapped) = applied.swapped {
            self.reinstate_document(&swapped);
            self.info(format!("undid: {}", swapped.action));
        }
    }

    /// Redo what undo reversed last.
    pub fn redo(&mut self) {
        let applied = self.apply(Command::Redo(self.session_view()));
        if let Some(swapped) = applied.swapped {
            self.reinstate_document(&swapped);
            self.info(format!("redid: {}", swapped.action));
        }
    }

    /// What Undo would reverse, for its menu entry ("move handles", "open cage.obj").
    pub fn undo_label(&self) -> Option<String> {
        self.model.undo_label().map(Into::into)
    }

    /// What Redo would repeat, for its menu entry.
    pub fn redo_label(&self) -> Option<String> {
        self.model.redo_label().map(Into::into)
    }

    pub fn reset_pose(&mut self) {
        let rest = self.model.document().cage().positions().to_vec();
        self.apply(Command::edit_pose(rest));
    }

    /// Move one handle to `position`, recording the change for undo.
    pub fn set_handle_position(&mut self, handle: usize, position: DVec3) {
        let mut pose = self.model.document().pose().to_vec();
        if let Some(moved) = pose.get_mut(handle) {
            *moved = position;
            self.apply(Command::edit_pose(pose));
        }
    }

    pub fn select_only(&mut self, handles: impl IntoIterator<Item = usize>) {
        self.select(Selection::only(handles));
    }

    pub(super) fn select(&mut self, selection: Selection) {
        self.apply(Command::Select(selection));
    }

    pub fn frame_scene(&mut self) {
        let (centre, radius) = self.model.document().bounding_sphere();
        self.viewport.frame(centre, radius);
    }

    /// Frame the selected handles (F), or the whole scene when none is selected.
    /// A single handle is framed with room around it: a tenth of the cage.
    pub fn frame_selection(&mut self) {
        let pose = self.model.document().pose();
        let selected: Vec<DVec3> = self
            .model
            .document()
            .selection()
            .iter()
            .map(|&i| pose[i])
            .collect();
        if selected.is_empty() {
            self.frame_scene();
            return;
        }
        let (lo, hi) = crate::geometry::bounds_of(&selected);
        let radius = ((hi - lo).length() / 2.0).max(0.1 * self.model.document().cage().diagonal());
        self.viewport.frame((lo + hi) / 2.0, radius);
    }

    /// The views drawn last frame and their screen rectangles.
    pub fn pane_rects(&self) -> Vec<(Pane, egui::Rect)> {
        self.viewport.pane_rects()
    }

    /// Lock all views to one camera (the first view's) or give each its own.
    pub fn set_cameras_locked(&mut self, locked: bool) {
        if locked != self.view.cameras_locked {
            self.view.cameras_locked = locked;
            self.viewport.unify_cameras();
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
