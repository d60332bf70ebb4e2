//! `--screenshot`: wait for the binds, let a few frames settle, capture the
//! window as PNG, quit. Every error the run reports is also kept here, so that a
//! script learns of it: the command then exits with status 1.

use super::exports::save_png;
use super::scripted_drag::{ScriptedDrag, DRAG_FRAMES, DRAG_START_FRAME};
use super::ui::statistics::FrameStats;
use crate::formats::{refuse_same_file, shown_path};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Frames drawn after the bind before `--screenshot` captures.
const SCREENSHOT_FRAMES: u32 = 90;

pub struct ScreenshotState {
    path: PathBuf,
    frames_after_bind: u32,
    requested: bool,
    saved: Arc<AtomicBool>,
    /// `--drag`: a handle dragged before the capture.
    pub(super) drag: Option<ScriptedDrag>,
    /// What failed during the run, in order; read by `run_editor` after it ends.
    failures: Arc<Mutex<Vec<String>>>,
}

impl ScreenshotState {
    /// A run saving the window to `path`, dragging the handle of cage vertex
    /// `drag` first if given.
    pub fn new(path: PathBuf, drag: Option<usize>) -> Self {
        Self {
            path,
            frames_after_bind: 0,
            requested: false,
            saved: Arc::new(AtomicBool::new(false)),
            drag: drag.map(ScriptedDrag::new),
            failures: Arc::default(),
        }
    }

    /// The failures of this run, shared with whoever waits for it to end.
    pub fn failures(&self) -> Arc<Mutex<Vec<String>>> {
        Arc::clone(&self.failures)
    }

    /// Record into `shared` from now on, with what was recorded so far.
    pub fn share_failures(&mut self, shared: Arc<Mutex<Vec<String>>>) {
        if let (Ok(recorded), Ok(mut list)) = (self.failures.lock(), shared.lock()) {
            list.extend(recorded.iter().cloned());
        }
        self.failures = shared;
    }

    /// Frames drawn since the bind finished.
    pub fn frames_after_bind(&self) -> u32 {
        self.frames_after_bind
    }

    /// The frame after the bind at which the window is captured: later by the
    /// scripted drag's frames when there is one.
    fn capture_frame(&self) -> u32 {
        let drag_frames = self
            .drag
            .as_ref()
            .map_or(0, |_| DRAG_START_FRAME + DRAG_FRAMES + 2);
        SCREENSHOT_FRAMES + drag_frames
    }

    pub fn record_failure(&self, text: &str) {
        if let Ok(mut failures) = self.failures.lock() {
            failures.push(text.to_owned());
        }
    }
}

impl ScreenshotState {
    /// Each frame of a scripted run: wait for the binds (`binding`), let a few
    /// frames settle, capture the window, then close it.
    /// `inputs` are the files the scene was read from, which the PNG may never
    /// replace.
    pub fn drive(
        &mut self,
        ctx: &egui::Context,
        binding: bool,
        inputs: Vec<PathBuf>,
        frames: &mut FrameStats,
    ) {
        if binding {
            ctx.request_repaint_after(Duration::from_millis(50));
            return;
        }
        if self.saved.swap(false, Ordering::Relaxed) {
            if let Some(average) = frames.average() {
                eprintln!("pmvc editor: average frame time {:.1} ms", average * 1000.0);
            }
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            return;
        }
        self.frames_after_bind += 1;
        if self.frames_after_bind == 1 {
            // Measure frame times of the idle scene only, not of the bind.
            frames.restart();
        }
        // Frames before the capture let the GPU upload settle and give a frame-time
        // sample of the continuously redrawn viewport.
        let drag_done = self.drag.as_ref().is_none_or(ScriptedDrag::is_done);
        if self.frames_after_bind >= self.capture_frame() && drag_done && !self.requested {
            self.requested = true;
            let path = self.path.clone();
            let saved = Arc::clone(&self.saved);
            let failures = self.failures();
            let repaint = ctx.clone();
            ctx.request_screenshot(move |image| {
                let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
                let saved_png =
                    refuse_same_file(&path, &inputs).and_then(|()| save_png(&path, &image, None));
                if let Err(error) = saved_png {
                    let text = format!("cannot save {}: {error}", shown_path(&path));
                    eprintln!("pmvc editor: {text}");
                    if let Ok(mut failures) = failures.lock() {
                        failures.push(text);
                    }
                }
                saved.store(true, Ordering::Relaxed);
                repaint.request_repaint();
            });
        }
        ctx.request_repaint();
    }
}
