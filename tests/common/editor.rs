//! Driving the editor through egui_kittest with the real app state and the wgpu
//! renderer (lavapipe on CI). Without a GPU adapter the editor tests print "not
//! run" and pass, unless `PMVC_REQUIRE_GPU=1`, which turns a missing adapter into a
//! failure.

use egui::{Event, Modifiers, PointerButton, Pos2};
use egui_kittest::Harness;
use pmvc::app::{BindOn, EditorApp, EditorOptions};
use std::time::{Duration, Instant};

/// A fast resolution keeps the binds in these tests short.
pub const TEST_RESOLUTION: u32 = 8;

pub fn render_state() -> Option<eframe::egui_wgpu::RenderState> {
    render_state_with(egui_kittest::wgpu::default_wgpu_setup())
}

/// A render state whose device has only `limits` (a weaker adapter than the one
/// the tests run on).
pub fn render_state_limited_to(limits: wgpu::Limits) -> Option<eframe::egui_wgpu::RenderState> {
    let mut setup = egui_kittest::wgpu::default_wgpu_setup();
    if let eframe::egui_wgpu::WgpuSetup::CreateNew(create) = &mut setup {
        create.device_descriptor = std::sync::Arc::new(move |_| wgpu::DeviceDescriptor {
            required_limits: limits.clone(),
            ..Default::default()
        });
    }
    render_state_with(setup)
}

/// Limits whose storage bindings hold only `bytes`, with room for a pool of
/// weight chunks (32 storage buffers per stage, as on lavapipe).
pub fn small_storage_bindings(bytes: u64) -> wgpu::Limits {
    wgpu::Limits {
        max_storage_buffer_binding_size: bytes,
        max_storage_buffers_per_shader_stage: 32,
        ..Default::default()
    }
}

fn render_state_with(
    setup: eframe::egui_wgpu::WgpuSetup,
) -> Option<eframe::egui_wgpu::RenderState> {
    let created = pollster::block_on(async {
        let instance = setup.new_instance().await;
        eframe::egui_wgpu::RenderState::create(
            &eframe::egui_wgpu::WgpuConfiguration {
                wgpu_setup: setup,
                ..Default::default()
            },
            &instance,
            None,
            eframe::egui_wgpu::RendererOptions::PREDICTABLE,
        )
        .await
    });
    match created {
        Ok(state) => Some(state),
        Err(error) if std::env::var("PMVC_REQUIRE_GPU").as_deref() == Ok("1") => {
            panic!("PMVC_REQUIRE_GPU=1 but no wgpu adapter: {error}")
        }
        Err(error) => {
            eprintln!("not run: no wgpu adapter ({error})");
            None
        }
    }
}

/// The user guide's pose of the default scene: the middle prong's tip pushed forward.
pub fn guide_pose() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/poses/middle-finger-forward.obj")
}

pub fn editor() -> Option<Harness<'static, EditorApp>> {
    editor_binding_on(BindOn::Auto)
}

pub fn editor_binding_on(bind_on: BindOn) -> Option<Harness<'static, EditorApp>> {
    editor_with(EditorOptions {
        bind_on,
        ..Default::default()
    })
}

/// The editor on the default scene with `options` (at [`TEST_RESOLUTION`] unless
/// they name one).
pub fn editor_with(options: EditorOptions) -> Option<Harness<'static, EditorApp>> {
    Some(editor_on(render_state()?, options))
}

/// The editor on `mesh` in `cage` (at [`TEST_RESOLUTION`]), bound.
pub fn editor_on_files(
    mesh: &std::path::Path,
    cage: &std::path::Path,
) -> Option<Harness<'static, EditorApp>> {
    let mut harness = editor_with(EditorOptions {
        mesh: Some(mesh.to_owned()),
        cage: Some(cage.to_owned()),
        resolution: Some(TEST_RESOLUTION),
        ..Default::default()
    })?;
    run_until_bound(&mut harness);
    Some(harness)
}

