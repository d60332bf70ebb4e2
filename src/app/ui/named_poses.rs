//! The Poses section of the side panel: poses kept under a name (stored, applied,
//! renamed and deleted, each one undo step), and a slider that blends the rest
//! pose into the current one to preview the motion. Export and Save pose write
//! what the slider shows.

use crate::app::actions::{Action, BlendStep};
use crate::app::commands::{Command, GestureKind};
use crate::app::ctx::PanelContext;
use crate::app::document::Document;
use glam::DVec3;

/// The rest-to-pose slider. While it is below 100% the document shows a blend of
/// the rest pose and `target`; any other change of the pose ends the blend.
#[derive(Clone, Debug, Default)]
pub struct PoseBlend {
    /// The pose blended towards, and the pose revision the slider last set.
    target: Option<(Vec<DVec3>, u64)>,
    /// 0 = rest, 1 = the target.
    amount: f64,
    /// The name field of "Store".
    new_name: String,
    /// The pose being renamed and the text typed so far.
    renaming: Option<(usize, String)>,
    /// A key time being dragged or typed: sent once, when the edit ends.
    editing_time: Option<(usize, f64)>,
}

/// `rest` moved the fraction `amount` of the way to `target`; exactly `target`
/// at 1, so scrubbing back to the end restores the pose bit for bit.
pub fn blend_poses(rest: &[DVec3], target: &[DVec3], amount: f64) -> Vec<DVec3> {
    if amount >= 1.0 {
        return target.to_vec();
    }
    rest.iter()
        .zip(target)
        .map(|(&r, &t)| r + (t - r) * amount)
        .collect()
}

impl PoseBlend {
    /// The blend shown, 0 to 1 (1 when no blend is under way).
    pub fn shown_amount(&self, document: &Document) -> f64 {
        match &self.target {
            Some((_, revision)) if *revision == document.pose_revision() => self.amount,
            _ => 1.0,
        }
    }

    /// The amount asked for, clamped, and the pose a blend heads for: the one
    /// a blend under way heads for, else the current pose.
    pub fn blend_target(&mut self, document: &Document, amount: f64) -> (f64, Vec<DVec3>) {
        let target = match self.target.take() {
            Some((target, revision)) if revision == document.pose_revision() => target,
            _ => document.pose().to_vec(),
        };
        (amount.clamp(0.0, 1.0), target)
    }

    /// The blend now shown: `amount` of the way to `target`, at pose `revision`.
    pub fn blended(&mut self, amount: f64, target: Vec<DVec3>, revision: u64) {
        self.amount = amount;
        self.target = Some((target, revision));
    }

    /// The blend reached, 0 to 1.
    pub fn amount(&self) -> f64 {
        self.amount
    }

    /// A rename went through: the field closes.
    pub fn renamed(&mut self) {
        self.renaming = None;
    }

