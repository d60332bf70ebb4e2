//! Thin wrappers over the editor's parts, for tests and scripted runs: each
//! reads a part, or does what a panel's action or a shortcut does, through
//! the same runner and model.

use super::EditorApp;
use crate::app::actions::{Action, BlendStep, CageRequest, FileAction, FileRole};
use crate::app::bind_queue::JobStatus;
use crate::app::cage_generation::CageGeneration;
use crate::app::commands::{Command, Selection};
use crate::app::compare::{HoverReadout, Pane, ValueRange, ViewSettings};
use crate::app::document::Document;
use crate::app::model::Unsaved;
use crate::app::pose_tools::{PoseToolSettings, Transform};
use crate::app::posing;
use crate::app::recent::{RecentEntry, RecentFiles};
use crate::app::scenes::BundledScene;
use crate::app::ui::drop_dialog::DroppedFile;
use crate::app::ui::notices::Notices;
use crate::app::ui::unsaved_dialog::Question;
use crate::app::viewport::TransformKind;
use crate::coords::{BindOptions, Method, Parameter};
use crate::render::{Colouring, OrbitCamera, Shading};
use glam::DVec3;
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

impl EditorApp {
    // ---- reading -----------------------------------------------------------------

    pub fn document(&self) -> &Document {
        self.model.document()
    }

    pub fn view(&self) -> &ViewSettings {
        &self.views.settings
    }

    pub fn view_mut(&mut self) -> &mut ViewSettings {
        &mut self.views.settings
    }

    /// The camera of the first view, and of every view while they are locked;
    /// its target is in scene coordinates ([`Self::scene_origin`]).
    pub fn camera(&self) -> OrbitCamera {
        self.views.camera_of(0)
    }

    /// The camera view `pane` is drawn with (in scene coordinates).
    pub fn camera_of(&self, pane: usize) -> OrbitCamera {
        self.views.camera_of(pane)
    }

    /// The bind options of the method a single view shows.
    pub fn bind_options(&self) -> BindOptions {
        self.binding.options
    }

    /// The options `method` is bound with: its family's current parameters.
    pub fn options_for(&self, method: Method) -> BindOptions {
        self.binding.options_for(method)
    }

    /// The method a single view shows.
    pub fn active_method(&self) -> Method {
        self.binding.active_method()
    }

    /// The methods the current views need, the active one first.
    pub fn wanted_methods(&self) -> Vec<Method> {
        self.wanted_methods_now()
    }

    /// Binds started so far (a method switch to bound weights must not add one).
    pub fn bind_count(&self) -> usize {
        self.binding.queue.jobs_started()
    }

    /// (done, total) vertices of the last bind when it ended.
    pub fn last_bind_progress(&self) -> Option<(usize, usize)> {
        self.binding.queue.last_progress()
    }

    /// A bind is running or queued.
    pub fn is_binding(&self) -> bool {
        self.binding.queue.is_busy()
    }

    /// The running bind, for the progress bar.
    pub fn bind_status(&self) -> Option<JobStatus> {
        self.binding.queue.status()
    }

    /// Bind progress as (done, total), while binding.
    pub fn bind_progress(&self) -> Option<(usize, usize)> {
        (self.binding.queue.status()).map(|status| (status.done, status.total))
    }

    /// The weights under the cursor, and the view they were read in.
    pub fn hover_readout(&self) -> Option<&(usize, HoverReadout)> {
        self.views.viewport.hover_readout.as_ref()
    }

    /// A dialog (file, quit or dropped file) waits for the user.
    pub fn modal_dialog_open(&self) -> bool {
        let panels = &self.panels;
        panels.file_dialogs.is_open() || panels.unsaved.is_asking() || panels.drop.is_open()
    }

    /// What Undo would reverse, for its menu entry ("move handles", "open cage.obj").
    pub fn undo_label(&self) -> Option<String> {
        self.model.undo_label().map(Into::into)
    }

