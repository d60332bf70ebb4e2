//! The Poses section of the side panel: poses kept under a name (stored, applied,
//! renamed and deleted, each one undo step), and a slider that blends the rest
//! pose into the current one to preview the motion. Export and Save pose write
//! what the slider shows.

use crate::app::editor::EditorApp;
use crate::app::model::{Command, GestureKind, Outcome};
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

impl EditorApp {
    /// The blend shown, 0 to 1 (1 when no blend is under way).
    pub fn pose_blend_amount(&self) -> f64 {
        match &self.pose_blend.target {
            Some((_, revision)) if *revision == self.model.document().pose_revision() => {
                self.pose_blend.amount
            }
            _ => 1.0,
        }
    }

    /// Show the rest pose blended `amount` (0 to 1) of the way to the current
    /// pose (or to the pose a blend under way is heading for), as one undo step.
    pub fn set_pose_blend(&mut self, amount: f64) {
        self.apply(Command::BeginGesture(GestureKind::Blend));
        self.preview_pose_blend(amount);
        self.end_pose_blend();
    }

    /// The blend gesture ends as one undo step named by the blend reached.
    fn end_pose_blend(&mut self) {
        let percent = (self.pose_blend.amount * 100.0).round();
        self.apply(Command::EndGesture {
            action: format!("blend the pose to {percent}%"),
        });
    }

    fn preview_pose_blend(&mut self, amount: f64) {
        let amount = amount.clamp(0.0, 1.0);
        let target = match self.pose_blend.target.take() {
            Some((target, revision)) if revision == self.model.document().pose_revision() => target,
            _ => self.model.document().pose().to_vec(),
        };
        let pose = blend_poses(self.model.document().cage().positions(), &target, amount);
        self.apply(Command::PreviewGesture(pose));
        self.pose_blend.amount = amount;
        self.pose_blend.target = Some((target, self.model.document().pose_revision()));
    }

    /// Keep the current pose under `name`.
    pub fn store_named_pose(&mut self, name: &str) {
        let name = name.trim();
        if name.is_empty() {
            self.error("a stored pose needs a name");
            return;
        }
        self.apply(Command::StoreNamedPose(name.to_owned()));
        self.info(format!("stored the pose as \"{name}\""));
    }

    /// Pose the cage as the named pose at `index`, as one undo step.
    pub fn apply_named_pose(&mut self, index: usize) {
        if let Some(named) = self.model.document().named_poses().get(index) {
            let pose = named.positions.clone();
            self.apply(Command::edit_pose(pose));
        }
    }

    pub(in crate::app) fn named_poses_section(&mut self, ui: &mut egui::Ui) {
        ui.label("Poses");
        let amount_now = self.pose_blend_amount();
        let at_rest = self.model.document().pose() == self.model.document().cage().positions();
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
                self.apply(Command::BeginGesture(GestureKind::Blend));
            }
            if slider.changed() {
                if self.model.gesture_under_way() == Some(GestureKind::Blend) {
                    self.preview_pose_blend(percent / 100.0);
                } else {
                    self.set_pose_blend(percent / 100.0);
                }
            }
            if slider.drag_stopped() && self.model.gesture_under_way() == Some(GestureKind::Blend) {
                self.end_pose_blend();
            }
        });

        ui.horizontal(|ui| {
            if self.pose_blend.new_name.is_empty() {
                self.pose_blend.new_name =
                    format!("pose {}", self.model.document().named_poses().len() + 1);
            }
            let label = ui.label("Name:");
            let field = ui
                .add(egui::TextEdit::singleline(&mut self.pose_blend.new_name).desired_width(110.0))
                .labelled_by(label.id);
            let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if ui
                .button("Store pose")
                .on_hover_text("Keep the current pose under this name (sessions save it)")
                .clicked()
                || entered
            {
                let name = std::mem::take(&mut self.pose_blend.new_name);
                self.store_named_pose(&name);
            }
        });

        let mut apply = None;
        let mut delete = None;
        let mut rename = None;
        for (index, named) in self.model.document().named_poses().iter().enumerate() {
            ui.horizontal(|ui| match &mut self.pose_blend.renaming {
                Some((renaming, text)) if *renaming == index => {
                    let label = ui.label("New name:");
                    let field = ui
                        .add(egui::TextEdit::singleline(text).desired_width(110.0))
                        .labelled_by(label.id);
                    if ui.button("OK").clicked()
                        || (field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)))
                    {
                        rename = Some((index, text.clone()));
                    }
                }
                _ => {
                    ui.label(&named.name);
                    if ui.small_button("Apply").clicked() {
                        apply = Some(index);
                    }
                    if ui.small_button("Rename").clicked() {
                        self.pose_blend.renaming = Some((index, named.name.clone()));
                    }
                    if ui
                        .small_button("Delete")
                        .on_hover_text("Forget this pose (Ctrl+Z brings it back)")
                        .clicked()
                    {
                        delete = Some(index);
                    }
                }
            });
        }
        if let Some(index) = apply {
            self.apply_named_pose(index);
        }
        if let Some(index) = delete {
            self.apply(Command::DeleteNamedPose(index));
        }
        if let Some((index, name)) = rename {
            let name = name.trim().to_owned();
            if name.is_empty() {
                self.error("a stored pose needs a name");
            } else if let Outcome::Refused(_) = self
                .apply(Command::RenameNamedPose {
                    index,
                    name: name.clone(),
                })
                .outcome
            {
                self.error(format!("there is already a pose called \"{name}\""));
            } else {
                self.pose_blend.renaming = None;
            }
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
