//! The Timeline section of the side panel: named poses placed at times play
//! in the viewport, blended linearly between neighbouring keys, looping. The
//! slider scrubs; releasing it keeps the pose shown as one undo step, and Stop
//! brings back the pose from before Play. File > Export glTF… writes the same
//! keys as the glTF animation.

use crate::app::actions::Action;
use crate::app::commands::{Command, GestureKind};
use crate::app::ctx::PanelContext;
use crate::app::timeline::{looped, pose_at, span};

#[derive(Clone, Debug, Default)]
pub struct TimelinePanel {
    /// Playing since egui's clock read this, from this time on the timeline.
    playing: Option<(f64, f64)>,
    /// The time shown, in seconds.
    seconds: f64,
}

impl TimelinePanel {
    pub fn is_playing(&self) -> bool {
        self.playing.is_some()
    }

    /// The time shown, in seconds.
    pub fn seconds(&self) -> f64 {
        self.seconds
    }

    pub fn ui(&mut self, ui: &mut egui::Ui, cx: &mut PanelContext) {
        ui.label("Timeline");
        let named = cx.document().named_poses();
        let mut sent = Vec::new();
        let Some((first, last)) = span(named) else {
            self.playing = None;
            ui.weak("Place named poses at times (the key toggle beside each pose) to play them.");
            return;
        };
        // Another gesture (a drag, an undo) ended the playback.
        if self.playing.is_some() && cx.model().gesture_under_way() != Some(GestureKind::Playback) {
            self.playing = None;
        }
        self.seconds = self.seconds.clamp(first, last);
        let keys = crate::app::timeline::keys(named).len();
        let mut preview = false;
        ui.horizontal(|ui| {
            if self.playing.is_some() {
                if ui
                    .button("Stop")
                    .on_hover_text("Stop, and bring back the pose from before Play")
                    .clicked()
                {
                    self.playing = None;
                    sent.push(Action::Apply(Command::CancelGesture));
                }
            } else if ui
                .add_enabled(keys >= 2, egui::Button::new("Play"))
                .on_hover_text("Play the keys in the viewport, looping")
                .on_disabled_hover_text("Place at least two poses at times")
                .clicked()
            {
                let now = ui.input(|i| i.time);
                self.playing = Some((now, self.seconds));
                sent.push(Action::Apply(Command::BeginGesture(GestureKind::Playback)));
                preview = true;
            }
            let slider = ui
                .add_enabled(
                    self.playing.is_none() && last > first,
                    // Shown to 2 decimals, not rounded: a slider that rounds
                    // its value reports a change each frame the value has more.
                    egui::Slider::new(&mut self.seconds, first..=last)
                        .suffix(" s")
                        .custom_formatter(|seconds, _| format!("{seconds:.2}"))
                        .text("time"),
                )
                .on_hover_text("Scrub: releasing keeps the pose shown (Ctrl+Z undoes it)");
            if slider.drag_started() {
                sent.push(Action::Apply(Command::BeginGesture(GestureKind::Playback)));
            }
            let dragging = slider.dragged() || slider.drag_started() || slider.drag_stopped();
            // Only the user's changes: playback moves the value too.
            let changed = slider.changed() && self.playing.is_none();
            if changed && !dragging {
                // A click or a typed time: that pose, as one undo step.
                if let Some(pose) = pose_at(named, self.seconds) {
                    sent.push(Action::Apply(Command::EditPose {
                        pose,
                        action: format!("pose at {:.2} s", self.seconds),
                    }));
                }
            } else if changed {
                preview = true;
            }
            if slider.drag_stopped() {
                if let Some(pose) = pose_at(named, self.seconds) {
                    sent.push(Action::Apply(Command::PreviewGesture(pose)));
                }
                sent.push(Action::Apply(Command::EndGesture {
                    action: format!("pose at {:.2} s", self.seconds),
                }));
            }
        });
        if let Some((clock, from)) = self.playing {
            let now = ui.input(|i| i.time);
            self.seconds = looped((first, last), from, now - clock);
            preview = true;
            ui.ctx().request_repaint();
        }
        let scrubbing = cx.model().gesture_under_way() == Some(GestureKind::Playback);
        if preview && (scrubbing || self.playing.is_some()) {
            if let Some(pose) = pose_at(named, self.seconds) {
                sent.push(Action::Apply(Command::PreviewGesture(pose)));
            }
        }
        ui.small(format!("{keys} key(s), {first:.2} s to {last:.2} s"));
        for action in sent {
            cx.send(action);
        }
    }
}
