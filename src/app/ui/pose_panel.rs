//! The Posing tools section of the side panel: the pivot of rotations and
//! scalings, symmetry, and soft selection.

use crate::app::actions::Action;
use crate::app::ctx::PanelContext;
use crate::app::pose_tools::{
    fitted_mirror_offset, mean_edge_length, MirrorPlane, Pivot, PoseToolSettings, AXIS_NAMES,
    MIRROR_TOLERANCES,
};
use crate::app::posing::handles_without_partner;

/// The section and the settings it owns, which the viewport's edits read.
#[derive(Default)]
pub struct PosePanel {
    pub tools: PoseToolSettings,
}

impl PosePanel {
    /// Fit the mirror plane along `axis` to the rest cage, and say how it went.
    fn fit_mirror_plane(&mut self, cx: &mut PanelContext, axis: usize) {
        let cage = cx.document().cage();
        let rest = cage.positions();
        let tolerance = self.tools.mirror_tolerance * mean_edge_length(rest, cage.triangles());
        let name = AXIS_NAMES[axis].to_lowercase();
        match fitted_mirror_offset(rest, axis, tolerance) {
            Ok(Some((offset, paired))) => {
                self.tools.mirror_plane = MirrorPlane::Fitted(offset);
                cx.send(Action::Info(format!(
                    "mirror plane fitted at {name} = {offset:.4}: {paired} of {} handles paired",
                    rest.len()
                )));
            }
            Ok(None) => cx.send(Action::Error(
                "no mirror plane pairs any handles within the tolerance".into(),
            )),
            Err(why) => cx.send(Action::Error(why)),
        }
    }

    pub fn ui(&mut self, ui: &mut egui::Ui, cx: &mut PanelContext) {
        ui.label("Posing tools (G move, R rotate, S scale)");
        ui.horizontal(|ui| {
            ui.label("Pivot:");
            ui.selectable_value(&mut self.tools.pivot, Pivot::SelectionCentre, "selection")
                .on_hover_text("Rotate and scale about the centre of the selected handles");
            ui.selectable_value(&mut self.tools.pivot, Pivot::Cursor, "3D cursor")
                .on_hover_text("Rotate and scale about the 3D cursor: Shift+right click places it");
        });
        let before = self.tools.symmetry;
        ui.horizontal(|ui| {
            ui.label("Symmetry:");
            ui.selectable_value(&mut self.tools.symmetry, None, "off");
            for (axis, name) in AXIS_NAMES.iter().enumerate() {
                ui.selectable_value(&mut self.tools.symmetry, Some(axis), *name)
                    .on_hover_text(format!(
                        "Mirror every edit across the plane perpendicular to {name}"
                    ));
            }
        });
        if let Some(axis) = self.tools.symmetry {
            ui.horizontal(|ui| {
                ui.label("Plane through:");
                ui.selectable_value(
                    &mut self.tools.mirror_plane,
                    MirrorPlane::CageCentre,
                    "cage centre",
                )
                .on_hover_text("The rest cage's bounding-box centre");
                ui.selectable_value(
                    &mut self.tools.mirror_plane,
                    MirrorPlane::Cursor,
                    "3D cursor",
                )
                .on_hover_text(
                    "The 3D cursor: Shift+right click on the mesh or a handle picks it, \
                         for a cage whose extent is not symmetric",
                );
                let fitted = matches!(self.tools.mirror_plane, MirrorPlane::Fitted(_));
                if ui
                    .selectable_label(fitted, "fitted")
                    .on_hover_text(
                        "The plane that pairs the most handles within the tolerance, found \
                         now (press again after changing the tolerance or the cage)",
                    )
                    .clicked()
                {
                    self.fit_mirror_plane(cx, axis);
                }
            });
            let offset = self
                .tools
                .mirror_offset(cx.document().cage().positions(), axis);
            ui.label(format!(
                "Mirror plane: {} = {offset:.4}",
                AXIS_NAMES[axis].to_lowercase()
            ));
            ui.horizontal(|ui| {
                let mut percent = self.tools.mirror_tolerance * 100.0;
                let range = MIRROR_TOLERANCES;
                let slider = ui
                    .add(
                        egui::Slider::new(
                            &mut percent,
                            range.start() * 100.0..=range.end() * 100.0,
                        )
                        .suffix("%")
                        .max_decimals(0)
                        .text("tolerance"),
                    )
                    .on_hover_text(
                        "How far a handle's mirror image may be from its partner in the rest \
                         cage, in % of the cage's mean edge: artists' cages are symmetric only \
                         to within a tolerance",
                    );
                if slider.changed() {
                    self.tools.mirror_tolerance = percent / 100.0;
                }
            });
            let unpaired = handles_without_partner(cx.document(), &self.tools);
            let handles = cx.document().pose().len();
            ui.label(format!(
                "{} of {handles} handles have a mirror partner",
                handles - unpaired
            ));
            if unpaired > 0 {
                ui.colored_label(
                    ui.visuals().warn_fg_color,
                    format!("{unpaired} handle(s) have no mirror image in the rest cage: their edits are not mirrored"),
                );
            }
            if before != self.tools.symmetry && unpaired > 0 {
                cx.send(Action::Info(format!(
                    "symmetry: {unpaired} handle(s) have no mirror image and are edited alone"
                )));
            }
        }
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.tools.soft_selection, "Soft selection (O)")
                .on_hover_text("Handles near the selection follow its edits, less with distance");
            let mut percent = self.tools.soft_radius * 100.0;
            let radius = ui.add_enabled(
                self.tools.soft_selection,
                egui::Slider::new(&mut percent, 1.0..=100.0)
                    .suffix("%")
                    .max_decimals(0)
                    .text("radius"),
            );
            radius.on_hover_text("The falloff radius, in % of the cage diagonal");
            self.tools.soft_radius = percent / 100.0;
        });
    }
}
