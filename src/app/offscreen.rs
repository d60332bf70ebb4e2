//! `--offscreen`: a scripted run (`--screenshot`) with no window and no display.
//! The editor's frames are drawn into a texture on the adapter wgpu picks, as a
//! window would show them, so that servers and CI machines can take pictures and
//! time drags. Each frame waits for the GPU to finish it, as presenting does.

use super::editor::EditorApp;
use super::options::{editor_device_descriptor, EditorError, EditorOptions, SCRIPTED_WINDOW_SIZE};
use eframe::egui_wgpu::{self, RenderState, ScreenDescriptor};
use egui::{ViewportCommand, ViewportId};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The longest sleep between frames while the app waits (a bind in the
/// background wakes it through a repaint request that nobody here hears).
const IDLE_POLL: Duration = Duration::from_millis(20);

/// Run `options` (which must ask for a screenshot) without a window.
pub fn run_offscreen(options: EditorOptions) -> Result<(), EditorError> {
    if options.screenshot.is_none() {
        return Err(EditorError::Offscreen(
            "--offscreen needs --screenshot: without a window there is nobody to close the editor"
                .into(),
        ));
    }
    let state = pollster::block_on(offscreen_render_state())?;
    let ctx = egui::Context::default();
    // eframe's own test constructors: the app gets the same creation context and
    // frame as under egui_kittest, which the UI tests run it with.
    let mut creation = eframe::CreationContext::_new_kittest(ctx.clone());
    creation.wgpu_render_state = Some(state.clone());
    let mut frame = eframe::Frame::_new_kittest();
    let mut app = EditorApp::new(&creation, options);
    let failures = app.scripted_failures();
    let target = Target::new(&state);
    let started = Instant::now();
    let mut events = Vec::new();
    loop {
        let mut input = raw_input(&state, started.elapsed(), std::mem::take(&mut events));
        eframe::App::raw_input_hook(&mut app, &ctx, &mut input);
        let mut output = ctx.run_ui(input, |ui| eframe::App::ui(&mut app, ui, &mut frame));
        let root = output.viewport_output.remove(&ViewportId::ROOT);
        target.draw(&state, &ctx, &mut output)?;
        let mut closing = false;
        let (commands, repaint_delay) = root.map_or((Vec::new(), Duration::ZERO), |root| {
            (root.commands, root.repaint_delay)
        });
        for command in commands {
            match command {
                ViewportCommand::Screenshot(callback) => {
                    callback.complete(Arc::new(target.read_back(&state)?));
                }
                ViewportCommand::Close => closing = true,
                _ => {}
            }
        }
        if closing {
            break;
        }
        if !repaint_delay.is_zero() {
            std::thread::sleep(repaint_delay.min(IDLE_POLL));
        }
    }
    let failures = failures
        .and_then(|list| list.lock().ok().map(|list| list.clone()))
        .unwrap_or_default();
    if failures.is_empty() {
        Ok(())
    } else {
        Err(EditorError::ScriptedRun(failures))
    }
}

/// A render state with no surface, on the adapter and limits a window would get.
async fn offscreen_render_state() -> Result<RenderState, EditorError> {
    let setup = egui_wgpu::WgpuSetup::CreateNew(egui_wgpu::WgpuSetupCreateNew {
        device_descriptor: Arc::new(editor_device_descriptor),
        ..egui_wgpu::WgpuSetupCreateNew::without_display_handle()
    });
    let instance = setup.new_instance().await;
    let configuration = egui_wgpu::WgpuConfiguration {
        wgpu_setup: setup,
        ..Default::default()
    };
    RenderState::create(
        &configuration,
        &instance,
        None,
        egui_wgpu::RendererOptions::default(),
    )
    .await
    .map_err(|error| EditorError::Offscreen(format!("no GPU adapter to draw on: {error}")))
}

/// One frame's input: the window's size and the time since the run began.
fn raw_input(state: &RenderState, elapsed: Duration, events: Vec<egui::Event>) -> egui::RawInput {
    let [width, height] = SCRIPTED_WINDOW_SIZE;
    let rect = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(width, height));
    let mut input = egui::RawInput {
        screen_rect: Some(rect),
        time: Some(elapsed.as_secs_f64()),
        max_texture_side: Some(state.device.limits().max_texture_dimension_2d as usize),
        focused: true,
        events,
        ..Default::default()
    };
    input.viewports.insert(
        ViewportId::ROOT,
        egui::ViewportInfo {
            native_pixels_per_point: Some(1.0),
            focused: Some(true),
            inner_rect: Some(rect),
            ..Default::default()
        },
    );
    input
}

