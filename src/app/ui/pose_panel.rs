//! The Posing tools section of the side panel: the pivot of rotations and
//! scalings, symmetry, and soft selection.

use crate::app::editor::EditorApp;
use crate::app::pose_tools::{Pivot, AXIS_NAMES};

impl EditorApp {
    pub(in crate::app) fn pose_tools_section(&mut self, ui: &mut egui::Ui) {
        ui.label("Posing tools (G move, R rotate, S scale)");
        ui.horizontal(|ui| {
            ui.label("Pivot:");
            ui.selectable_value(
                &mut self.pose_tools.pivot,
                Pivot::SelectionCentre,
                "selection",
            )
            .on_hover_text("Rotate and scale about the centre of the selected handles");
            ui.selectable_value(&mut self.pose_tools.pivot, Pivot::Cursor, "3D cursor")
                .on_hover_text("Rotate and scale about the 3D cursor: Shift+right click places it");
        });
        let before = self.pose_tools.symmetry;
        ui.horizontal(|ui| {
            ui.label("Symmetry:");
            ui.selectable_value(&mut self.pose_tools.symmetry, None, "off");
            for (axis, name) in AXIS_NAMES.iter().enumerate() {
                ui.selectable_value(&mut self.pose_tools.symmetry, Some(axis), *name)
                    .on_hover_text(format!(
                        "Mirror every edit across the plane through the rest cage's centre \
                         perpendicular to {name}"
                    ));
            }
        });
        if self.pose_tools.symmetry.is_some() {
            let unpaired = self.handles_without_partner();
            if unpaired > 0 {
                ui.colored_label(
                    ui.visuals().warn_fg_color,
                    format!("{unpaired} handle(s) have no mirror image in the rest cage: their edits are not mirrored"),
                );
            }
            if before != self.pose_tools.symmetry && unpaired > 0 {
                self.info(format!(
                    "symmetry: {unpaired} handle(s) have no mirror image and are edited alone"
                ));
            }
        }
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.pose_tools.soft_selection, "Soft selection (O)")
                .on_hover_text("Handles near the selection follow its edits, less with distance");
            let mut percent = self.pose_tools.soft_radius * 100.0;
            let radius = ui.add_enabled(
                self.pose_tools.soft_selection,
                egui::Slider::new(&mut percent, 1.0..=100.0)
                    .suffix("%")
                    .max_decimals(0)
                    .text("radius"),
            );
            radius.on_hover_text("The falloff radius, in % of the cage diagonal");
            self.pose_tools.soft_radius = percent / 100.0;
        });
    }
}