    /// What Redo would repeat, for its menu entry.
    pub fn redo_label(&self) -> Option<String> {
        self.model.redo_label().map(Into::into)
    }

    /// The pose differs from the rest pose and from the last one saved or loaded.
    pub fn pose_is_unsaved(&self) -> bool {
        self.model.pose_unsaved()
    }

    pub fn notices(&self) -> &Notices {
        &self.panels.notices
    }

    pub fn notices_mut(&mut self) -> &mut Notices {
        &mut self.panels.notices
    }

    /// The latest error, if any (for tests and the status bar).
    pub fn last_error(&self) -> Option<&str> {
        self.panels.notices.last_error()
    }

    /// The quit question is shown.
    pub fn is_asking_to_quit(&self) -> bool {
        self.panels.unsaved.question() == Some(&Question::Quit)
    }

    /// Write the recovery file now, as the timer would.
    pub fn autosave(&mut self) -> Result<(), String> {
        self.autosave_now()
    }

    /// This editor's recovery file, when it keeps one.
    pub fn recovery_file(&self) -> Option<&Path> {
        self.files.recovery.as_ref().map(|r| r.file())
    }

    /// The gesture under way, if any.
    pub fn gesture_under_way(&self) -> Option<crate::app::commands::GestureKind> {
        self.model.gesture_under_way()
    }

    /// The timeline is playing.
    pub fn timeline_playing(&self) -> bool {
        self.panels.timeline.is_playing()
    }

    /// The time the timeline shows, in seconds.
    pub fn timeline_seconds(&self) -> f64 {
        self.panels.timeline.seconds()
    }

    /// The recovery question is shown.
    pub fn is_offering_recovery(&self) -> bool {
        self.panels.recovery.is_open()
    }

    /// The session file Save session writes to, if it has one.
    pub fn session_path(&self) -> Option<&Path> {
        self.files.session_path.as_deref()
    }

    /// The unsaved-work question shown, if one is.
    pub fn unsaved_question(&self) -> Option<&Question> {
        self.panels.unsaved.question()
    }

    /// What quitting or opening another scene would lose now.
    pub fn unsaved(&self) -> Unsaved {
        self.model.unsaved()
    }

    /// The window was told to close.
    pub fn quit_confirmed(&self) -> bool {
        self.panels.unsaved.confirmed()
    }

    /// The dropped file waiting for a choice, if any.
    pub fn pending_drop(&self) -> Option<&DroppedFile> {
        self.panels.drop.pending()
    }

    /// Average frame interval over the recent frames, in seconds.
    pub fn average_frame_time(&self) -> Option<f32> {
        self.panels.statistics.frames().average()
    }

    /// File > Recent, most recent first.
    pub fn recent_files(&self) -> &RecentFiles {
        &self.files.recent
    }

    /// The Generate cage window's state, for the window and for tests.
    pub fn cage_generation(&self) -> &CageGeneration {
        &self.panels.cage_window
    }

    pub fn cage_generation_mut(&mut self) -> &mut CageGeneration {
        &mut self.panels.cage_window
    }

    /// The action the in-window dialog is open for, if it is.
    pub fn open_file_dialog(&self) -> Option<FileAction> {
        self.panels.file_dialogs.open_for()
    }

    /// The file name the in-window dialog holds, if it is open.
    pub fn file_dialog_name(&self) -> Option<&str> {
        self.panels.file_dialogs.typed_name()
    }

    /// The blend shown, 0 to 1 (1 when no blend is under way).
    pub fn pose_blend_amount(&self) -> f64 {
        self.panels.named_poses.shown_amount(self.model.document())
    }

    /// Pivot, symmetry, soft selection and the 3D cursor.
    pub fn pose_tool_settings(&self) -> PoseToolSettings {
        self.panels.pose_tools.tools
    }

    /// The posing tools' settings, to change as the Posing tools section does.
    pub fn pose_tool_settings_mut(&mut self) -> &mut PoseToolSettings {
        &mut self.panels.pose_tools.tools
    }

