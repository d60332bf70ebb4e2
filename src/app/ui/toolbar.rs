//! The comparison controls above the viewport: the method shown, the layout,
//! which methods are compared, and the colouring.

use crate::app::compare::{Layout, Overlay, Pane, DIFFERENCE_LIMITS};
use crate::app::editor::EditorApp;
use crate::coords::Method;
use crate::render::colormap::Scale;
use crate::render::Colouring;

/// What the first run shows, in one line.
pub const FIRST_RUN_LINE: &str = "The middle finger's handles are pulled up. \
    Left, MVC: negative weights make the fingers beside it sink. Middle, PMVC: they stay. \
    Right: the distance between the two. Drag any handle to try.";

impl EditorApp {
    /// The first run's line, with a button that dismisses it.
    pub(in crate::app) fn first_run_line(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            if ui.small_button("Hide").clicked() {
                self.first_run_hint = false;
            }
            ui.label(egui::RichText::new(FIRST_RUN_LINE).strong());
        });
    }

    pub(in crate::app) fn toolbar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            ui.label("Method (M):");
            let mut method = self.active_method();
            for family in Method::ALL {
                ui.selectable_value(&mut method, family, family.name())
                    .on_hover_text(family.spec().summary);
            }
            self.set_active_method(method);
            ui.separator();
            ui.label("View:");
            let layout = &mut self.view.layout;
            ui.selectable_value(layout, Layout::Single, "Single");
            ui.selectable_value(layout, Layout::SideBySide, "Side by side");
            ui.selectable_value(layout, Layout::Difference, "Difference");
            match self.view.layout {
                Layout::SideBySide => self.comparison_controls(ui),
                Layout::Difference => self.difference_controls(ui),
                Layout::Single => {}
            }
            ui.separator();
            ui.label("Colour:");
            let overlay = &mut self.view.overlay;
            ui.selectable_value(overlay, Overlay::Shaded, "Shaded");
            ui.selectable_value(overlay, Overlay::Heatmap, "Heatmap λi");
            ui.selectable_value(overlay, Overlay::Negativity, "Negativity");
            if self.view.overlay == Overlay::Heatmap {
                self.heatmap_controls(ui);
            }
            if self.view.overlay != Overlay::Shaded || self.view.layout != Layout::Single {
                let scale = self.view.overlay_scale_mut();
                ui.selectable_value(scale, Scale::Linear, "Linear");
                ui.selectable_value(scale, Scale::LogMagnitude, "Log");
            }
        });
    }

    /// Which coordinate function the heatmap shows: a cage vertex's, or (Green
    /// coordinates) a cage triangle's ψ.
    fn heatmap_controls(&mut self, ui: &mut egui::Ui) {
        let triangles = self.model.document().cage().triangle_count();
        let mut of_triangle = self.view.heat_triangle.is_some();
        let label = ui.label("of");
        egui::ComboBox::from_id_salt("heatmap of")
            .selected_text(if of_triangle {
                "ψj of triangle"
            } else {
                "λi of vertex"
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut of_triangle, false, "λi of vertex")
                    .on_hover_text("Every family: the coordinate of cage vertex i (φi for Green)");
                ui.selectable_value(&mut of_triangle, true, "ψj of triangle")
                    .on_hover_text("Green coordinates only: the function of cage triangle j");
            })
            .response
            .labelled_by(label.id);
        if of_triangle {
            let mut triangle = self.view.heat_triangle.unwrap_or(0);
            let label = ui.label("j =");
            ui.add(egui::DragValue::new(&mut triangle).range(0..=triangles.saturating_sub(1)))
                .labelled_by(label.id)
                .on_hover_text("Cage triangle, in the order the cage's faces are triangulated");
            self.view.heat_triangle = Some(triangle);
        } else {
            self.view.heat_triangle = None;
            let last = self.model.document().pose().len().saturating_sub(1);
            let label = ui.label("i =");
            ui.add(egui::DragValue::new(&mut self.view.heat_vertex).range(0..=last))
                .labelled_by(label.id)
                .on_hover_text("Cage vertex whose coordinate is shown (or click its handle)");
        }
    }

    /// Which methods the side-by-side layout shows.
    fn comparison_controls(&mut self, ui: &mut egui::Ui) {
        if Method::ALL.len() > 2 {
            ui.menu_button("Compare…", |ui| {
                for family in Method::ALL {
                    let mut shown = self.view.compared.contains(family);
                    if ui.checkbox(&mut shown, family.name()).changed() {
                        self.view.compared.set(family, shown);
                    }
                }
            });
        }
        ui.checkbox(&mut self.view.difference_pane, "+ difference");
        if self.view.difference_pane {
            self.difference_scale_controls(ui);
        }
        let mut locked = self.view.cameras_locked;
        if ui.checkbox(&mut locked, "Lock cameras").changed() {
            self.set_cameras_locked(locked);
        }
    }

    /// Which two methods the difference compares: "[MVC] vs [PMVC] shown".
    fn difference_controls(&mut self, ui: &mut egui::Ui) {
        for (index, label) in ["vs", "shown"].into_iter().enumerate() {
            let mut chosen = self.view.difference[index];
            egui::ComboBox::from_label(label)
                .selected_text(chosen.name())
                .show_ui(ui, |ui| {
                    for family in Method::ALL {
                        ui.selectable_value(&mut chosen, family, family.name());
                    }
                });
            self.view.difference[index] = chosen;
        }
        self.difference_scale_controls(ui);
    }

    /// Auto (the largest distance, at least `compare::DIFFERENCE_FLOOR`) or a fixed end
    /// of the difference's colour scale, shared by every difference view.
    fn difference_scale_controls(&mut self, ui: &mut egui::Ui) {
        let mut fixed = self.view.difference_limit.is_some();
        let toggle = ui.checkbox(&mut fixed, "fixed scale").on_hover_text(
            "Keep the difference's colour scale at one distance (in % of the cage diagonal) \
             across poses and views; pmvc edit --difference-limit sets it for a run",
        );
        if toggle.changed() {
            self.view.difference_limit = if fixed {
                let [against, shown] = self.view.difference;
                Some(self.colour_limit(
                    Colouring::MethodDistance,
                    Pane::Difference { against, shown },
                ))
            } else {
                None
            };
        }
        if let Some(limit) = self.view.difference_limit {
            let mut percent = limit * 100.0;
            ui.add(
                egui::DragValue::new(&mut percent)
                    .speed(0.01)
                    .range(DIFFERENCE_LIMITS.start() * 100.0..=DIFFERENCE_LIMITS.end() * 100.0)
                    .suffix("%"),
            );
            self.view.difference_limit = Some(percent / 100.0);
        }
    }
}
