//! The frame loop: what the editor does each frame, in order, and what it keeps
//! across runs (the recent files). A frame runs input → actions and commands →
//! model → GPU copy → pixels: shortcuts and panels queue actions, the runner
//! carries them out (after the shortcuts, after the panels, and after the
//! windows drawn over them), and the viewport's gestures apply their commands
//! as the pointer moves.

use super::EditorApp;
use crate::app::actions::Action;
use crate::app::binding;
use crate::app::ctx::{PanelContext, Shown};
use crate::app::files;
use crate::app::model::Model;
use crate::app::shortcuts::{pressed, Scope, Shortcut};
use crate::app::ui::{generate_cage, menu, side_panel, toolbar};
use crate::app::views::{ViewportContext, ViewportFacts, Views};
use crate::coords::Method;

impl eframe::App for EditorApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.run.clock = ctx.input(|i| i.time);
        let panels = &mut self.panels;
        panels
            .statistics
            .frames_mut()
            .record_frame(ctx.input(|i| i.time));
        let (scripted, model) = (self.run.screenshot.is_some(), &self.model);
        if panels
            .unsaved
            .intercept_close(&ctx, scripted, || model.unsaved())
        {
            self.files.waiting = Some(super::Waiting::Quit);
        }
        self.run.focus.ask(&ctx, frame);
        self.poll_bind();
        let mesh = std::sync::Arc::clone(self.model.document().mesh());
        self.panels.cage_window.poll(&mesh);
        self.run_shortcuts(&ctx);

        // What the panels show, gathered once a frame: the actions they queue
        // run after them, and what changes shows in the next frame.
        let shown = self.shown();
        with_context(&self.model, &shown, &mut self.actions, |cx| {
            self.panels.drop.take_dropped_files(&ctx, cx);
        });
        let (model, actions, panels) = (&self.model, &mut self.actions, &mut self.panels);
        egui::Panel::top("menu").show(ui, |ui| {
            with_context(model, &shown, actions, |cx| menu::menu_bar(ui, cx));
        });
        egui::Panel::top("toolbar").show(ui, |ui| {
            with_context(model, &shown, actions, |cx| toolbar::toolbar(ui, cx));
        });
        if panels.first_run_hint {
            egui::Panel::top("first run").show(ui, |ui| {
                with_context(model, &shown, actions, |cx| toolbar::first_run_line(ui, cx));
            });
        }
        egui::Panel::right("side")
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    let sections = side_panel::Sections {
                        pose_tools: &mut panels.pose_tools,
                        named_poses: &mut panels.named_poses,
                        timeline: &mut panels.timeline,
                        statistics: &panels.statistics,
                        notices: &panels.notices,
                    };
                    with_context(model, &shown, actions, |cx| {
                        side_panel::side_panel(ui, cx, sections)
                    });
                })
            });
        let viewport = egui::CentralPanel::no_frame()
            .show(ui, |ui| self.viewport(ui))
            .response
            .rect;
        with_context(&self.model, &shown, &mut self.actions, |cx| {
            self.panels.drop.ui(&ctx, cx);
            self.panels.unsaved.ui(&ctx, cx);
            self.panels.recovery.ui(&ctx, cx);
            (self.panels.notices).toasts(&ctx, viewport, shown.hide_timings, cx);
        });
        // After the panels that send actions; before the file dialog, so the
        // question's Save pose… opens it in this frame.
        self.run_actions(&ctx);
        with_context(&self.model, &shown, &mut self.actions, |cx| {
            self.panels.file_dialogs.window(&ctx, cx);
            generate_cage::window(&mut self.panels.cage_window, &ctx, cx);
        });
        self.panels.shortcuts_help.window(&ctx);
        self.run_actions(&ctx);
        self.request_wanted_binds();
        if self.panels.statistics.is_shown() {
            // Keep frames coming so the readout measures rendering, not idling.
            ctx.request_repaint();
        }
        if let Some(screenshot) = &mut self.run.screenshot {
            let binding = self.binding.queue.is_busy();
            let session = self.files.session_path.as_deref();
            let inputs = files::open_inputs(self.model.document(), session);
            let inputs = inputs
                .into_iter()
                .map(std::path::Path::to_path_buf)
                .collect();
            screenshot.drive(&ctx, binding, inputs, self.panels.statistics.frames_mut());
        }
        self.autosave_when_due(&ctx);
        let panes = self.views.viewport.pane_rects().into_iter().map(|(_, r)| r);
        if let Some(report) = self.files.image_request.drive(&ctx, panes) {
            self.report(report);
        }
    }

    /// A scripted run's pointer events (`--drag`) join the frame's input here.
    fn raw_input_hook(&mut self, _ctx: &egui::Context, raw_input: &mut egui::RawInput) {
        let Some(screenshot) = &mut self.run.screenshot else {
            return;
        };
        let frame = screenshot.frames_after_bind();
        let Some(drag) = &mut screenshot.drag else {
            return;
        };
        let scene = crate::app::scripted_drag::DragScene {
            document: self.model.document(),
            views: &mut self.views,
            binding: self.binding.queue.is_busy(),
            frames: self.panels.statistics.frames_mut(),
        };
        if let Some(error) = drag.script_input(frame, raw_input, scene) {
            self.error(error);
        }
    }

    /// A clean exit lets the autosave go when nothing is unsaved (quitting
    /// without saving removed it already).
    fn on_exit(&mut self) {
        if !self.model.unsaved().any() {
            if let Some(recovery) = &mut self.files.recovery {
                recovery.remove();
            }
        }
    }

    /// Recent files outlive the run; a scripted run leaves them as they were.
    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        if self.run.screenshot.is_none() {
            self.files.recent.save(storage);
        }
    }

    /// Only the recent files are kept: panels and windows open as they always
    /// do, so screenshots and snapshot tests start from the same state.
    fn persist_egui_memory(&self) -> bool {
        false
    }
}