    /// The 3D cursor, in world coordinates.
    pub fn cursor(&self) -> DVec3 {
        self.panels.pose_tools.tools.cursor
    }

    /// Handles with no mirror partner under the symmetry in use.
    pub fn handles_without_partner(&self) -> usize {
        posing::handles_without_partner(self.model.document(), &self.panels.pose_tools.tools)
    }

    pub fn transform_under_way(&self) -> Option<TransformKind> {
        self.views.transform_under_way()
    }

    /// The pose `transform` gives `start` with the current selection, pivot,
    /// soft selection and symmetry.
    pub fn pose_transformed(&self, start: &[DVec3], transform: &Transform) -> Vec<DVec3> {
        let tools = &self.panels.pose_tools.tools;
        posing::pose_transformed(self.model.document(), tools, start, transform)
    }

    /// The views drawn last frame and their screen rectangles.
    pub fn pane_rects(&self) -> Vec<(Pane, egui::Rect)> {
        self.views.viewport.pane_rects()
    }

    /// Screen position (in points) of a cage handle in the first view.
    pub fn handle_screen_position(&self, handle: usize) -> Option<egui::Pos2> {
        self.handle_screen_position_in(0, handle)
    }

    /// Screen position (in points) of a cage handle in view `pane`.
    pub fn handle_screen_position_in(&self, pane: usize, handle: usize) -> Option<egui::Pos2> {
        let at = *self.model.document().pose().get(handle)?;
        self.views.screen_position_in(pane, at)
    }

    /// Screen position of mesh vertex `vertex` as drawn in view `pane`.
    pub fn mesh_vertex_screen_position(
        &mut self,
        pane: usize,
        vertex: usize,
    ) -> Option<egui::Pos2> {
        (self.views).mesh_vertex_screen_position(self.model.document(), pane, vertex)
    }

    /// The range of the values `colouring` shows in `pane`.
    pub fn value_range(&mut self, colouring: Colouring, pane: Pane) -> Option<ValueRange> {
        (self.views).value_range(self.model.document(), colouring, pane)
    }

    /// How view `pane` is shaded this frame (method, colouring and colour scale).
    pub fn shading_of(&mut self, pane: Pane) -> Shading {
        let wanted = self.wanted_methods_now();
        (self.views).shading_of(self.model.document(), &wanted, pane)
    }

    // ---- doing what a panel or a shortcut does --------------------------------------

    /// Queue `action` for the end of the next frame, as a panel would.
    pub fn queue_action(&mut self, action: Action) {
        self.actions.push(action);
    }

    /// Carry out `action` now, through the runner.
    fn now(&mut self, action: Action) {
        self.run_action(&egui::Context::default(), action);
    }

    pub fn undo(&mut self) {
        self.undo_step();
    }

    pub fn redo(&mut self) {
        self.redo_step();
    }

    pub fn reset_pose(&mut self) {
        self.now(Action::ResetPose);
    }

    /// Move one handle to `position`, recording the change for undo.
    pub fn set_handle_position(&mut self, handle: usize, position: DVec3) {
        self.now(Action::SetHandlePosition(handle, position));
    }

    pub fn select_only(&mut self, handles: impl IntoIterator<Item = usize>) {
        self.apply(Command::Select(Selection::only(handles)));
    }

    /// Apply `transform` to the selection as one undo step.
    pub fn transform_selection(&mut self, transform: Transform) {
        let tools = &self.panels.pose_tools.tools;
        posing::transform_selection(&mut self.model, tools, transform);
    }

    pub fn frame_scene(&mut self) {
        self.frame_scene_now();
    }

    /// Frame the selected handles (F), or the whole scene when none is selected.
    pub fn frame_selection(&mut self) {
        self.frame_selection_now();
    }

    /// Lock all views to one camera (the first view's) or give each its own.
    pub fn set_cameras_locked(&mut self, locked: bool) {
        self.lock_cameras(locked);
    }

