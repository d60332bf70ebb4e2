//! The editor application: menus, toolbar, side panel, and the viewports' mouse
//! and keyboard handling. GPU work goes through [`crate::render`]; binding
//! through [`super::jobs`]; what the views compare is [`super::compare`].
//!
//! Both methods are bound for every scene (the active one first) and both weight
//! sets stay on the GPU, so switching between MVC and PMVC, or showing them side
//! by side, never rebinds.

use super::compare::{self, HoverReadout, Layout, Overlay, Pane, ValueRange, ViewSettings};
use super::jobs::{BindJob, BindOutcome, JobError};
use super::scene::{Bound, PoseHistory, Scene};
use super::scenes::BundledScene;
use super::widgets::{draw_colour_bar, hover_box};
use super::{BindOn, EditorOptions};
use crate::coords::{BindOptions, Method, DEFAULT_RESOLUTION};
use crate::geometry::{
    load_cage, load_mesh, subdivide_midpoint, write_deformed_mesh, write_obj, TriMesh,
};
use crate::gpu::{Backend, GpuContext};
use crate::render::colormap::Scale;
use crate::render::viewport::MSAA_SAMPLES;
use crate::render::{
    Colouring, FrameParams, OrbitCamera, ReadBack, RenderError, SceneUpload, ScreenProjection,
    Shading, ViewportCallback, ViewportRenderer, MAX_VIEWS,
};
use eframe::egui_wgpu;
use egui::{Color32, Key, KeyboardShortcut, Modifiers, PointerButton, Pos2, Rect, Sense, Stroke};
use glam::{DVec3, Vec2, Vec3};
use std::collections::{BTreeSet, VecDeque};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Handles are picked within this many points of the cursor.
const PICK_RADIUS: f32 = 9.0;
/// Handle half-size in points.
const HANDLE_RADIUS: f32 = 4.0;
const RECENT_LIMIT: usize = 8;
/// Frame times kept for the statistics readout.
const FRAME_SAMPLES: usize = 120;
/// Frames drawn after the bind before `--screenshot` captures.
const SCREENSHOT_FRAMES: u32 = 90;
/// The resolutions the PMVC selector offers.
pub const RESOLUTION_CHOICES: [u32; 4] = [16, 32, 64, 128];
/// The hover read-out picks mesh vertices within this many points of the cursor.
const HOVER_RADIUS: f32 = 6.0;
/// Gap between side-by-side views, in points.
const PANE_GAP: f32 = 2.0;

/// What a mouse drag in the viewport is doing.
#[derive(Clone, Debug)]
enum Drag {
    Orbit,
    Pan,
    /// Moving the selected handles: the pose when the drag began, and the total
    /// pointer motion since then (so axis constraints can change mid-drag).
    Move {
        start_pose: Vec<DVec3>,
        motion: egui::Vec2,
    },
    /// Rubber-band selection from `origin`; `additive` keeps the old selection.
    Box {
        origin: Pos2,
        additive: bool,
    },
}

/// A message shown in the status area.
#[derive(Clone, Debug, PartialEq)]
pub struct Notice {
    pub text: String,
    pub is_error: bool,
}

/// The wgpu handles the editor needs outside paint callbacks (uploads, readback).
struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    renderer: Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>,
}

/// Which kind of file is being opened.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileRole {
    Mesh,
    Cage,
}

pub struct EditorApp {
    gpu: Option<Gpu>,
    /// For waking the UI from bind threads started outside a frame.
    egui_ctx: egui::Context,
    pub scene: Scene,
    /// The camera of the first view, and of every view while they are locked.
    pub camera: OrbitCamera,
    /// Cameras of the other views while unlocked (index = view).
    pane_cameras: [OrbitCamera; MAX_VIEWS],
    /// What the viewport compares and how the mesh is coloured.
    pub view: ViewSettings,
    pub selection: BTreeSet<usize>,
    hovered: Option<usize>,
    history: PoseHistory,
    drag: Option<Drag>,
    job: Option<BindJob>,
    /// Binds to run after the current one, in order.
    pending_binds: VecDeque<BindOptions>,
    /// Binds started so far (a method switch must not add one).
    pub bind_count: usize,
    /// The method shown in a single view (and bound first), and the PMVC resolution.
    pub bind_options: BindOptions,
    pub notices: Vec<Notice>,
    pub show_statistics: bool,
    pub highlight_outside: bool,
    recent: Vec<(FileRole, PathBuf)>,
    frame_times: VecDeque<f32>,
    last_frame: Option<Instant>,
    /// Set when the pose or selection changed and the GPU copy is stale.
    pose_dirty: bool,
    handles_dirty: bool,
    /// The views drawn last frame, each with its screen rectangle and projection.
    panes: Vec<(Pane, Rect, ScreenProjection)>,
    /// The mesh deformed on the CPU per method for the current pose (hover picking
    /// and the difference's colour bar); cleared when the pose or weights change.
    deformed_cache: [Option<Arc<Vec<Vec3>>>; 2],
    /// The weights under the cursor, and the view they were read in.
    pub hover_readout: Option<(usize, HoverReadout)>,
    /// Colour-bar ranges already computed (a row-minimum scan of a large matrix
    /// is too slow to repeat every frame); cleared when what they depend on changes.
    range_cache: Vec<((Colouring, Method), Option<ValueRange>)>,
    path_input: String,
    screenshot: Option<ScreenshotState>,
    /// Vertices done / total reported by the last bind when it ended.
    pub last_bind_progress: Option<(usize, usize)>,
    /// Where binds run: the editor's GPU when it is a hardware one, else the CPU.
    bind_backend: Backend,
    /// Set when a failed GPU bind should be retried on the CPU next frame.
    retry_bind: bool,
    /// The pose when a drag on a numeric position field began.
    numeric_drag_start: Option<Vec<DVec3>>,
}

