//! The frame loop: what the editor does each frame, in order, and what it keeps
//! across runs (the recent files).

use super::ctx::PanelContext;
use super::editor::EditorApp;

impl eframe::App for EditorApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.statistics
            .frames_mut()
            .record_frame(ctx.input(|i| i.time));
        let (scripted, unsaved) = (self.screenshot.is_some(), self.model.pose_unsaved());
        self.quit.intercept_close(&ctx, scripted, unsaved);
        self.ask_for_keyboard_focus(&ctx, frame);
        self.poll_bind();
        self.poll_cage_generation();
        let mut context = PanelContext::new(&self.model, &mut self.actions);
        self.drop_dialog.take_dropped_files(&ctx, &mut context);
        self.run_shortcuts(&ctx);
        egui::Panel::top("menu").show(ui, |ui| self.menu_bar(ui));
        egui::Panel::top("toolbar").show(ui, |ui| self.toolbar(ui));
        if self.first_run_hint {
            egui::Panel::top("first run").show(ui, |ui| self.first_run_line(ui));
        }
        egui::Panel::right("side")
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.side_panel(ui))
            });
        egui::CentralPanel::no_frame().show(ui, |ui| self.viewport(ui));
        let mut context = PanelContext::new(&self.model, &mut self.actions);
        self.drop_dialog.ui(&ctx, &mut context);
        self.quit.ui(&ctx, &mut context);
        // After the panels that send actions, in one place; before the file
        // dialog, so the question's Save pose… opens it in this frame.
        self.run_actions(&ctx);
        self.file_dialog_window(&ctx);
        self.generate_cage_window(&ctx);
        self.request_wanted_binds();
        if self.statistics.is_shown() {
            // Keep frames coming so the readout measures rendering, not idling.
            ctx.request_repaint();
        }
        self.drive_screenshot(&ctx);
        self.drive_image_request(&ctx);
    }

    /// A scripted run's pointer events (`--drag`) join the frame's input here.
    fn raw_input_hook(&mut self, _ctx: &egui::Context, raw_input: &mut egui::RawInput) {
        self.script_drag_input(raw_input);
    }

    /// Recent files outlive the run; a scripted run leaves them as they were.
    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        if self.screenshot.is_none() {
            self.recent.save(storage);
        }
    }

    /// Only the recent files are kept: panels and windows open as they always
    /// do, so screenshots and snapshot tests start from the same state.
    fn persist_egui_memory(&self) -> bool {
        false
    }
}