    /// Use the in-window file dialog (true) or the system's (false).
    pub fn set_in_window_file_dialog(&mut self, in_window: bool) {
        self.panels.file_dialogs.in_window = in_window;
    }

    /// Bind the methods the views show, the active one first, replacing any
    /// running bind. Existing weights stay in use until new ones arrive.
    pub fn start_bind(&mut self) {
        self.now(Action::StartBind);
    }

    /// Show `method`: instant from weights already bound; otherwise its bind is
    /// queued first.
    pub fn set_active_method(&mut self, method: Method) {
        self.set_method(method);
    }

    /// Show the next family (the M key).
    pub fn toggle_method(&mut self) {
        self.now(Action::NextMethod);
    }

    /// Set a family parameter (PMVC's resolution, …) and rebind the families
    /// that read it; the others keep their weights.
    pub fn set_parameter(&mut self, parameter: Parameter, value: u32) {
        self.now(Action::SetParameter(parameter, value));
    }

    /// Rebind PMVC at `resolution` (MVC does not depend on it).
    pub fn set_resolution(&mut self, resolution: u32) {
        self.set_parameter(Parameter::Resolution, resolution);
    }

    /// Cancel the running bind and those queued after it.
    pub fn cancel_bind(&mut self) {
        self.now(Action::CancelBind);
    }

    /// Wait for the running and queued binds (tests); true if they finished.
    pub fn wait_for_bind(&mut self, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        while self.binding.queue.is_busy() {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.binding.queue.wait(left) {
                Some(finished) => self.finish_bind(finished),
                None if left.is_zero() => return false,
                None => self.binding.queue.launch_next(),
            }
        }
        true
    }

    /// Subdivide the cage 1-to-4 at edge midpoints, keeping the current pose,
    /// and rebind; false, with an error, when it cannot.
    pub fn subdivide_cage(&mut self) -> bool {
        let change = crate::app::files::subdivide_cage(self.model.document());
        self.change_scene(change)
    }

    /// Make the current pose the rest shape, and bind afresh (one undo step).
    pub fn pose_as_rest(&mut self) {
        self.now(Action::PoseAsRest);
    }

    /// Show the rest pose blended `amount` (0 to 1) of the way to the current
    /// pose (or to the pose a blend under way is heading for), as one undo step.
    pub fn set_pose_blend(&mut self, amount: f64) {
        self.now(Action::Blend(BlendStep::Set(amount)));
    }

    /// Keep the current pose under `name`.
    pub fn store_named_pose(&mut self, name: &str) {
        self.now(Action::StoreNamedPose(name.to_owned()));
    }

    /// Pose the cage as the named pose at `index`, as one undo step.
    pub fn apply_named_pose(&mut self, index: usize) {
        self.now(Action::ApplyNamedPose(index));
    }

    // ---- files ----------------------------------------------------------------------

    /// Replace the mesh (keeping the cage) or the cage (keeping the mesh), then
    /// rebind. A file that fails to load or validate changes nothing.
    pub fn open_file(&mut self, role: FileRole, path: &Path) -> bool {
        self.open_file_now(role, path)
    }

    /// Open a session: its mesh, cage, poses, method, parameters and views.
    pub fn open_session(&mut self, path: &Path) -> bool {
        self.open_session_now(path)
    }

    /// Open a mesh and its cage together.
    pub fn open_pair(&mut self, mesh: &Path, cage: &Path) -> bool {
        self.open_pair_now(mesh, cage, crate::app::files::ObjectNames::default())
    }

    /// Read object `object` of the mesh's (or the cage's) file in its place,
    /// as the side panel's object choice does; `None`: the file's default.
    pub fn choose_object(&mut self, role: FileRole, object: Option<&str>) -> bool {
        self.reopen_object_now(role, object)
    }

    /// Open a File > Recent entry; one that no longer opens leaves the list.
    pub fn open_recent(&mut self, entry: &RecentEntry) -> bool {
        self.open_recent_now(entry)
    }