/// `--screenshot`: wait for the bind, let a few frames settle, capture, quit.
struct ScreenshotState {
    path: PathBuf,
    frames_after_bind: u32,
    requested: bool,
    saved: Arc<std::sync::atomic::AtomicBool>,
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
            Gpu {
                device: state.device.clone(),
                queue: state.queue.clone(),
                renderer: Arc::clone(&state.renderer),
            }
        });
        let (mesh, cage) = BundledScene::Comb.build();
        let mut app = Self {
            gpu,
            egui_ctx: cc.egui_ctx.clone(),
            scene: Scene::new(BundledScene::Comb.title(), mesh, cage),
            camera: OrbitCamera::default(),
            pane_cameras: [OrbitCamera::default(); MAX_VIEWS],
            view: options.view,
            selection: BTreeSet::new(),
            hovered: None,
            history: PoseHistory::default(),
            drag: None,
            job: None,
            pending_binds: VecDeque::new(),
            bind_count: 0,
            bind_options: BindOptions {
                method: options.method.unwrap_or(Method::Pmvc),
                resolution: options.resolution.unwrap_or(DEFAULT_RESOLUTION).max(1),
            },
            notices: Vec::new(),
            show_statistics: false,
            highlight_outside: false,
            recent: Vec::new(),
            frame_times: VecDeque::new(),
            last_frame: None,
            pose_dirty: true,
            handles_dirty: true,
            panes: Vec::new(),
            deformed_cache: [None, None],
            hover_readout: None,
            range_cache: Vec::new(),
            path_input: String::new(),
            last_bind_progress: None,
            retry_bind: false,
            numeric_drag_start: None,
            bind_backend: usable_state.map_or(Backend::Cpu, |state| {
                bind_backend_for(state, options.bind_on)
            }),
            screenshot: options.screenshot.map(|path| ScreenshotState {
                path,
                frames_after_bind: 0,
                requested: false,
                saved: Arc::new(std::sync::atomic::AtomicBool::new(false)),
            }),
        };
        if let Some(error) = unsupported {
            app.error(error.to_string());
        } else if app.gpu.is_none() {
            app.error("no wgpu device: the viewport cannot draw (run with the wgpu renderer)");
        }
        let mut opened = false;
        match (&options.mesh, &options.cage) {
            (Some(mesh), Some(cage)) => opened = app.open_pair(mesh, cage),
            (None, None) => {}
            _ => app.error("give both a mesh and a cage; showing the default scene"),
        }
        if !opened {
            app.install_scene(app.scene.clone());
        }
        if let Some(pose) = &options.pose {
            app.load_pose(pose);
        }
        let cage_vertices = app.scene.pose.len();
        if options.view.heat_vertex >= cage_vertices {
            app.error(format!(
                "--heatmap {}: the cage has {cage_vertices} vertices (0 to {}); showing vertex {}",
                options.view.heat_vertex,
                cage_vertices.saturating_sub(1),
                app.view.heat_vertex
            ));
        }
        app.start_bind(&cc.egui_ctx);
        app
    }

    fn error(&mut self, text: impl Into<String>) {
        let text = text.into();
        log::warn!("{text}");
        self.notices.push(Notice {
            text,
            is_error: true,
        });
    }

    fn info(&mut self, text: impl Into<String>) {
        self.notices.push(Notice {
            text: text.into(),
            is_error: false,
        });
    }

    /// The latest error, if any (for tests and the status bar).
    pub fn last_error(&self) -> Option<&str> {
        self.notices
            .iter()
            .rev()
            .find(|n| n.is_error)
            .map(|n| n.text.as_str())
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

    /// Make `scene` current: upload it, reset selection and history, frame it.
    fn install_scene(&mut self, scene: Scene) {
        self.job = None;
        self.pending_binds.clear();
        self.deformed_cache = [None, None];
        self.hover_readout = None;
        self.range_cache.clear();
        self.scene = scene;
        let cage_vertices = self.scene.pose.len();
        self.view.heat_vertex = self.view.heat_vertex.min(cage_vertices.saturating_sub(1));
        self.selection.clear();
        self.hovered = None;
        self.history.clear();
        self.drag = None;
        let rest = to_f32(&self.scene.mesh.positions);
        let cage_rest = to_f32(&self.scene.cage.positions);
        let triangles = self.scene.mesh.triangles.clone();
        let cage_triangles = self.scene.cage.triangles.clone();
        self.with_renderer(|renderer, device, _| {
            renderer.upload_scene(
                device,
                &SceneUpload {
                    rest_positions: &rest,
                    triangles: &triangles,
                    cage_rest: &cage_rest,
                    cage_triangles: &cage_triangles,
                },
            )
        });
        self.pose_dirty = true;
        self.handles_dirty = true;
        self.frame_scene();
    }

    /// Bind the current mesh and cage with both methods, the active one first,
    /// replacing any running bind. Existing weights stay in use until new ones arrive.
    pub fn start_bind(&mut self, ctx: &egui::Context) {
        let active = self.bind_options.method;
        self.bind_methods(ctx, &[active, other_method(active)]);
    }

    /// Bind `methods` in order (PMVC at `bind_options.resolution`), replacing any
    /// running or queued bind.
    fn bind_methods(&mut self, ctx: &egui::Context, methods: &[Method]) {
        self.job = None;
        self.pending_binds = methods
            .iter()
            .map(|&method| BindOptions {
                method,
                resolution: self.bind_options.resolution,
            })
            .collect();
        self.launch_next_bind(ctx);
    }

    fn launch_next_bind(&mut self, ctx: &egui::Context) {
        let Some(options) = self.pending_binds.pop_front() else {
            return;
        };
        let ctx = ctx.clone();
        let points = Arc::new(self.scene.mesh.positions.clone());
        self.bind_count += 1;
        self.job = Some(BindJob::start(
            points,
            Arc::clone(&self.scene.cage),
            options,
            self.bind_backend.clone(),
            move || ctx.request_repaint(),
        ));
    }

    /// A bind is running or queued.
    pub fn is_binding(&self) -> bool {
        self.job.is_some() || !self.pending_binds.is_empty()
    }

    /// The method a single view shows.
    pub fn active_method(&self) -> Method {
        self.bind_options.method
    }

    /// Show `method`: instant, from the weights already bound. Only a method that
    /// has no weights and none on the way is bound.
    pub fn set_active_method(&mut self, method: Method) {
        if method == self.bind_options.method {
            return;
        }
        self.bind_options.method = method;
        self.hover_readout = None;
        let on_the_way = self
            .job
            .as_ref()
            .is_some_and(|j| j.options().method == method)
            || self.pending_binds.iter().any(|o| o.method == method);
        if self.scene.bound(method).is_none() && !on_the_way {
            let ctx = self.egui_ctx.clone();
            self.pending_binds.push_back(BindOptions {
                method,
                resolution: self.bind_options.resolution,
            });
            if self.job.is_none() {
                self.launch_next_bind(&ctx);
            }
        }
    }

    /// Switch between MVC and PMVC (the M key).
    pub fn toggle_method(&mut self) {
        self.set_active_method(other_method(self.bind_options.method));
    }

    /// Rebind PMVC at `resolution` (MVC does not depend on it).
    pub fn set_resolution(&mut self, resolution: u32) {
        let resolution = resolution.max(1);
        if resolution == self.bind_options.resolution {
            return;
        }
        self.bind_options.resolution = resolution;
        let ctx = self.egui_ctx.clone();
        let mut methods = vec![Method::Pmvc];
        // A queued MVC bind still has to happen.
        if self.scene.bound(Method::Mvc).is_none() {
            methods.push(Method::Mvc);
        }
        self.bind_methods(&ctx, &methods);
    }

    /// Subdivide the cage 1-to-4 at edge midpoints, keeping the current pose
    /// (smoother coordinates near reflex edges, the paper's Figure 4), and rebind.
    pub fn subdivide_cage(&mut self) -> bool {
        let subdivided = match subdivide_midpoint(&self.scene.cage, &self.scene.pose) {
            Ok(subdivided) => subdivided,
            Err(error) => {
                self.error(format!("cannot subdivide the cage: {error}"));
                return false;
            }
        };
        let (before, after) = (self.scene.pose.len(), subdivided.cage.vertex_count());
        let mut scene = Scene::new(
            self.scene.title.clone(),
            (*self.scene.mesh).clone(),
            subdivided.cage,
        );
        scene.mesh_file = self.scene.mesh_file.clone();
        scene.pose = subdivided.pose;
        let camera = self.camera;
        self.install_scene(scene);
        self.camera = camera;
        self.pose_dirty = true;
        self.info(format!(
            "subdivided the cage: {before} -> {after} vertices; rebinding"
        ));
        let ctx = self.egui_ctx.clone();
        self.start_bind(&ctx);
        true
    }

    /// Bind progress as (done, total), while binding.
    pub fn bind_progress(&self) -> Option<(usize, usize)> {
        self.job.as_ref().map(|job| (job.done(), job.total()))
    }

    /// Cancel the running bind and those queued after it.
    pub fn cancel_bind(&mut self) {
        self.pending_binds.clear();
        if let Some(job) = &self.job {
            job.cancel();
        }
    }

    /// Wait for the running and queued binds (tests); true if they finished.
    pub fn wait_for_bind(&mut self, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        while let Some(job) = &mut self.job {
            match job.wait(deadline.saturating_duration_since(Instant::now())) {
                Some(result) => self.finish_bind(result),
                None => return false,
            }
        }
        true
    }

    fn poll_bind(&mut self) {
        let Some(job) = &mut self.job else { return };
        if let Some(result) = job.poll() {
            self.finish_bind(result);
        }
    }

    fn finish_bind(&mut self, result: Result<BindOutcome, JobError>) {
        let mut failed_options = None;
        if let Some(job) = self.job.take() {
            self.last_bind_progress = Some((job.done(), job.total()));
            failed_options = Some(job.options());
        }
        let outcome = match result {
            Ok(outcome) => outcome,
            Err(JobError::Cancelled) => {
                self.pending_binds.clear();
                self.info("binding cancelled; the previous weights (if any) stay in use");
                return;
            }
            Err(JobError::Failed(reason)) => {
                self.error(reason);
                if matches!(self.bind_backend, Backend::Gpu(_)) {
                    // The CPU path always works; use it from now on.
                    self.bind_backend = Backend::Cpu;
                    self.info("retrying the bind on the CPU");
                    if let Some(options) = failed_options {
                        self.pending_binds.push_front(options);
                    }
                    self.retry_bind = true;
                } else {
                    let ctx = self.egui_ctx.clone();
                    self.launch_next_bind(&ctx);
                }
                return;
            }
        };
        let ctx = self.egui_ctx.clone();
        self.install_weights(outcome);
        self.launch_next_bind(&ctx);
    }

    /// Put a finished bind's weights in the scene and on the GPU.
    fn install_weights(&mut self, outcome: BindOutcome) {
        if outcome.weights.rows != self.scene.mesh.positions.len()
            || outcome.weights.cols != self.scene.cage.vertex_count()
        {
            return; // A bind for a scene that has since been replaced.
        }
        let method = outcome.options.method;
        let uploaded = self.with_renderer(|renderer, device, queue| {
            let rest = to_f32(&self.scene.mesh.positions);
            renderer.set_outside(queue, &rest, &outcome.outside);
            renderer.set_weights(
                device,
                method,
                Some(&outcome.weights),
                outcome.resident.as_ref(),
            )
        });
        if let Some(Err(error)) = uploaded {
            self.error(error.to_string());
        }
        self.scene.set_bound(
            method,
            Bound {
                weights: outcome.weights,
                options: outcome.options,
                bind_time: outcome.elapsed,
                device: outcome.device,
                quality: outcome.quality,
            },
        );
        self.scene.outside = outcome.outside;
        self.deformed_cache[method_slot(method)] = None;
        self.hover_readout = None;
        self.range_cache.clear();
        self.pose_dirty = true;
    }

    /// Deformed mesh positions of the active method as the vertex shader computes
    /// them, read back from the GPU.
    pub fn read_back_deformed(&self) -> Option<Result<Vec<Vec3>, RenderError>> {
        let shading = Shading {
            method: self.active_method(),
            ..Default::default()
        };
        self.read_back(&shading)
            .map(|result| result.map(|read_back| read_back.positions))
    }

    /// Positions, colouring values and colours as the shaders compute them.
    pub fn read_back(&self, shading: &Shading) -> Option<Result<ReadBack, RenderError>> {
        self.with_renderer(|renderer, device, queue| renderer.read_back(device, queue, shading))
    }

    /// How view `pane` is shaded this frame (method, colouring and colour scale).
    pub fn shading_of(&mut self, pane: Pane) -> Shading {
        let colouring = self.view.colouring(pane);
        Shading {
            method: pane.method(),
            colouring,
            scale: self.view.scale,
            colour_limit: self.colour_limit(colouring),
            cage_size: compare::cage_size(&self.scene.cage.positions) as f32,
        }
    }

    /// The mesh deformed with `method` on the CPU for the current pose (cached).
    fn deformed_on_cpu(&mut self, method: Method) -> Option<Arc<Vec<Vec3>>> {
        let slot = method_slot(method);
        if self.deformed_cache[slot].is_none() {
            let weights = self.scene.weights(method)?;
            self.deformed_cache[slot] = Some(Arc::new(compare::deform(weights, &self.scene.pose)));
        }
        self.deformed_cache[slot].clone()
    }

    /// The range of the values `colouring` shows with `method`'s weights.
    pub fn value_range(&mut self, colouring: Colouring, method: Method) -> Option<ValueRange> {
        let key = (colouring, method);
        if let Some((_, range)) = self.range_cache.iter().find(|(k, _)| *k == key) {
            return *range;
        }
        let range = self.compute_value_range(colouring, method);
        self.range_cache.push((key, range));
        range
    }

    fn compute_value_range(&mut self, colouring: Colouring, method: Method) -> Option<ValueRange> {
        match colouring {
            Colouring::Shaded => None,
            Colouring::CageVertexWeight(vertex) => {
                compare::column_range(self.scene.weights(method)?, vertex as usize)
            }
            Colouring::MostNegativeWeight => {
                compare::row_minimum_range(self.scene.weights(method)?)
            }
            Colouring::MethodDistance => {
                let mvc = self.deformed_on_cpu(Method::Mvc)?;
                let pmvc = self.deformed_on_cpu(Method::Pmvc)?;
                let size = compare::cage_size(&self.scene.cage.positions) as f32;
                compare::distance_range(&pmvc, &mvc, size)
            }
        }
    }

    /// The magnitude at which `colouring`'s colours saturate: the same for both
    /// methods, so that MVC and PMVC are compared on one scale, side by side or
    /// when toggling.
    fn colour_limit(&mut self, colouring: Colouring) -> f32 {
        let limit = [Method::Mvc, Method::Pmvc]
            .into_iter()
            .filter_map(|method| self.value_range(colouring, method))
            .map(|range| range.magnitude())
            .fold(0.0f32, f32::max);
        if limit > 0.0 {
            limit
        } else {
            1.0
        }
    }

    /// Push pending pose and selection changes to the GPU.
    pub fn sync_gpu(&mut self) {
        if self.pose_dirty {
            let pose = to_f32(&self.scene.pose);
            self.with_renderer(|renderer, _, queue| renderer.set_cage_pose(queue, &pose));
            self.pose_dirty = false;
        }
        if self.handles_dirty {
            let states: Vec<u32> = (0..self.scene.pose.len())
                .map(|i| {
                    if self.selection.contains(&i) {
                        1
                    } else if self.hovered == Some(i) {
                        2
                    } else {
                        0
                    }
                })
                .collect();
            self.with_renderer(|renderer, _, queue| renderer.set_handle_states(queue, &states));
            self.handles_dirty = false;
        }
    }

    fn set_pose(&mut self, pose: Vec<DVec3>) {
        if pose.len() == self.scene.pose.len() {
            self.scene.pose = pose;
            self.pose_dirty = true;
            self.deformed_cache = [None, None];
            self.range_cache
                .retain(|((colouring, _), _)| *colouring != Colouring::MethodDistance);
        }
    }

    pub fn undo(&mut self) {
        if let Some(pose) = self.history.undo(&self.scene.pose) {
            self.set_pose(pose);
        }
    }

    pub fn redo(&mut self) {
        if let Some(pose) = self.history.redo(&self.scene.pose) {
            self.set_pose(pose);
        }
    }

    pub fn reset_pose(&mut self) {
        if self.scene.pose != self.scene.cage.positions {
            self.history.record(self.scene.pose.clone());
            let rest = self.scene.cage.positions.clone();
            self.set_pose(rest);
        }
    }

    /// Move one handle to `position`, recording the change for undo.
    pub fn set_handle_position(&mut self, handle: usize, position: DVec3) {
        if handle < self.scene.pose.len() && self.scene.pose[handle] != position {
            self.history.record(self.scene.pose.clone());
            let mut pose = self.scene.pose.clone();
            pose[handle] = position;
            self.set_pose(pose);
        }
    }

    pub fn select_only(&mut self, handles: impl IntoIterator<Item = usize>) {
        self.selection = handles.into_iter().collect();
        self.handles_dirty = true;
    }

    pub fn frame_scene(&mut self) {
        let (centre, radius) = self.scene.bounding_sphere();
        self.camera.frame(centre.as_vec3(), radius as f32);
        self.pane_cameras = [self.camera; MAX_VIEWS];
    }

    /// Lock all views to one camera (the first view's) or give each its own.
    pub fn set_cameras_locked(&mut self, locked: bool) {
        if locked != self.view.cameras_locked {
            self.view.cameras_locked = locked;
            self.pane_cameras = [self.camera; MAX_VIEWS];
        }
    }

    /// The camera view `pane` is drawn with.
    pub fn camera_of(&self, pane: usize) -> OrbitCamera {
        if self.view.cameras_locked || pane == 0 {
            self.camera
        } else {
            self.pane_cameras[pane.min(MAX_VIEWS - 1)]
        }
    }

    fn camera_mut(&mut self, pane: usize) -> &mut OrbitCamera {
        if self.view.cameras_locked || pane == 0 {
            &mut self.camera
        } else {
            &mut self.pane_cameras[pane.min(MAX_VIEWS - 1)]
        }
    }

    fn remember(&mut self, role: FileRole, path: &Path) {
        let entry = (role, path.to_owned());
        self.recent.retain(|e| *e != entry);
        self.recent.insert(0, entry);
        self.recent.truncate(RECENT_LIMIT);
    }

    /// Open a mesh and cage together; on any failure the current scene stays.
    fn open_pair(&mut self, mesh_path: &Path, cage_path: &Path) -> bool {
        let mesh = match load_mesh(mesh_path) {
            Ok(mesh) => mesh,
            Err(error) => {
                self.error(error.to_string());
                return false;
            }
        };
        let (cage, report) = match load_cage(cage_path) {
            Ok(cage) => cage,
            Err(error) => {
                self.error(error.to_string());
                return false;
            }
        };
        for message in report.messages() {
            self.info(message);
        }
        let title = mesh_path
            .file_name()
            .map_or_else(|| "mesh".into(), |n| n.to_string_lossy().into_owned());
        let mut scene = Scene::new(title, mesh.mesh.clone(), cage);
        scene.mesh_file = Some(mesh);
        scene.cage_path = Some(cage_path.to_owned());
        self.install_scene(scene);
        self.remember(FileRole::Mesh, mesh_path);
        self.remember(FileRole::Cage, cage_path);
        true
    }

    /// Replace the mesh (keeping the cage) or the cage (keeping the mesh), then
    /// rebind. A file that fails to load or validate changes nothing.
    pub fn open_file(&mut self, ctx: &egui::Context, role: FileRole, path: &Path) -> bool {
        let scene = match role {
            FileRole::Mesh => match load_mesh(path) {
                Ok(file) => {
                    let mut scene = Scene::new(
                        path.file_name()
                            .map_or_else(|| "mesh".into(), |n| n.to_string_lossy().into_owned()),
                        file.mesh.clone(),
                        (*self.scene.cage).clone(),
                    );
                    scene.mesh_file = Some(file);
                    scene.cage_path = self.scene.cage_path.clone();
                    scene
                }
                Err(error) => {
                    self.error(error.to_string());
                    return false;
                }
            },
            FileRole::Cage => match load_cage(path) {
                Ok((cage, report)) => {
                    for message in report.messages() {
                        self.info(message);
                    }
                    let mut scene =
                        Scene::new(self.scene.title.clone(), (*self.scene.mesh).clone(), cage);
                    scene.mesh_file = self.scene.mesh_file.clone();
                    scene.cage_path = Some(path.to_owned());
                    scene
                }
                Err(error) => {
                    self.error(error.to_string());
                    return false;
                }
            },
        };
        self.install_scene(scene);
        self.remember(role, path);
        self.info(format!("opened {}", path.display()));
        self.start_bind(ctx);
        true
    }

    pub fn open_bundled(&mut self, ctx: &egui::Context, bundled: BundledScene) {
        let (mesh, cage) = bundled.build();
        self.install_scene(Scene::new(bundled.title(), mesh, cage));
        self.start_bind(ctx);
    }

    /// Load a pose: a cage-shaped OBJ/OFF with one vertex per cage vertex.
    pub fn load_pose(&mut self, path: &Path) -> bool {
        match load_mesh(path) {
            Ok(file) if file.mesh.positions.len() == self.scene.pose.len() => {
                self.history.record(self.scene.pose.clone());
                self.set_pose(file.mesh.positions);
                self.info(format!("loaded pose {}", path.display()));
                true
            }
            Ok(file) => {
                self.error(format!(
                    "{}: the pose has {} vertices but the cage has {}",
                    path.display(),
                    file.mesh.positions.len(),
                    self.scene.pose.len()
                ));
                false
            }
            Err(error) => {
                self.error(error.to_string());
                false
            }
        }
    }

    pub fn save_pose(&mut self, path: &Path) {
        let posed = TriMesh {
            positions: self.scene.pose.clone(),
            triangles: self.scene.cage.triangles.clone(),
            triangle_faces: self.scene.cage.triangle_faces.clone(),
        };
        match write_obj(path, &posed) {
            Ok(()) => self.info(format!("saved pose {}", path.display())),
            Err(error) => self.error(error.to_string()),
        }
    }

    pub fn export_deformed(&mut self, path: &Path) {
        let positions = self.scene.deformed_positions(self.active_method());
        let result = match &self.scene.mesh_file {
            Some(file) => write_deformed_mesh(file, &positions, path),
            None => write_obj(
                path,
                &TriMesh {
                    positions,
                    ..(*self.scene.mesh).clone()
                },
            ),
        };
        match result {
            Ok(()) => self.info(format!("exported {}", path.display())),
            Err(error) => self.error(error.to_string()),
        }
    }

    /// Rest the cage in its current pose and rebind.
    fn pose_as_rest(&mut self, ctx: &egui::Context) {
        let cage = self.scene.cage.with_positions(self.scene.pose.clone());
        let mut scene = Scene::new(self.scene.title.clone(), (*self.scene.mesh).clone(), cage);
        scene.mesh_file = self.scene.mesh_file.clone();
        self.install_scene(scene);
        self.start_bind(ctx);
    }

    fn handle_dropped_files(&mut self, ctx: &egui::Context) {
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_owned())
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        });
        for path in dropped {
            // A file whose name mentions "cage" replaces the cage; anything else the mesh.
            let is_cage = path
                .file_name()
                .is_some_and(|n| n.to_string_lossy().to_lowercase().contains("cage"));
            let role = if is_cage {
                FileRole::Cage
            } else {
                FileRole::Mesh
            };
            self.open_file(ctx, role, &path);
        }
    }

    fn handle_shortcuts(&mut self, ctx: &egui::Context) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        let redo_shift = KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
        let redo_y = KeyboardShortcut::new(Modifiers::COMMAND, Key::Y);
        let undo = KeyboardShortcut::new(Modifiers::COMMAND, Key::Z);
        let (redo, undo, escape, frame, toggle_method) = ctx.input_mut(|i| {
            (
                i.consume_shortcut(&redo_shift) || i.consume_shortcut(&redo_y),
                i.consume_shortcut(&undo),
                i.key_pressed(Key::Escape),
                i.key_pressed(Key::F) && i.modifiers.is_none(),
                i.key_pressed(Key::M) && i.modifiers.is_none(),
            )
        });
        if toggle_method {
            self.toggle_method();
        }
        if redo {
            self.redo();
        }
        if undo {
            self.undo();
        }
        if escape {
            self.select_only([]);
        }
        if frame {
            self.frame_scene();
        }
    }

    /// The projection of view `pane` as drawn last frame.
    fn projection(&self, pane: usize) -> Option<ScreenProjection> {
        self.panes.get(pane).map(|(_, _, projection)| *projection)
    }

    /// The view under `pointer`.
    fn pane_at(&self, pointer: Pos2) -> Option<usize> {
        self.panes
            .iter()
            .position(|(_, rect, _)| rect.contains(pointer))
    }

    /// The handle nearest to `pointer` within the pick radius, in the view under it.
    fn pick(&self, pointer: Pos2) -> Option<usize> {
        let projection = self.projection(self.pane_at(pointer)?)?;
        let pointer = Vec2::new(pointer.x, pointer.y);
        self.scene
            .pose
            .iter()
            .enumerate()
            .filter_map(|(i, p)| {
                let screen = projection.project(p.as_vec3())?;
                let distance = screen.distance(pointer);
                (distance <= PICK_RADIUS).then_some((i, distance))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// Screen position (in points) of a cage handle in the first view.
    pub fn handle_screen_position(&self, handle: usize) -> Option<Pos2> {
        self.handle_screen_position_in(0, handle)
    }

    /// Screen position (in points) of a cage handle in view `pane`.
    pub fn handle_screen_position_in(&self, pane: usize, handle: usize) -> Option<Pos2> {
        let screen = self
            .projection(pane)?
            .project(self.scene.pose.get(handle)?.as_vec3())?;
        Some(Pos2::new(screen.x, screen.y))
    }

    /// The views drawn last frame and their screen rectangles.
    pub fn pane_rects(&self) -> Vec<(Pane, Rect)> {
        self.panes
            .iter()
            .map(|(pane, rect, _)| (*pane, *rect))
            .collect()
    }

    /// Screen position of mesh vertex `vertex` as drawn in view `pane`.
    pub fn mesh_vertex_screen_position(&mut self, pane: usize, vertex: usize) -> Option<Pos2> {
        let (kind, _, projection) = *self.panes.get(pane)?;
        let positions = self.deformed_on_cpu(kind.method())?;
        let screen = projection.project(*positions.get(vertex)?)?;
        Some(Pos2::new(screen.x, screen.y))
    }

    fn viewport(&mut self, ui: &mut egui::Ui) {
        let full = ui.available_rect_before_wrap();
        let kinds = self.view.panes(self.active_method());
        let width = (full.width() - PANE_GAP * (kinds.len() as f32 - 1.0)) / kinds.len() as f32;
        let rects: Vec<Rect> = (0..kinds.len())
            .map(|i| {
                let left = full.left() + i as f32 * (width + PANE_GAP);
                Rect::from_min_max(
                    Pos2::new(left, full.top()),
                    Pos2::new(left + width, full.bottom()),
                )
            })
            .collect();
        // Projections first, so that picking sees every view with this frame's layout.
        self.panes = kinds
            .iter()
            .zip(&rects)
            .enumerate()
            .map(|(i, (&kind, &rect))| (kind, rect, self.pane_projection(i, rect)))
            .collect();
        let mut hovered_pane = None;
        for (index, (&kind, &rect)) in kinds.iter().zip(&rects).enumerate() {
            let response = ui.interact(
                rect,
                ui.scope_id().with(("view", index)),
                Sense::click_and_drag(),
            );
            self.viewport_input(ui, index, &response, rect);
            // The input may have moved the camera; draw with the final one.
            let projection = self.pane_projection(index, rect);
            self.panes[index].2 = projection;
            if response.hovered() {
                hovered_pane = Some((index, response.hover_pos()));
            }
            self.draw_pane(ui, index, kind, rect, projection);
        }
        ui.advance_cursor_after_rect(full);
        if hovered_pane.is_none() && self.hovered.is_some() && self.drag.is_none() {
            self.hovered = None;
            self.handles_dirty = true;
        }
        self.update_hover(ui, hovered_pane);
        if let Some(Drag::Box { origin, .. }) = &self.drag {
            if let Some(current) = ui.input(|i| i.pointer.interact_pos()) {
                let band = Rect::from_two_pos(*origin, current);
                ui.painter()
                    .rect_filled(band, 0.0, Color32::from_white_alpha(20));
                ui.painter().rect_stroke(
                    band,
                    0.0,
                    Stroke::new(1.0, Color32::WHITE),
                    egui::StrokeKind::Inside,
                );
            }
        }
    }

    fn pane_projection(&self, pane: usize, rect: Rect) -> ScreenProjection {
        let aspect = rect.width() / rect.height().max(1.0);
        ScreenProjection {
            view_projection: self.camera_of(pane).view_projection(aspect),
            origin: Vec2::new(rect.min.x, rect.min.y),
            size: Vec2::new(rect.width(), rect.height()),
        }
    }

    /// One view: the 3D image, its label, its colour bar and any notice.
    fn draw_pane(
        &mut self,
        ui: &egui::Ui,
        index: usize,
        kind: Pane,
        rect: Rect,
        projection: ScreenProjection,
    ) {
        self.sync_gpu();
        let shading = self.shading_of(kind);
        let painter = ui.painter_at(rect);
        let pixels_per_point = ui.ctx().pixels_per_point();
        if self.gpu.is_some() {
            let params = FrameParams {
                view: index,
                shading,
                view_projection: projection.view_projection,
                eye: self.camera_of(index).eye(),
                size_px: [
                    (rect.width() * pixels_per_point).round().max(1.0) as u32,
                    (rect.height() * pixels_per_point).round().max(1.0) as u32,
                ],
                handle_radius_px: HANDLE_RADIUS * pixels_per_point,
                highlight_outside: self.highlight_outside,
            };
            painter.add(egui_wgpu::Callback::new_paint_callback(
                rect,
                ViewportCallback { params },
            ));
        } else {
            painter.text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "No wgpu device: the viewport is unavailable",
                egui::FontId::proportional(16.0),
                Color32::LIGHT_RED,
            );
        }
        let font = egui::FontId::proportional(14.0);
        painter.text(
            rect.left_top() + egui::vec2(10.0, 8.0),
            egui::Align2::LEFT_TOP,
            self.pane_title(kind),
            font.clone(),
            Color32::from_gray(230),
        );
        let needed: &[Method] = match kind {
            Pane::Method(method) => &[method][..],
            Pane::Difference => &[Method::Mvc, Method::Pmvc][..],
        };
        if needed.iter().any(|&m| self.scene.bound(m).is_none()) {
            let message = if self.is_binding() {
                "Binding… the mesh is shown at rest until the weights are ready"
            } else {
                "Not bound: the mesh is shown at rest (Bind in the side panel)"
            };
            painter.text(
                rect.left_top() + egui::vec2(10.0, 28.0),
                egui::Align2::LEFT_TOP,
                message,
                font,
                Color32::from_gray(200),
            );
        }
        if shading.colouring != Colouring::Shaded {
            if let Some(range) = self.value_range(shading.colouring, kind.method()) {
                draw_colour_bar(&painter, rect, &shading, range, self.colour_bar_title(kind));
            }
        }
    }

    /// "PMVC · 32² · bound in 0.41 s" and the like.
    fn pane_title(&self, kind: Pane) -> String {
        let describe = |method: Method| match self.scene.bound(method) {
            Some(bound) => match method {
                Method::Pmvc => format!(
                    "PMVC · {}² · bound in {:.2} s",
                    bound.options.resolution,
                    bound.bind_time.as_secs_f32()
                ),
                Method::Mvc => format!("MVC · bound in {:.2} s", bound.bind_time.as_secs_f32()),
            },
            None => format!("{} · not bound", method.name()),
        };
        match kind {
            Pane::Method(method) => describe(method),
            Pane::Difference => "MVC vs PMVC: distance / cage size".into(),
        }
    }

    fn colour_bar_title(&self, kind: Pane) -> String {
        let method = kind.method().name();
        match self.view.colouring(kind) {
            Colouring::CageVertexWeight(vertex) => format!("λ{} ({method})", vertex),
            Colouring::MostNegativeWeight => format!("min λ ({method})"),
            Colouring::MethodDistance => "|p'(MVC) - p'(PMVC)| / cage size".into(),
            Colouring::Shaded => String::new(),
        }
    }

    /// Find the mesh vertex under the cursor and read out its weights.
    fn update_hover(&mut self, ui: &egui::Ui, hovered: Option<(usize, Option<Pos2>)>) {
        let target = match hovered {
            // Not in `--screenshot` runs, where the pointer rests wherever the
            // display server put it.
            Some((pane, Some(pointer))) if self.drag.is_none() && self.screenshot.is_none() => {
                Some((pane, pointer))
            }
            _ => None,
        };
        let readout = target.and_then(|(pane, pointer)| {
            let (kind, _, projection) = *self.panes.get(pane)?;
            if !self.view.shows_hover(kind) {
                return None;
            }
            let method = kind.method();
            let positions = self.deformed_on_cpu(method)?;
            let vertex = compare::vertex_under_pointer(
                &positions,
                projection.view_projection,
                projection.origin,
                projection.size,
                Vec2::new(pointer.x, pointer.y),
                HOVER_RADIUS,
            )?;
            let readout = HoverReadout::new(self.scene.weights(method)?, method, vertex)?;
            Some((pane, pointer, readout))
        });
        self.hover_readout = readout.as_ref().map(|(pane, _, r)| (*pane, r.clone()));
        if let Some((_, pointer, readout)) = readout {
            egui::Area::new(egui::Id::unique("hover weights"))
                .order(egui::Order::Tooltip)
                .fixed_pos(pointer + egui::vec2(16.0, 16.0))
                .interactable(false)
                .show(ui.ctx(), |ui| {
                    egui::Frame::popup(ui.style()).show(ui, |ui| hover_box(ui, &readout));
                });
        }
    }

    fn viewport_input(
        &mut self,
        ui: &egui::Ui,
        pane: usize,
        response: &egui::Response,
        rect: Rect,
    ) {
        let (modifiers, press_origin, scroll, hover) = ui.input(|i| {
            (
                i.modifiers,
                i.pointer.press_origin(),
                i.smooth_scroll_delta.y,
                i.pointer.hover_pos(),
            )
        });

        // Hover highlight (not while dragging, so the highlight does not flicker, and
        // not in `--screenshot` runs, where the pointer rests wherever the display
        // server put it).
        if self.drag.is_none() && self.screenshot.is_none() && response.hovered() {
            let hovered = response.hover_pos().and_then(|p| self.pick(p));
            if hovered != self.hovered {
                self.hovered = hovered;
                self.handles_dirty = true;
            }
        }

        if response.hovered() && scroll != 0.0 {
            if let (Some(pointer), Some(projection)) = (hover, self.projection(pane)) {
                let ndc = projection.to_ndc(Vec2::new(pointer.x, pointer.y));
                let factor = (-scroll * 0.0015).exp();
                self.camera_mut(pane).zoom_towards(
                    factor,
                    ndc,
                    rect.width() / rect.height().max(1.0),
                );
            }
        }

        if response.clicked_by(PointerButton::Primary) {
            let picked = response.interact_pointer_pos().and_then(|p| self.pick(p));
            // In heatmap mode a click on a handle shows that vertex's coordinate.
            if let (Some(handle), Overlay::Heatmap) = (picked, self.view.overlay) {
                self.view.heat_vertex = handle;
            }
            match (picked, modifiers.shift) {
                (Some(handle), true) => self.toggle(handle),
                (Some(handle), false) => self.select_only([handle]),
                (None, false) => self.select_only([]),
                (None, true) => {}
            }
        }

        if response.drag_started() {
            let origin = press_origin.unwrap_or(rect.center());
            self.drag = Some(if response.dragged_by(PointerButton::Primary) {
                if modifiers.command || ui.input(|i| i.key_down(Key::B)) {
                    Drag::Box {
                        origin,
                        additive: modifiers.shift,
                    }
                } else if let Some(handle) = self.pick(origin) {
                    if modifiers.shift {
                        if !self.selection.contains(&handle) {
                            self.toggle(handle);
                        }
                    } else if !self.selection.contains(&handle) {
                        self.select_only([handle]);
                    }
                    Drag::Move {
                        start_pose: self.scene.pose.clone(),
                        motion: egui::Vec2::ZERO,
                    }
                } else {
                    Drag::Orbit
                }
            } else if response.dragged_by(PointerButton::Middle) {
                if modifiers.shift {
                    Drag::Pan
                } else {
                    Drag::Orbit
                }
            } else {
                Drag::Pan
            });
        }

        if response.dragged() {
            let delta = response.drag_delta();
            let axis = ui.input(|i| {
                if i.key_down(Key::X) {
                    Some(DVec3::X)
                } else if i.key_down(Key::Y) {
                    Some(DVec3::Y)
                } else if i.key_down(Key::Z) {
                    Some(DVec3::Z)
                } else {
                    None
                }
            });
            match self.drag.take() {
                Some(Drag::Orbit) => {
                    self.camera_mut(pane).orbit(Vec2::new(delta.x, delta.y));
                    self.drag = Some(Drag::Orbit);
                }
                Some(Drag::Pan) => {
                    self.camera_mut(pane)
                        .pan(Vec2::new(delta.x, delta.y), rect.height().min(rect.width()));
                    self.drag = Some(Drag::Pan);
                }
                Some(Drag::Move { start_pose, motion }) => {
                    let motion = motion + delta;
                    let pose = self.moved_pose(pane, &start_pose, motion, axis, rect);
                    self.set_pose(pose);
                    self.drag = Some(Drag::Move { start_pose, motion });
                }
                other => self.drag = other,
            }
        }

        if response.drag_stopped() {
            match self.drag.take() {
                Some(Drag::Move { start_pose, .. }) if start_pose != self.scene.pose => {
                    self.history.record(start_pose);
                }
                Some(Drag::Box { origin, additive }) => {
                    let end = response.interact_pointer_pos().unwrap_or(origin);
                    self.box_select(pane, Rect::from_two_pos(origin, end), additive);
                }
                _ => {}
            }
        }
    }

    fn toggle(&mut self, handle: usize) {
        if !self.selection.remove(&handle) {
            self.selection.insert(handle);
        }
        self.handles_dirty = true;
    }

    fn box_select(&mut self, pane: usize, band: Rect, additive: bool) {
        let Some(projection) = self.projection(pane) else {
            return;
        };
        if !additive {
            self.selection.clear();
        }
        for (i, p) in self.scene.pose.iter().enumerate() {
            if let Some(screen) = projection.project(p.as_vec3()) {
                if band.contains(Pos2::new(screen.x, screen.y)) {
                    self.selection.insert(i);
                }
            }
        }
        self.handles_dirty = true;
    }

    /// `start_pose` with the selection moved by a pointer motion of `motion` points:
    /// in the view plane, or along `axis` by the motion's component along the axis's
    /// screen direction.
    fn moved_pose(
        &self,
        pane: usize,
        start_pose: &[DVec3],
        motion: egui::Vec2,
        axis: Option<DVec3>,
        rect: Rect,
    ) -> Vec<DVec3> {
        let mut pose = start_pose.to_vec();
        if self.selection.is_empty() {
            return pose;
        }
        let centre = self
            .selection
            .iter()
            .filter_map(|&i| start_pose.get(i))
            .sum::<DVec3>()
            / self.selection.len() as f64;
        let camera = self.camera_of(pane);
        let short_side = rect.height().min(rect.width());
        let scale = camera.units_per_pixel(camera.depth_of(centre.as_vec3()), short_side);
        let (right, up) = camera.right_up();
        let in_plane = (right * motion.x - up * motion.y) * scale;
        let offset = match (axis, self.projection(pane)) {
            (Some(axis), Some(projection)) => {
                let from = projection.project(centre.as_vec3());
                let to = projection.project((centre + axis).as_vec3());
                match (from, to) {
                    (Some(from), Some(to)) if (to - from).length_squared() > 1e-6 => {
                        let screen_axis = to - from;
                        let along = Vec2::new(motion.x, motion.y).dot(screen_axis)
                            / screen_axis.length_squared();
                        axis * f64::from(along)
                    }
                    _ => axis * in_plane.as_dvec3().dot(axis),
                }
            }
            _ => in_plane.as_dvec3(),
        };
        for &i in &self.selection {
            if let Some(p) = pose.get_mut(i) {
                *p += offset;
            }
        }
        pose
    }

    fn menu_bar(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("Open mesh…").clicked() {
                    if let Some(path) = pick_file("Open mesh") {
                        self.open_file(&ctx, FileRole::Mesh, &path);
                    }
                }
                if ui.button("Open cage…").clicked() {
                    if let Some(path) = pick_file("Open cage") {
                        self.open_file(&ctx, FileRole::Cage, &path);
                    }
                }
                ui.horizontal(|ui| {
                    ui.label("Path:");
                    ui.text_edit_singleline(&mut self.path_input);
                });
                ui.horizontal(|ui| {
                    let path = PathBuf::from(self.path_input.trim());
                    if ui.button("Open as mesh").clicked() {
                        self.open_file(&ctx, FileRole::Mesh, &path);
                    }
                    if ui.button("Open as cage").clicked() {
                        self.open_file(&ctx, FileRole::Cage, &path);
                    }
                });
                ui.menu_button("Recent files", |ui| {
                    if self.recent.is_empty() {
                        ui.label("(none)");
                    }
                    for (role, path) in self.recent.clone() {
                        let label = format!(
                            "{} {}",
                            if role == FileRole::Mesh {
                                "mesh"
                            } else {
                                "cage"
                            },
                            path.display()
                        );
                        if ui.button(label).clicked() {
                            self.open_file(&ctx, role, &path);
                        }
                    }
                });
                ui.separator();
                if ui.button("Load pose…").clicked() {
                    if let Some(path) = pick_file("Load pose") {
                        self.load_pose(&path);
                    }
                }
                if ui.button("Save pose…").clicked() {
                    if let Some(path) = save_file("Save pose", "pose.obj") {
                        self.save_pose(&path);
                    }
                }
                if ui.button("Export deformed mesh…").clicked() {
                    if let Some(path) = save_file("Export deformed mesh", "deformed.obj") {
                        self.export_deformed(&path);
                    }
                }
                ui.separator();
                if ui.button("Quit").clicked() {
                    ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                }
            });
            ui.menu_button("Edit", |ui| {
                if ui
                    .add_enabled(self.history.can_undo(), egui::Button::new("Undo (Ctrl+Z)"))
                    .clicked()
                {
                    self.undo();
                }
                if ui
                    .add_enabled(
                        self.history.can_redo(),
                        egui::Button::new("Redo (Ctrl+Shift+Z)"),
                    )
                    .clicked()
                {
                    self.redo();
                }
                if ui.button("Reset pose").clicked() {
                    self.reset_pose();
                }
                if ui.button("Use pose as rest shape (rebind)").clicked() {
                    self.pose_as_rest(&ctx);
                }
            });
            ui.menu_button("View", |ui| {
                ui.checkbox(&mut self.show_statistics, "Statistics");
                ui.checkbox(
                    &mut self.view.hover_in_shaded,
                    "Weights under the cursor (always)",
                );
                ui.checkbox(&mut self.highlight_outside, "Highlight outside vertices");
                let mut antialiased = self
                    .with_renderer(|renderer, _, _| renderer.sample_count() > 1)
                    .unwrap_or(false);
                if ui
                    .checkbox(&mut antialiased, "Anti-aliasing (4x MSAA)")
                    .changed()
                {
                    let samples = if antialiased { MSAA_SAMPLES } else { 1 };
                    self.with_renderer(|renderer, device, _| {
                        renderer.set_sample_count(device, samples)
                    });
                }
                if ui.button("Frame scene (F)").clicked() {
                    self.frame_scene();
                }
            });
            ui.menu_button("Scenes", |ui| {
                for bundled in BundledScene::ALL {
                    if ui.button(bundled.title()).clicked() {
                        self.open_bundled(&ctx, bundled);
                    }
                }
            });
        });
    }

    fn side_panel(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        ui.heading(&self.scene.title);
        ui.label(format!(
            "{} mesh vertices, {} cage vertices",
            self.scene.mesh.positions.len(),
            self.scene.pose.len()
        ));
        ui.separator();
        ui.label("Binding");
        let mut resolution = self.bind_options.resolution;
        egui::ComboBox::from_label("PMVC resolution")
            .selected_text(format!("{resolution}²"))
            .show_ui(ui, |ui| {
                for choice in RESOLUTION_CHOICES {
                    ui.selectable_value(&mut resolution, choice, format!("{choice}²"));
                }
            });
        if resolution != self.bind_options.resolution {
            self.set_resolution(resolution);
        }
        if ui
            .button("Subdivide cage")
            .on_hover_text(
                "1-to-4 midpoint subdivision, keeping the pose; smooths the coordinates near sharp reflex edges. Rebinds.",
            )
            .clicked()
        {
            self.subdivide_cage();
        }
        if let Some(job) = &self.job {
            let (done, total) = (job.done(), job.total());
            ui.add(
                egui::ProgressBar::new(job.fraction()).text(format!("{done} / {total} vertices")),
            );
            let remaining = job.estimated_remaining().map_or("estimating…".into(), |r| {
                format!("{:.1} s left", r.as_secs_f32())
            });
            ui.label(format!(
                "{} {} — {:.1} s elapsed, {remaining}",
                if job.is_cancelling() {
                    "Cancelling"
                } else {
                    "Binding"
                },
                job.options().method.name(),
                job.elapsed().as_secs_f32()
            ));
            if ui.button("Cancel").clicked() {
                job.cancel();
            }
            ctx.request_repaint_after(Duration::from_millis(100));
        } else if (self.scene.bound(Method::Mvc).is_none()
            || self.scene.bound(Method::Pmvc).is_none())
            && ui.button("Bind").clicked()
        {
            self.start_bind(&ctx);
        }
        if let Some(bound) = self.scene.bound(self.active_method()) {
            ui.label(format!("Bound on {}", bound.device));
        }
        if self.scene.bound(Method::Mvc).is_some() || self.scene.bound(Method::Pmvc).is_some() {
            let outside = self.scene.outside.len();
            ui.label(format!("{outside} mesh vertices outside the cage"));
            if outside > 0 {
                ui.checkbox(&mut self.highlight_outside, "Highlight them");
            }
        }
        ui.separator();
        self.quality_panel(ui);
        ui.separator();
        ui.label(format!("Selection: {} handle(s)", self.selection.len()));
        if self.selection.len() == 1 {
            if let Some(&handle) = self.selection.iter().next() {
                let mut position = self.scene.pose[handle];
                let (mut changed, mut drag_started, mut drag_stopped) = (false, false, false);
                ui.horizontal(|ui| {
                    ui.label(format!("Handle {handle}"));
                    for (label, value) in [
                        ("x", &mut position.x),
                        ("y", &mut position.y),
                        ("z", &mut position.z),
                    ] {
                        let label = ui.label(label);
                        let field = ui
                            .add(egui::DragValue::new(value).speed(0.01).max_decimals(4))
                            .labelled_by(label.id);
                        changed |= field.changed();
                        drag_started |= field.drag_started();
                        drag_stopped |= field.drag_stopped();
                    }
                });
                // Dragging a field is one undo step; typing a value is one each.
                if drag_started {
                    self.numeric_drag_start = Some(self.scene.pose.clone());
                }
                if changed && self.numeric_drag_start.is_some() {
                    let mut pose = self.scene.pose.clone();
                    pose[handle] = position;
                    self.set_pose(pose);
                } else if changed {
                    self.set_handle_position(handle, position);
                }
                if drag_stopped {
                    if let Some(start) = self.numeric_drag_start.take() {
                        if start != self.scene.pose {
                            self.history.record(start);
                        }
                    }
                }
            }
        }
        ui.horizontal(|ui| {
            if ui.button("Reset pose").clicked() {
                self.reset_pose();
            }
            if ui
                .add_enabled(self.history.can_undo(), egui::Button::new("Undo"))
                .clicked()
            {
                self.undo();
            }
            if ui
                .add_enabled(self.history.can_redo(), egui::Button::new("Redo"))
                .clicked()
            {
                self.redo();
            }
        });
        ui.separator();
        ui.small("Left-drag: orbit / move handles · Right-drag or Shift+middle: pan · Wheel: zoom · Ctrl+drag: box select · Shift+click: toggle · X/Y/Z: axis · F: frame · M: MVC/PMVC · Esc: deselect");
        if self.show_statistics {
            ui.separator();
            self.statistics(ui);
        }
        ui.separator();
        let mut dismiss = None;
        for (index, notice) in self.notices.iter().enumerate().rev().take(6) {
            // Not horizontal_wrapped: there a text just wider than the space left
            // beside the button widens the whole panel. Here it wraps in that space.
            ui.horizontal_top(|ui| {
                let colour = if notice.is_error {
                    Color32::LIGHT_RED
                } else {
                    ui.visuals().text_color()
                };
                if ui.small_button("x").clicked() {
                    dismiss = Some(index);
                }
                ui.add(
                    egui::Label::new(egui::RichText::new(&notice.text).color(colour))
                        .wrap_mode(egui::TextWrapMode::Wrap),
                );
            });
        }
        if let Some(index) = dismiss {
            self.notices.remove(index);
        }
    }

    /// Per-method quality: negativity, partition of unity, linear precision.
    fn quality_panel(&self, ui: &mut egui::Ui) {
        ui.label("Quality");
        let outside = self.scene.outside.len();
        egui::Grid::new("quality")
            .num_columns(3)
            .striped(true)
            .show(ui, |ui| {
                ui.label("");
                ui.strong("MVC");
                ui.strong("PMVC");
                ui.end_row();
                let rows: [QualityRow; 5] = [
                    ("vertices with λ < 0", |b| {
                        format!("{:.1} %", 100.0 * b.quality.negative_share)
                    }),
                    ("most negative λ", |b| {
                        format!("{:.4}", b.quality.most_negative)
                    }),
                    ("max |Σλ - 1|", |b| {
                        format!("{:.1e}", b.quality.max_partition_error)
                    }),
                    ("max |Σλc - x| / size", |b| {
                        format!("{:.1e}", b.quality.max_linear_precision_error)
                    }),
                    ("bind time", |b| {
                        format!("{:.2} s", b.bind_time.as_secs_f32())
                    }),
                ];
                for (name, value) in rows {
                    ui.label(name);
                    for method in [Method::Mvc, Method::Pmvc] {
                        ui.label(self.scene.bound(method).map_or("—".into(), value));
                    }
                    ui.end_row();
                }
                ui.label("outside vertices");
                for method in [Method::Mvc, Method::Pmvc] {
                    let bound = self.scene.bound(method).is_some();
                    ui.label(if bound {
                        outside.to_string()
                    } else {
                        "—".into()
                    });
                }
                ui.end_row();
            });
    }

    /// The comparison controls above the viewport.
    fn toolbar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            ui.label("Method (M):");
            let mut method = self.active_method();
            ui.selectable_value(&mut method, Method::Mvc, "MVC");
            ui.selectable_value(&mut method, Method::Pmvc, "PMVC");
            self.set_active_method(method);
            ui.separator();
            ui.label("View:");
            let layout = &mut self.view.layout;
            ui.selectable_value(layout, Layout::Single, "Single");
            ui.selectable_value(layout, Layout::SideBySide, "Side by side");
            ui.selectable_value(layout, Layout::Difference, "Difference");
            if self.view.layout == Layout::SideBySide {
                ui.checkbox(&mut self.view.difference_pane, "+ difference");
                let mut locked = self.view.cameras_locked;
                if ui.checkbox(&mut locked, "Lock cameras").changed() {
                    self.set_cameras_locked(locked);
                }
            }
            ui.separator();
            ui.label("Colour:");
            let overlay = &mut self.view.overlay;
            ui.selectable_value(overlay, Overlay::Shaded, "Shaded");
            ui.selectable_value(overlay, Overlay::Heatmap, "Heatmap λi");
            ui.selectable_value(overlay, Overlay::Negativity, "Negativity");
            if self.view.overlay == Overlay::Heatmap {
                let last = self.scene.pose.len().saturating_sub(1);
                let label = ui.label("i =");
                ui.add(egui::DragValue::new(&mut self.view.heat_vertex).range(0..=last))
                    .labelled_by(label.id)
                    .on_hover_text("Cage vertex whose coordinate is shown (or click its handle)");
            }
            if self.view.overlay != Overlay::Shaded || self.view.layout != Layout::Single {
                ui.selectable_value(&mut self.view.scale, Scale::Linear, "Linear");
                ui.selectable_value(&mut self.view.scale, Scale::LogMagnitude, "Log");
            }
        });
    }

    fn statistics(&self, ui: &mut egui::Ui) {
        let count = self.frame_times.len().max(1) as f32;
        let average = self.frame_times.iter().sum::<f32>() / count;
        let worst = self.frame_times.iter().copied().fold(0.0, f32::max);
        ui.label(format!(
            "Frame time: {:.1} ms average, {:.1} ms worst (last {} frames)",
            average * 1000.0,
            worst * 1000.0,
            self.frame_times.len()
        ));
        ui.label(format!(
            "{} triangles, {} weights",
            self.scene.mesh.triangles.len(),
            self.scene.mesh.positions.len() * self.scene.pose.len()
        ));
    }

    /// Average frame interval over the recent frames, in seconds.
    pub fn average_frame_time(&self) -> Option<f32> {
        (!self.frame_times.is_empty())
            .then(|| self.frame_times.iter().sum::<f32>() / self.frame_times.len() as f32)
    }

    fn record_frame_time(&mut self) {
        let now = Instant::now();
        if let Some(last) = self.last_frame.replace(now) {
            self.frame_times.push_back((now - last).as_secs_f32());
            if self.frame_times.len() > FRAME_SAMPLES {
                self.frame_times.pop_front();
            }
        }
    }

    fn drive_screenshot(&mut self, ctx: &egui::Context) {
        let Some(state) = &mut self.screenshot else {
            return;
        };
        if self.job.is_some() {
            ctx.request_repaint_after(Duration::from_millis(50));
            return;
        }
        if state
            .saved
            .swap(false, std::sync::atomic::Ordering::Relaxed)
        {
            if let Some(average) = self.average_frame_time() {
                eprintln!("pmvc editor: average frame time {:.1} ms", average * 1000.0);
            }
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            return;
        }
        state.frames_after_bind += 1;
        if state.frames_after_bind == 1 {
            // Measure frame times of the idle scene only, not of the bind.
            self.frame_times.clear();
        }
        // Frames before the capture let the GPU upload settle and give a frame-time
        // sample of the continuously redrawn viewport.
        if state.frames_after_bind >= SCREENSHOT_FRAMES && !state.requested {
            state.requested = true;
            let path = state.path.clone();
            let saved = Arc::clone(&state.saved);
            let repaint = ctx.clone();
            ctx.request_screenshot(move |image| {
                if let Err(error) = save_png(&path, &image) {
                    eprintln!("pmvc editor: cannot save {}: {error}", path.display());
                }
                saved.store(true, std::sync::atomic::Ordering::Relaxed);
                repaint.request_repaint();
            });
        }
        ctx.request_repaint();
    }
}