    pub fn ui(&mut self, ui: &mut egui::Ui, cx: &mut PanelContext) {
        ui.label("Poses");
        let document = cx.document();
        let amount_now = self.shown_amount(document);
        let at_rest = document.pose() == document.cage().positions();
        let mut percent = amount_now * 100.0;
        ui.horizontal(|ui| {
            ui.label("Rest");
            let slider = ui
                .add_enabled(
                    !at_rest || amount_now < 1.0,
                    egui::Slider::new(&mut percent, 0.0..=100.0)
                        .suffix("%")
                        .max_decimals(0)
                        .text("pose"),
                )
                .on_hover_text(
                    "Blend from the rest pose (0%) to the current pose (100%) to preview the \
                     motion. Export and Save pose write the blend shown.",
                )
                .on_disabled_hover_text("The cage is at rest: there is no motion to blend.");
            if slider.drag_started() {
                cx.send(Action::Blend(BlendStep::Begin));
            }
            if slider.changed() {
                // A step of a drag under way (or begun now), else one step at once.
                let dragging = slider.drag_started()
                    || cx.model().gesture_under_way() == Some(GestureKind::Blend);
                cx.send(Action::Blend(if dragging {
                    BlendStep::Preview(percent / 100.0)
                } else {
                    BlendStep::Set(percent / 100.0)
                }));
            }
            if slider.drag_stopped() {
                cx.send(Action::Blend(BlendStep::End));
            }
        });

        ui.horizontal(|ui| {
            if self.new_name.is_empty() {
                self.new_name = format!("pose {}", cx.document().named_poses().len() + 1);
            }
            let label = ui.label("Name:");
            let field = ui
                .add(egui::TextEdit::singleline(&mut self.new_name).desired_width(110.0))
                .labelled_by(label.id);
            let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if ui
                .button("Store pose")
                .on_hover_text("Keep the current pose under this name (sessions save it)")
                .clicked()
                || entered
            {
                cx.send(Action::StoreNamedPose(std::mem::take(&mut self.new_name)));
            }
        });

        let mut sent = Vec::new();
        for (index, named) in cx.document().named_poses().iter().enumerate() {
            ui.horizontal(|ui| match &mut self.renaming {
                Some((renaming, text)) if *renaming == index => {
                    let label = ui.label("New name:");
                    let field = ui
                        .add(egui::TextEdit::singleline(text).desired_width(110.0))
                        .labelled_by(label.id);
                    if ui.button("OK").clicked()
                        || (field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)))
                    {
                        sent.push(Action::RenameNamedPose {
                            index,
                            name: text.clone(),
                        });
                    }
                }
                _ => {
                    ui.label(&named.name);
                    if ui.small_button("Apply").clicked() {
                        sent.push(Action::ApplyNamedPose(index));
                    }
                    if ui.small_button("Rename").clicked() {
                        self.renaming = Some((index, named.name.clone()));
                    }
                    if ui
                        .small_button("Delete")
                        .on_hover_text("Forget this pose (Ctrl+Z brings it back)")
                        .clicked()
                    {
                        sent.push(Action::Apply(Command::DeleteNamedPose(index)));
                    }
                    if let Some(command) = self.key_time(ui, cx.document(), index) {
                        sent.push(Action::Apply(command));
                    }
                }
            });
        }
        for action in sent {
            cx.send(action);
        }
    }
}

impl PoseBlend {
    /// The pose's place on the timeline: a clock toggle and its time, sent as
    /// one command when the edit ends (not one per dragged frame).
    fn key_time(
        &mut self,
        ui: &mut egui::Ui,
        document: &Document,
        index: usize,
    ) -> Option<Command> {
        let named = document.named_poses();
        let time = named[index].time;
        let mut on = time.is_some();
        let toggle = ui
            .toggle_value(&mut on, "key")
            .on_hover_text("Place this pose on the timeline, or take it off");
        if toggle.clicked() {
            let after_last = crate::app::timeline::span(named).map_or(0.0, |(_, last)| last + 1.0);
            return Some(Command::SetPoseTime {
                index,
                time: on.then_some(after_last),
            });
        }
        let time = time?;
        let mut seconds = match self.editing_time {
            Some((editing, seconds)) if editing == index => seconds,
            _ => time,
        };
        let field = ui
            .add(
                egui::DragValue::new(&mut seconds)
                    .range(0.0..=crate::app::timeline::LONGEST_SECONDS)
                    .speed(0.05)
                    .custom_formatter(|seconds, _| format!("{seconds:.2}"))
                    .suffix(" s"),
            )
            .on_hover_text("Its time on the timeline");
        if field.changed() {
            self.editing_time = Some((index, seconds));
        }
        let ended = field.drag_stopped()
            || field.lost_focus()
            || (field.changed() && !field.dragged() && !field.has_focus());
        match self.editing_time {
            Some((editing, seconds)) if editing == index && ended => {
                self.editing_time = None;
                Some(Command::SetPoseTime {
                    index,
                    time: Some(seconds),
                })
            }
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_blend_runs_from_rest_to_the_target_and_ends_on_it_exactly() {
        let rest = [DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0)];
        let target = [DVec3::new(0.0, 0.3, 0.0), DVec3::new(1.0, 0.0, 0.7)];
        assert_eq!(blend_poses(&rest, &target, 0.0), rest.to_vec());
        let half = blend_poses(&rest, &target, 0.5);
        assert_eq!(half[0], DVec3::new(0.0, 0.15, 0.0));
        assert_eq!(half[1], DVec3::new(1.0, 0.0, 0.35));
        assert_eq!(blend_poses(&rest, &target, 1.0), target.to_vec());
    }
}
