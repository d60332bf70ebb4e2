//! The side panel: the scene, binding (each family's parameter, progress and
//! cancel), quality, the selected handle's position, and the notices.

use crate::app::ctx::PanelContext;
use crate::app::editor::EditorApp;
use crate::app::model::{Command, GestureKind, POSE_EDIT};
use crate::coords::Method;
use std::time::Duration;

impl EditorApp {
    pub(in crate::app) fn side_panel(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        ui.heading(self.model.document().title());
        ui.label(format!(
            "{} mesh vertices, {} cage vertices",
            self.model.document().mesh().positions.len(),
            self.model.document().pose().len()
        ));
        ui.separator();
        self.binding_section(ui, &ctx);
        ui.separator();
        self.quality_table(ui);
        ui.separator();
        self.selection_section(ui);
        ui.separator();
        self.pose_tools_section(ui);
        ui.separator();
        self.named_poses_section(ui);
        ui.separator();
        ui.small("Left-drag: orbit / move handles · Right-drag or Shift+middle: pan · Wheel: zoom · Ctrl+drag: box select · Shift+click: toggle · X/Y/Z: axis · G/R/S: move/rotate/scale · O: soft selection · Shift+right click: 3D cursor · F: frame selection · Home: frame all · H: cage · M: next method · Esc: deselect");
        let mut context = PanelContext::new(&self.model, &mut self.actions);
        if self.statistics.is_shown() {
            ui.separator();
            self.statistics.ui(ui, &context);
        }
        ui.separator();
        self.notices.ui(ui, &mut context);
    }

    fn binding_section(&mut self, ui: &mut egui::Ui, ctx: &egui::Context) {
        ui.label("Binding");
        for family in Method::ALL {
            let Some(spec) = family.spec().parameter else {
                continue;
            };
            let mut value = self.bind_options.get(spec.key);
            egui::ComboBox::from_label(spec.label)
                .selected_text((spec.format)(value))
                .show_ui(ui, |ui| {
                    for &choice in spec.choices {
                        ui.selectable_value(&mut value, choice, (spec.format)(choice));
                    }
                });
            if value != self.bind_options.get(spec.key) {
                self.set_parameter(spec.key, value);
            }
        }
        if ui
            .button("Subdivide cage")
            .on_hover_text(
                "1-to-4 midpoint subdivision, keeping the pose; smooths the coordinates near sharp reflex edges. Rebinds.",
            )
            .clicked()
        {
            self.subdivide_cage();
        }
        if let Some(status) = self.bind_status() {
            ui.add(
                egui::ProgressBar::new(status.fraction)
                    .text(format!("{} / {} vertices", status.done, status.total)),
            );
            let remaining = status.remaining.map_or("estimating…".into(), |r| {
                format!("{:.1} s left", r.as_secs_f32())
            });
            let elapsed = if self.hide_timings {
                String::new()
            } else {
                format!(
                    " — {:.1} s elapsed, {remaining}",
                    status.elapsed.as_secs_f32()
                )
            };
            ui.label(format!(
                "{} {}{elapsed}",
                if status.cancelling {
                    "Cancelling"
                } else {
                    "Binding"
                },
                status.options.method.name(),
            ));
            if ui.button("Cancel").clicked() {
                self.cancel_bind();
            }
            ctx.request_repaint_after(Duration::from_millis(100));
        } else {
            let unbound = self
                .wanted_methods()
                .into_iter()
                .any(|m| self.model.document().bound(m).is_none());
            if unbound && ui.button("Bind").clicked() {
                self.start_bind();
            }
        }
        if let Some(set) = self.model.document().bound(self.active_method()) {
            ui.label(format!("Bound on {}", set.device));
        }
        if self.model.document().bound_methods().next().is_some() {
            let outside = self.model.document().outside().len();
            ui.label(format!("{outside} mesh vertices outside the cage"));
            if outside > 0 {
                ui.checkbox(&mut self.highlight_outside, "Highlight them");
            }
        }
    }

    fn selection_section(&mut self, ui: &mut egui::Ui) {
        let selection = self.model.document().selection();
        ui.label(format!("Selection: {} handle(s)", selection.len()));
        if let (1, Some(&handle)) = (selection.len(), selection.iter().next()) {
            let mut position = self.model.document().pose()[handle];
            let (mut changed, mut drag_started, mut drag_stopped) = (false, false, false);
            ui.label(format!("Handle {handle}"));
            // Fields of a fixed share of the panel: a field sized by its number
            // would widen the panel and move the model under the cursor.
            ui.horizontal(|ui| {
                let spacing = ui.spacing().item_spacing.x;
                let label_width = 3.0 * (ui.spacing().icon_width + 2.0 * spacing);
                let field_size = egui::vec2(
                    ((ui.available_width() - label_width) / 3.0).max(40.0),
                    ui.spacing().interact_size.y,
                );
                for (label, value) in [
                    ("x", &mut position.x),
                    ("y", &mut position.y),
                    ("z", &mut position.z),
                ] {
                    let label = ui.label(label);
                    let field = ui
                        .add_sized(
                            field_size,
                            egui::DragValue::new(value).speed(0.01).max_decimals(4),
                        )
                        .labelled_by(label.id);
                    changed |= field.changed();
                    drag_started |= field.drag_started();
                    drag_stopped |= field.drag_stopped();
                }
            });
            // Dragging a field is one undo step; typing a value is one each.
            if drag_started {
                self.apply(Command::BeginGesture(GestureKind::NumericDrag));
            }
            let dragging = self.model.gesture_under_way() == Some(GestureKind::NumericDrag);
            if changed && dragging {
                let mut pose = self.model.document().pose().to_vec();
                pose[handle] = position;
                self.apply(Command::PreviewGesture(pose));
            } else if changed {
                self.set_handle_position(handle, position);
            }
            if drag_stopped && dragging {
                self.apply(Command::EndGesture {
                    action: POSE_EDIT.into(),
                });
            }
        }
        let (can_undo, can_redo) = (self.undo_label().is_some(), self.redo_label().is_some());
        ui.horizontal(|ui| {
            if ui.button("Reset pose").clicked() {
                self.reset_pose();
            }
            if ui
                .add_enabled(can_undo, egui::Button::new("Undo"))
                .clicked()
            {
                self.undo();
            }
            if ui
                .add_enabled(can_redo, egui::Button::new("Redo"))
                .clicked()
            {
                self.redo();
            }
        });
    }
}
