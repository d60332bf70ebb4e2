//! The menu bar: File, Edit, View and Scenes.

use crate::app::actions::Action;
use crate::app::compare::HANDLE_SIZES;
use crate::app::editor::EditorApp;
use crate::app::scenes::BundledScene;
use crate::app::ui::file_dialog::FileAction;
use crate::render::viewport::MSAA_SAMPLES;

impl EditorApp {
    pub(in crate::app) fn menu_bar(&mut self, ui: &mut egui::Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| self.file_menu(ui));
            ui.menu_button("Edit", |ui| self.edit_menu(ui));
            ui.menu_button("View", |ui| self.view_menu(ui));
            ui.menu_button("Scenes", |ui| {
                for bundled in BundledScene::ALL {
                    if ui.button(bundled.title()).clicked() {
                        self.open_bundled(bundled);
                    }
                }
            });
        });
    }

    fn file_menu(&mut self, ui: &mut egui::Ui) {
        if ui.button("Open mesh…").clicked() {
            self.ask_for_file(FileAction::OpenMesh);
        }
        if ui.button("Open cage…").clicked() {
            self.ask_for_file(FileAction::OpenCage);
        }
        if ui
            .button("Generate cage…")
            .on_hover_text("A cage of about a chosen number of vertices around the mesh, shown before it replaces the current one")
            .clicked()
        {
            self.open_cage_generation();
        }
        ui.menu_button("Recent", |ui| {
            if self.recent.entries().is_empty() {
                ui.label("(none)");
            }
            for entry in self.recent.entries().to_vec() {
                if ui
                    .button(entry.label())
                    .on_hover_text(entry.paths())
                    .clicked()
                {
                    self.open_recent(&entry);
                }
            }
        });
        ui.separator();
        if ui.button("Open session… (Ctrl+O)").clicked() {
            self.ask_for_file(FileAction::OpenSession);
        }
        if ui.button("Save session (Ctrl+S)").clicked() {
            self.save_session_again();
        }
        if ui.button("Save session as… (Ctrl+Shift+S)").clicked() {
            self.ask_for_file(FileAction::SaveSession);
        }
        ui.separator();
        if ui.button("Load pose…").clicked() {
            self.ask_for_file(FileAction::LoadPose);
        }
        if ui.button("Save pose…").clicked() {
            self.ask_for_file(FileAction::SavePose);
        }
        if ui.button("Export deformed mesh…").clicked() {
            self.ask_for_file(FileAction::ExportMesh);
        }
        if ui
            .button("Export coloured mesh (PLY)…")
            .on_hover_text(
                "The deformed mesh with each vertex in the colour the view gives it \
                 (heatmap, negativity or difference); the header names the scale and range.",
            )
            .clicked()
        {
            self.ask_for_file(FileAction::ExportColouredMesh);
        }
        if ui
            .button("Save image…")
            .on_hover_text("The views as drawn, with their titles and colour bars, as PNG.")
            .clicked()
        {
            self.ask_for_file(FileAction::SaveImage);
        }
        ui.separator();
        ui.checkbox(&mut self.file_dialogs.in_window, "In-window file dialog")
            .on_hover_text(
                "Use pmvc's own file dialog instead of the system's. It is chosen by itself \
                 where the system's cannot appear (no desktop portal).",
            );
        ui.separator();
        if ui.button("Quit (Ctrl+Q)").clicked() {
            self.actions.push(Action::Quit);
        }
    }

    fn edit_menu(&mut self, ui: &mut egui::Ui) {
        let (undo, redo) = (self.undo_label(), self.redo_label());
        let undo_text = match &undo {
            Some(action) => format!("Undo {action} (Ctrl+Z)"),
            None => "Undo (Ctrl+Z)".into(),
        };
        if ui
            .add_enabled(undo.is_some(), egui::Button::new(undo_text))
            .clicked()
        {
            self.undo();
        }
        let redo_text = match &redo {
            Some(action) => format!("Redo {action} (Ctrl+Shift+Z)"),
            None => "Redo (Ctrl+Shift+Z)".into(),
        };
        if ui
            .add_enabled(redo.is_some(), egui::Button::new(redo_text))
            .clicked()
        {
            self.redo();
        }
        if ui.button("Reset pose").clicked() {
            self.reset_pose();
        }
        if ui.button("Use pose as rest shape (rebind)").clicked() {
            self.pose_as_rest();
        }
    }

    fn view_menu(&mut self, ui: &mut egui::Ui) {
        let mut statistics = self.statistics.is_shown();
        if ui.checkbox(&mut statistics, "Statistics").changed() {
            self.statistics.set_shown(statistics);
        }
        ui.checkbox(
            &mut self.view.hover_in_shaded,
            "Weights under the cursor (always)",
        );
        ui.checkbox(&mut self.highlight_outside, "Highlight outside vertices");
        let mut antialiased = self
            .with_renderer(|renderer, _, _| renderer.sample_count() > 1)
            .unwrap_or(false);
        if ui
            .checkbox(&mut antialiased, "Anti-aliasing (4x MSAA)")
            .changed()
        {
            let samples = if antialiased { MSAA_SAMPLES } else { 1 };
            self.with_renderer(|renderer, device, _| renderer.set_sample_count(device, samples));
        }
        if ui.button("Frame selection (F)").clicked() {
            self.frame_selection();
        }
        if ui.button("Frame all (Home)").clicked() {
            self.frame_scene();
        }
        ui.separator();
        ui.checkbox(&mut self.view.show_cage, "Cage and handles (H)")
            .on_hover_text("Hidden handles cannot be picked or box-selected");
        match self.smooth_shading_refusal() {
            None => {
                ui.checkbox(&mut self.view.smooth_shading, "Smooth shading")
                    .on_hover_text(
                        "Light the mesh with each vertex's normal of the deformed mesh, \
                         recomputed on the GPU when the pose changes; off: one normal per face \
                         (faceted)",
                    );
            }
            Some(reason) => {
                ui.add_enabled(
                    false,
                    egui::Checkbox::new(&mut false, "Smooth shading (unavailable)"),
                )
                .on_disabled_hover_text(reason);
            }
        }
        ui.checkbox(&mut self.view.wireframe, "Wireframe")
            .on_hover_text("The mesh's edges over its surface, deformed with it");
        let label = ui.label("Handle size");
        ui.add(
            egui::Slider::new(&mut self.view.handle_size, HANDLE_SIZES)
                .suffix(" pt")
                .step_by(0.5),
        )
        .labelled_by(label.id);
    }
}