/// The texture that stands in for the window.
struct Target {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    screen: ScreenDescriptor,
}

impl Target {
    fn new(state: &RenderState) -> Self {
        let [width, height] = SCRIPTED_WINDOW_SIZE.map(|side| side as u32);
        let texture = state.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("offscreen window"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: state.target_format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        Self {
            texture,
            view,
            screen: ScreenDescriptor {
                size_in_pixels: [width, height],
                pixels_per_point: 1.0,
            },
        }
    }

    /// Draw the frame's shapes (and the viewport's paint callbacks) and wait
    /// for the GPU to finish them.
    fn draw(
        &self,
        state: &RenderState,
        ctx: &egui::Context,
        output: &mut egui::FullOutput,
    ) -> Result<(), EditorError> {
        let mut renderer = state.renderer.write();
        for (id, deltas) in &output.textures_delta.set {
            for delta in deltas {
                renderer.update_texture(&state.device, &state.queue, *id, delta);
            }
        }
        let shapes = std::mem::take(&mut output.shapes);
        let jobs = ctx.tessellate(shapes, output.pixels_per_point);
        let mut encoder = state
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("offscreen frame"),
            });
        let prepared = renderer.update_buffers(
            &state.device,
            &state.queue,
            &mut encoder,
            &jobs,
            &self.screen,
        );
        {
            let mut pass = encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("offscreen frame"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &self.view,
                        resolve_target: None,
                        depth_slice: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    ..Default::default()
                })
                .forget_lifetime();
            renderer.render(&mut pass, &jobs, &self.screen);
        }
        let submitted = state
            .queue
            .submit(prepared.into_iter().chain([encoder.finish()]));
        for id in &output.textures_delta.free {
            renderer.free_texture(id);
        }
        drop(renderer);
        wait_for(state, submitted)
    }

    /// The last frame drawn, as the window's screenshot would give it.
    fn read_back(&self, state: &RenderState) -> Result<egui::ColorImage, EditorError> {
        let [width, height] = self.screen.size_in_pixels;
        let unpadded = width * 4;
        let padded = unpadded.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = state.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("offscreen screenshot"),
            size: u64::from(padded * height),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = state
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("offscreen screenshot"),
            });
        encoder.copy_texture_to_buffer(
            self.texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: None,
                },
            },
            self.texture.size(),
        );
        state.queue.submit([encoder.finish()]);
        let mapped = crate::render::readback::map_bytes(&state.device, &buffer)
            .map_err(|error| EditorError::Offscreen(format!("cannot read the frame: {error}")))?;
        let blue_first = matches!(
            state.target_format,
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
        );
        let mut rgba = Vec::with_capacity((unpadded * height) as usize);
        for row in mapped.chunks_exact(padded as usize) {
            for texel in row[..unpadded as usize].chunks_exact(4) {
                let [r, g, b, a] = [texel[0], texel[1], texel[2], texel[3]];
                rgba.extend(if blue_first {
                    [b, g, r, a]
                } else {
                    [r, g, b, a]
                });
            }
        }
        Ok(egui::ColorImage::from_rgba_unmultiplied(
            [width as usize, height as usize],
            &rgba,
        ))
    }
}

fn wait_for(state: &RenderState, submitted: wgpu::SubmissionIndex) -> Result<(), EditorError> {
    state
        .device
        .poll(wgpu::PollType::Wait {
            submission_index: Some(submitted),
            timeout: Some(Duration::from_secs(60)),
        })
        .map(drop)
        .map_err(|error| EditorError::Offscreen(format!("the GPU did not finish a frame: {error}")))
}