impl eframe::App for EditorApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.record_frame_time();
        self.poll_bind();
        if std::mem::take(&mut self.retry_bind) {
            self.launch_next_bind(&ctx);
        }
        self.handle_dropped_files(&ctx);
        self.handle_shortcuts(&ctx);
        egui::Panel::top("menu").show(ui, |ui| self.menu_bar(ui));
        egui::Panel::top("toolbar").show(ui, |ui| self.toolbar(ui));
        egui::Panel::right("side")
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.side_panel(ui))
            });
        egui::CentralPanel::no_frame().show(ui, |ui| self.viewport(ui));
        if self.show_statistics {
            // Keep frames coming so the readout measures rendering, not idling.
            ctx.request_repaint();
        }
        self.drive_screenshot(&ctx);
    }
}

fn pick_file(title: &str) -> Option<PathBuf> {
    rfd::FileDialog::new()
        .set_title(title)
        .add_filter("Meshes", &["obj", "off", "OBJ", "OFF"])
        .pick_file()
}

fn save_file(title: &str, name: &str) -> Option<PathBuf> {
    rfd::FileDialog::new()
        .set_title(title)
        .set_file_name(name)
        .add_filter("OBJ", &["obj"])
        .save_file()
}

fn save_png(path: &Path, image: &egui::ColorImage) -> Result<(), image::ImageError> {
    let [width, height] = image.size;
    let bytes: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
    image::save_buffer(
        path,
        &bytes,
        width as u32,
        height as u32,
        image::ColorType::Rgba8,
    )
}