/// The editor with `options` on the device of `state`.
pub fn editor_on(
    state: eframe::egui_wgpu::RenderState,
    options: EditorOptions,
) -> Harness<'static, EditorApp> {
    editor_sized(state, options, egui::vec2(1100.0, 700.0), 0.25)
}

/// The editor with `options` in a window of `size` points, each frame
/// `step_dt` seconds after the last (egui_kittest's default is 0.25).
pub fn editor_sized(
    state: eframe::egui_wgpu::RenderState,
    options: EditorOptions,
    size: egui::Vec2,
    step_dt: f32,
) -> Harness<'static, EditorApp> {
    let harness = Harness::builder()
        .with_size(size)
        .with_step_dt(step_dt)
        .renderer(egui_kittest::wgpu::WgpuTestRenderer::from_render_state(
            state,
        ))
        .build_eframe(move |cc| {
            EditorApp::new(
                cc,
                EditorOptions {
                    resolution: Some(options.resolution.unwrap_or(TEST_RESOLUTION)),
                    // Bind times differ from run to run; snapshots must not.
                    hide_timings: true,
                    ..options
                },
            )
        });
    harness
}

/// Snapshot tolerances near egui_kittest's defaults: the frames are deterministic
/// (no timings shown), so a handle that vanishes fails the comparison.
pub fn snapshot_options() -> egui_kittest::SnapshotOptions {
    egui_kittest::SnapshotOptions::new()
        .threshold(1.0)
        .max_failed_pixels(200)
}

/// Step the app until the bind finishes, checking that progress is reported.
pub fn run_until_bound(harness: &mut Harness<'static, EditorApp>) {
    let deadline = Instant::now() + Duration::from_secs(300);
    while harness.state().is_binding() {
        assert!(Instant::now() < deadline, "the bind did not finish in time");
        harness.step();
        std::thread::sleep(Duration::from_millis(20));
    }
    harness.run_steps(3);
}

/// A cage handle with no other handle near it on screen, and its position.
pub fn isolated_handle(harness: &Harness<'static, EditorApp>) -> (usize, Pos2) {
    let app = harness.state();
    let screen: Vec<Option<Pos2>> = (0..app.document().pose().len())
        .map(|i| app.handle_screen_position(i))
        .collect();
    screen
        .iter()
        .enumerate()
        .filter_map(|(i, p)| Some((i, (*p)?)))
        .filter(|(_, p)| p.x > 50.0 && p.x < 700.0 && p.y > 80.0 && p.y < 650.0)
        .find(|(i, p)| {
            screen
                .iter()
                .enumerate()
                .all(|(j, q)| j == *i || q.is_none_or(|q| q.distance(*p) > 25.0))
        })
        .expect("some handle stands alone on screen")
}

/// A plain left click at `at`, as a press and release without movement.
pub fn click(harness: &mut Harness<'static, EditorApp>, at: Pos2) {
    harness.hover_at(at);
    harness.run_steps(2);
    harness.drag_at(at);
    harness.step();
    harness.drop_at(at);
    harness.run_steps(2);
}

pub fn drag(harness: &mut Harness<'static, EditorApp>, from: Pos2, to: Pos2, modifiers: Modifiers) {
    // Held modifier keys, as the window system reports them with every event.
    harness.event(Event::ModifiersChanged(modifiers));
    harness.hover_at(from);
    harness.run_steps(2);
    harness.event(Event::PointerButton {
        pos: from,
        button: PointerButton::Primary,
        pressed: true,
        modifiers,
    });
    harness.step();
    for k in 1..=10 {
        harness.hover_at(from + (to - from) * (k as f32 / 10.0));
        harness.step();
    }
    harness.event(Event::PointerButton {
        pos: to,
        button: PointerButton::Primary,
        pressed: false,
        modifiers,
    });
    harness.run_steps(2);
    harness.event(Event::ModifiersChanged(Modifiers::NONE));
}