    /// Open a bundled scene; if it cannot be loaded the current scene stays.
    pub fn open_bundled(&mut self, bundled: BundledScene) {
        self.now(Action::OpenBundled(bundled));
    }

    /// Load a pose: a cage-shaped OBJ/OFF with one vertex per cage vertex.
    pub fn load_pose(&mut self, path: &Path) -> bool {
        self.load_pose_now(path)
    }

    /// Write the pose as a cage-shaped OBJ; true when it was written.
    pub fn save_pose(&mut self, path: &Path) -> bool {
        self.save_pose_now(path)
    }

    /// Write the rest cage (polygons kept) and its pose beside it; true when
    /// both were written.
    pub fn save_cage(&mut self, path: &Path) -> bool {
        self.save_cage_now(path)
    }

    /// Save the session to `path`; true when it was written.
    pub fn save_session(&mut self, path: &Path) -> bool {
        self.save_session_now(path)
    }

    /// File > Save session: where it was last saved or opened, else ask.
    pub fn save_session_again(&mut self) {
        self.now(Action::SaveSessionAgain);
    }

    /// Write the mesh deformed with the active method; true when it was written.
    pub fn export_deformed(&mut self, path: &Path) -> bool {
        self.export_deformed_now(path)
    }

    /// File > Export glTF…: the rest mesh as the base shape, named poses as
    /// morph targets and the timeline as its animation; true when it was written.
    pub fn export_gltf(&mut self, path: &Path) -> bool {
        self.export_gltf_now(path, crate::app::files::GltfBase::Rest)
    }

    /// File > Export glTF, the pose as its base…: [`Self::export_gltf`] with
    /// the mesh deformed by the current pose as the base shape.
    pub fn export_gltf_posed_base(&mut self, path: &Path) -> bool {
        self.export_gltf_now(path, crate::app::files::GltfBase::Pose)
    }

    /// File > Export coloured mesh…: the deformed mesh as PLY in the view's colours.
    pub fn export_coloured_mesh(&mut self, path: &Path) -> bool {
        self.export_coloured_mesh_now(path)
    }

    /// File > Save image…: the panes as drawn in the next frame.
    pub fn save_image(&mut self, path: &Path) -> bool {
        self.save_image_now(path)
    }

    /// Ask for a file for `action` and carry it out: the system's dialog when it
    /// works, else the in-window one (which finishes in a later frame).
    pub fn ask_for_file(&mut self, action: FileAction) {
        self.ask_for_file_now(action);
    }

    /// File > Generate cage…: open the window.
    pub fn open_cage_generation(&mut self) {
        self.now(Action::CageWindow(CageRequest::Open));
    }

    /// Close the window; a running job is cancelled and a proposal dropped.
    pub fn close_cage_generation(&mut self) {
        self.now(Action::CageWindow(CageRequest::Close));
    }

    /// Generate a cage around the document's mesh in the background.
    pub fn start_cage_generation(&mut self) {
        self.now(Action::CageWindow(CageRequest::Generate));
    }

    /// Replace the document's cage by the proposal, as one undo step, and bind.
    /// Returns false when there is no proposal.
    pub fn use_generated_cage(&mut self) -> bool {
        self.use_generated_cage_now()
    }

    // ---- scripted runs ----------------------------------------------------------------

    /// The failures of a scripted run (`--screenshot`), shared with whoever
    /// waits for it to end; `None` for an interactive run.
    pub fn scripted_failures(&self) -> Option<Arc<Mutex<Vec<String>>>> {
        self.run.screenshot.as_ref().map(|s| s.failures())
    }

    /// Record a scripted run's failures into `shared` from now on.
    pub fn share_scripted_failures(&mut self, shared: Arc<Mutex<Vec<String>>>) {
        if let Some(screenshot) = self.run.screenshot.as_mut() {
            screenshot.share_failures(shared);
        }
    }
}
