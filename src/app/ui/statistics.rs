//! View → Statistics: frame times over the last seconds, measured only while the
//! readout is shown (so idle time before it was switched on never counts).

use crate::app::editor::EditorApp;
use egui::util::History;

/// Frames kept, and how far back they may reach in seconds.
const FRAMES: usize = 120;
const SECONDS: f32 = 4.0;

pub struct FrameStats {
    /// Frame intervals in seconds, keyed by frame time.
    intervals: History<f32>,
    last: Option<f64>,
}

impl Default for FrameStats {
    fn default() -> Self {
        Self {
            intervals: History::new(0..FRAMES, SECONDS),
            last: None,
        }
    }
}

impl FrameStats {
    /// Note a frame drawn at `time` seconds (egui's input time).
    pub fn record_frame(&mut self, time: f64) {
        if let Some(last) = self.last.replace(time) {
            self.intervals.add(time, (time - last) as f32);
        }
    }

    /// Forget what was measured; the next interval starts at the next frame.
    pub fn restart(&mut self) {
        self.intervals.clear();
        self.last = None;
    }

    /// Average frame interval in seconds.
    pub fn average(&self) -> Option<f32> {
        self.intervals.average()
    }

    pub fn worst(&self) -> Option<f32> {
        self.intervals.values().reduce(f32::max)
    }

    pub fn len(&self) -> usize {
        self.intervals.len()
    }

    pub fn is_empty(&self) -> bool {
        self.intervals.is_empty()
    }
}

impl EditorApp {
    /// Average frame interval over the recent frames, in seconds.
    pub fn average_frame_time(&self) -> Option<f32> {
        self.stats.average()
    }

    pub(in crate::app) fn statistics(&self, ui: &mut egui::Ui) {
        let milliseconds = |seconds: Option<f32>| seconds.map_or(0.0, |s| s * 1000.0);
        ui.label(format!(
            "Frame time: {:.1} ms average, {:.1} ms worst (last {} frames)",
            milliseconds(self.stats.average()),
            milliseconds(self.stats.worst()),
            self.stats.len()
        ));
        let mesh = self.model.document().mesh();
        ui.label(format!(
            "{} triangles, {} weights",
            mesh.triangles.len(),
            mesh.positions.len() * self.model.document().pose().len()
        ));
    }
}
