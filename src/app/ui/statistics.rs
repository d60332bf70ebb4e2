//! View → Statistics: frame times over the last seconds, measured only while the
//! readout is shown (so idle time before it was switched on never counts).

use crate::app::ctx::PanelContext;
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

/// The readout: whether it is shown, and the frames it measures.
#[derive(Default)]
pub struct StatisticsPanel {
    shown: bool,
    frames: FrameStats,
}

impl StatisticsPanel {
    pub fn is_shown(&self) -> bool {
        self.shown
    }

    /// Show or hide the readout; switching it on or off starts measuring afresh.
    pub fn set_shown(&mut self, shown: bool) {
        if shown != self.shown {
            self.shown = shown;
            self.frames.restart();
        }
    }

    pub fn frames(&self) -> &FrameStats {
        &self.frames
    }

    pub fn frames_mut(&mut self) -> &mut FrameStats {
        &mut self.frames
    }

    /// Frame times, and the size of the document's mesh and weights.
    pub fn ui(&self, ui: &mut egui::Ui, context: &PanelContext) {
        let milliseconds = |seconds: Option<f32>| seconds.map_or(0.0, |s| s * 1000.0);
        ui.label(format!(
            "Frame time: {:.1} ms average, {:.1} ms worst (last {} frames)",
            milliseconds(self.frames.average()),
            milliseconds(self.frames.worst()),
            self.frames.len()
        ));
        let document = context.document();
        let mesh = document.mesh();
        ui.label(format!(
            "{} triangles, {} weights",
            mesh.triangles.len(),
            mesh.positions.len() * document.pose().len()
        ));
    }
}