/// A row of the quality table: its name and how a method's bind shows in it.
type QualityRow = (&'static str, fn(&Bound) -> String);

fn other_method(method: Method) -> Method {
    match method {
        Method::Mvc => Method::Pmvc,
        Method::Pmvc => Method::Mvc,
    }
}

fn method_slot(method: Method) -> usize {
    match method {
        Method::Mvc => 0,
        Method::Pmvc => 1,
    }
}

/// Points in the renderer's f32.
fn to_f32(points: &[glam::DVec3]) -> Vec<Vec3> {
    points.iter().map(|p| p.as_vec3()).collect()
}

/// With [`BindOn::Auto`], bind on the editor's own device when it is a hardware
/// GPU; a software adapter binds faster on the CPU path (docs/benchmarks.md).
fn bind_backend_for(state: &egui_wgpu::RenderState, bind_on: BindOn) -> Backend {
    let info = state.adapter.get_info();
    let use_gpu = match bind_on {
        BindOn::Gpu => true,
        BindOn::Cpu => false,
        BindOn::Auto => info.device_type != wgpu::DeviceType::Cpu,
    };
    if !use_gpu {
        return Backend::Cpu;
    }
    Backend::Gpu(Arc::new(GpuContext::from_device(
        state.device.clone(),
        state.queue.clone(),
        info,
    )))
}