impl EditorApp {
    /// The panels' context for this frame, with what they show gathered.
    fn shown(&self) -> Shown {
        Shown {
            bind_options: self.binding.options,
            family_parameters: Method::ALL
                .into_iter()
                .filter_map(|m| Some((m, self.binding.options_for(m).parameter()?.1)))
                .collect(),
            view: self.views.settings,
            highlight_outside: self.views.highlight_outside,
            bind_status: self.binding.queue.status(),
            wanted: self.wanted_methods_now(),
            hide_timings: self.run.hide_timings,
            recent: self.files.recent.entries().to_vec(),
            in_window_dialog: self.panels.file_dialogs.in_window,
            antialiased: self.with_renderer(|renderer, _, _| renderer.sample_count() > 1),
            smooth_shading_refusal: self
                .with_renderer(|renderer, device, _| renderer.smooth_shading_refusal(device))
                .flatten(),
            statistics_shown: self.panels.statistics.is_shown(),
        }
    }

    /// What the panes see: the model, the posing tools and the action queue.
    fn viewport_context(&mut self) -> (&mut Views, ViewportContext<'_>) {
        let facts = ViewportFacts {
            active_method: self.binding.active_method(),
            wanted: binding::wanted_methods(self.binding.active_method(), &self.views.settings),
            binding: self.binding.queue.is_busy(),
            scripted: self.run.screenshot.is_some(),
            hide_timings: self.run.hide_timings,
            proposal: self.panels.cage_window.proposal(),
            has_gpu: self.gpu.is_some(),
        };
        let context = ViewportContext::new(
            &mut self.model,
            &mut self.panels.pose_tools.tools,
            &mut self.actions,
            facts,
        );
        (&mut self.views, context)
    }

    /// The panes: their input (which may change the model), the GPU copy
    /// brought up to date, then their drawing.
    fn viewport(&mut self, ui: &mut egui::Ui) {
        let (views, mut cx) = self.viewport_context();
        let layout = views.input(ui, &mut cx);
        drop(cx);
        self.sync_gpu();
        let (views, mut cx) = self.viewport_context();
        views.draw(ui, &mut cx, layout);
    }

    /// This frame's shortcuts, run at once: a transform begins or steers in
    /// the viewport, everything else is an action.
    fn run_shortcuts(&mut self, ctx: &egui::Context) {
        for shortcut in pressed(ctx, Scope::Always) {
            self.actions.extend(shortcut.action());
        }
        self.run_actions(ctx);
        // A dialog's fields and keys are its own; M or F typed into a path must
        // not switch the method or move the camera.
        let keyboard_taken =
            |app: &Self| ctx.egui_wants_keyboard_input() || app.modal_dialog_open();
        if keyboard_taken(self) {
            return;
        }
        let (views, mut cx) = self.viewport_context();
        if !views.steer_transform(ctx, &mut cx) {
            for shortcut in pressed(ctx, Scope::Viewport) {
                if let Shortcut::BeginTransform(kind) = shortcut {
                    if views.begin_transform_at_pointer(ctx, &mut cx, kind) {
                        break;
                    }
                    continue;
                }
                cx.send_all(shortcut.action());
            }
        }
        drop(cx);
        self.run_actions(ctx);
        if keyboard_taken(self) {
            return;
        }
        if let Some(&shortcut) = pressed(ctx, Scope::Files).first() {
            self.actions.extend(shortcut.action());
        }
        self.run_actions(ctx);
    }
}

/// Run `f` with a panel context over `model`, `shown` and `actions`.
fn with_context<R>(
    model: &Model,
    shown: &Shown,
    actions: &mut Vec<Action>,
    f: impl FnOnce(&mut PanelContext) -> R,
) -> R {
    let mut context = PanelContext::new(model, shown, actions);
    f(&mut context)
}