/// Select a handle away from the others and drag it across the viewport,
/// returning it and the drawn mesh from before the drag.
pub fn drag_an_isolated_handle(
    harness: &mut Harness<'static, EditorApp>,
) -> (usize, Vec<glam::Vec3>) {
    let before = harness.state().read_back_deformed().unwrap().unwrap();
    let (handle, at) = isolated_handle(harness);
    click(harness, at);
    drag(harness, at, at + egui::vec2(60.0, -30.0), Modifiers::NONE);
    harness.run_steps(2);
    (handle, before)
}

pub fn max_distance(a: &[glam::Vec3], b: &[glam::Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max)
}

/// The mesh at rest, in f32.
pub fn rest_positions(app: &EditorApp) -> Vec<glam::Vec3> {
    let mesh = app.document().mesh();
    mesh.positions.iter().map(|p| p.as_vec3()).collect()
}

/// The window system's close button, as eframe hands it to egui.
pub fn close_window(harness: &mut Harness<'static, EditorApp>) {
    harness
        .input_mut()
        .viewports
        .entry(egui::ViewportId::ROOT)
        .or_default()
        .events
        .push(egui::ViewportEvent::Close);
    harness.run_steps(2);
}

/// A file dropped on the window, as the window system hands it to egui.
#[derive(Debug)]
struct DroppedPath(std::path::PathBuf);

impl egui::DroppedFile for DroppedPath {
    fn path(&self) -> &std::path::Path {
        &self.0
    }

    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

pub fn drop_files(harness: &mut Harness<'static, EditorApp>, paths: &[std::path::PathBuf]) {
    for path in paths {
        harness
            .input_mut()
            .dropped_files
            .push(std::sync::Arc::new(DroppedPath(path.clone())));
    }
    harness.run_steps(3);
}

/// Answer "Save changes before opening …?" with Open without saving; the
/// question must be shown.
pub fn open_without_saving(harness: &mut Harness<'static, EditorApp>) {
    use egui_kittest::kittest::Queryable;
    harness.run_steps(2);
    assert!(
        matches!(
            harness.state().unsaved_question(),
            Some(pmvc::app::ui::unsaved_dialog::Question::Open(_))
        ),
        "opening asks first: {:?}",
        harness.state().unsaved()
    );
    harness.get_by_label("Open without saving").click();
    harness.run_steps(2);
}

/// Type `path` into the in-window dialog's name field and press Enter.
pub fn answer_file_dialog(harness: &mut Harness<'static, EditorApp>, path: &std::path::Path) {
    use egui_kittest::kittest::Queryable;
    harness.get_by_label("File name:").focus();
    harness.step();
    harness.key_press_modifiers(Modifiers::COMMAND, egui::Key::A);
    harness
        .get_by_label("File name:")
        .type_text(path.to_str().unwrap());
    harness.step();
    harness.key_press(egui::Key::Enter);
    harness.run_steps(2);
}

/// Loads, as a pose, the whole cage turned, scaled by 1.5 and shifted; returns
/// the rest mesh under the same map (f32): what a family that follows every
/// similarity of the cage must draw.
pub fn load_a_similarity_pose(harness: &mut Harness<'static, EditorApp>) -> Vec<glam::Vec3> {
    use glam::{DMat3, DVec3};
    let cage = harness.state().document().cage().clone();
    let rotation = DMat3::from_axis_angle(DVec3::new(0.3, 1.0, 0.2).normalize(), 0.6);
    let centre = cage.positions().iter().sum::<DVec3>() / cage.vertex_count() as f64;
    let moved = |p: DVec3| centre + 1.5 * (rotation * (p - centre)) + DVec3::X * 0.4;
    let pose: Vec<DVec3> = cage.positions().iter().map(|&p| moved(p)).collect();
    let dir = tempfile::tempdir().unwrap();
    let pose_path = super::write(
        dir.path(),
        "pose.obj",
        &super::triangles_obj(&pose, cage.triangles()),
    );
    assert!(harness.state_mut().load_pose(&pose_path));
    harness.run_steps(2);
    let rest = rest_positions(harness.state());
    rest.iter().map(|p| moved(p.as_dvec3()).as_vec3()).collect()
}
