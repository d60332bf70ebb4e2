//! The one runner of actions: what the panels and shortcuts queued, carried
//! out in order after they have drawn. Actions do the I/O (`files.rs` reads and
//! writes, returning values) and change the model through commands; this is
//! also where a finished bind's weights go to the model.

use super::{EditorApp, Waiting};
use crate::app::actions::{Action, BlendStep, CageRequest, FileAction};
use crate::app::bind_queue::{Finished, JobError};
use crate::app::commands::{Command, GestureKind, Selection};
use crate::app::document::WeightSet;
use crate::app::files;
use crate::app::model::Outcome;
use crate::app::ui::named_poses::blend_poses;
use crate::render::Colouring;
use std::sync::Arc;

impl EditorApp {
    /// Run the actions the panels and shortcuts queued, in order.
    pub(super) fn run_actions(&mut self, ctx: &egui::Context) {
        let mut ran = false;
        // An action may queue more: run until none is left.
        while !self.actions.is_empty() {
            for action in std::mem::take(&mut self.actions) {
                self.run_action(ctx, action);
                ran = true;
            }
        }
        if ran {
            // What the actions changed shows in the next frame, without waiting
            // for input.
            ctx.request_repaint();
        }
    }

    pub(super) fn run_action(&mut self, ctx: &egui::Context, action: Action) {
        match action {
            Action::Quit => {
                if self.panels.unsaved.request_quit(self.model.unsaved()) {
                    ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                } else {
                    self.files.waiting = Some(Waiting::Quit);
                }
            }
            Action::Unsaved(answer) => self.answer_unsaved(answer),
            Action::Recover(path, answer) => self.recover(&path, answer),
            Action::CloseWindow => {
                // Quitting was confirmed: what was autosaved was let go.
                if let Some(recovery) = &mut self.files.recovery {
                    recovery.remove();
                }
                ctx.send_viewport_cmd(egui::ViewportCommand::Close)
            }
            Action::AskForFile(file_action) => self.ask_for_file_now(file_action),
            Action::FileChosen(file_action, path) => self.in_window_answer(file_action, &path),
            Action::FileCancelled(file_action) => self.file_action_cancelled(file_action),
            Action::Open(role, path) => {
                self.open_file_now(role, &path);
            }
            Action::OpenObject { role, object } => {
                self.reopen_object_now(role, object.as_deref());
            }
            Action::OpenPair { mesh, cage } => {
                self.open_pair_now(&mesh, &cage, files::ObjectNames::default());
            }
            Action::OpenRecent(entry) => {
                self.open_recent_now(&entry);
            }
            Action::OpenSession(path) => {
                self.open_session_now(&path);
            }
            Action::OpenBundled(bundled) => {
                self.change_scene(files::open_bundled(bundled));
            }
            Action::TakePose { path, pose } => {
                let checked = files::check_pose(&path, pose, self.model.document());
                self.take_pose(&path, checked);
            }
            Action::SaveSessionAgain => match self.files.session_path.clone() {
                Some(path) => {
                    self.save_session_now(&path);
                }
                None => self.ask_for_file_now(FileAction::SaveSession),
            },
            Action::Error(text) => self.error(text),
            Action::Info(text) => self.info(text),
            Action::DismissNotice(index) => self.panels.notices.dismiss(index),
            Action::Apply(command) => {
                // A preview after its gesture ended is dropped quietly; any
                // other refusal is the user's to read (a key time in use).
                let quiet = matches!(command, Command::PreviewGesture(_));
                if let Outcome::Refused(why) = self.apply(command).outcome {
                    if !quiet {
                        self.error(why);
                    }
                }
            }
            Action::Undo => self.undo_step(),
            Action::Redo => self.redo_step(),
            Action::ResetPose => {
                let rest = self.model.document().cage().positions().to_vec();
                self.apply(Command::edit_pose(rest));
            }
            Action::PoseAsRest => {
                let method = self.binding.active_method();
                self.change_scene(files::pose_as_rest(self.model.document(), method));
            }
            Action::SubdivideCage => {
                self.change_scene(files::subdivide_cage(self.model.document()));
            }
            Action::SetHandlePosition(handle, position) => {
                let mut pose = self.model.document().pose().to_vec();
                if let Some(moved) = pose.get_mut(handle) {
                    *moved = position;
                    self.apply(Command::edit_pose(pose));
                }
            }
            Action::Blend(step) => self.blend(step),
            Action::StoreNamedPose(name) => self.store_pose_as(&name),
            Action::ApplyNamedPose(index) => {
                if let Some(named) = self.model.document().named_poses().get(index) {
                    let pose = named.positions.clone();
                    self.apply(Command::edit_pose(pose));
                }
            }
            Action::RenameNamedPose { index, name } => self.rename_named_pose(index, &name),
            Action::SetView(view) => self.views.settings = view,
            Action::SetMethod(method) => self.set_method(method),
            Action::NextMethod => self.set_method(self.binding.active_method().next()),
            Action::SetParameter(parameter, value) => {
                match self.binding.set_parameter(parameter, value) {
                    Ok(true) => self.request_wanted_binds(),
                    Ok(false) => {}
                    Err(error) => self.error(error),
                }
            }
            Action::SetFamilyParameter(family, value) => {
                match self.binding.set_family_parameter(family, value) {
                    Ok(true) => self.request_wanted_binds(),
                    Ok(false) => {}
                    Err(error) => self.error(error),
                }
            }
            Action::SetDeformParameter(parameter, value) => {
                self.apply(Command::SetDeformParameter { parameter, value });
            }
            Action::SetQuadSplit(split) => {
                if self.binding.set_quad_split(split) {
                    self.request_wanted_binds();
                }
            }
            Action::StartBind => self.bind_wanted(),
            Action::CancelBind => self.binding.cancel(self.model.document()),
            Action::SetHighlightOutside(on) => self.views.highlight_outside = on,
            Action::SetSampleCount(samples) => {
                self.with_renderer(|renderer, device, _| {
                    renderer.set_sample_count(device, samples)
                });
            }
            Action::SetCamerasLocked(locked) => self.lock_cameras(locked),
            Action::FixDifferenceScale(fixed) => self.fix_difference_scale(fixed),
            Action::FrameSelection => self.frame_selection_now(),
            Action::FrameAll => self.frame_scene_now(),
            Action::ToggleCage => {
                self.views.settings.show_cage = !self.views.settings.show_cage;
            }
            Action::ToggleSoftSelection => {
                let tools = &mut self.panels.pose_tools.tools;
                tools.soft_selection = !tools.soft_selection;
            }
            Action::ShowStatistics(shown) => self.panels.statistics.set_shown(shown),
            Action::SetInWindowDialog(in_window) => self.panels.file_dialogs.in_window = in_window,
            Action::CageWindow(request) => self.cage_window(request),
            Action::HideFirstRunLine => self.panels.first_run_hint = false,
            Action::ShowShortcuts => self.panels.shortcuts_help.open = true,
            Action::SelectAll => {
                let handles = self.model.document().pose().len();
                self.apply(Command::Select(Selection::only(0..handles)));
            }
            Action::InvertSelection => {
                let document = self.model.document();
                let selected = document.selection();
                let others: Vec<usize> = (0..document.pose().len())
                    .filter(|i| !selected.contains(i))
                    .collect();
                self.apply(Command::Select(Selection::only(others)));
            }
            Action::ToggleOrthographic => self.views.viewport.toggle_orthographic(),
            Action::ViewFrom(side) => {
                let (yaw, pitch) = side.yaw_pitch();
                self.views.viewport.look_from(yaw, pitch);
            }
        }
    }

    /// Queue binds for the wanted methods that have none at the current
    /// parameters (each frame, and when a parameter changes).
    pub(super) fn request_wanted_binds(&mut self) {
        self.binding
            .request_wanted(self.model.document(), &self.views.settings);
    }

    /// Show `method`: instant from weights already bound; otherwise its bind is
    /// queued first.
    pub(super) fn set_method(&mut self, method: crate::coords::Method) {
        if self.binding.set_active_method(method) {
            self.views.viewport.hover_readout = None;
            self.request_wanted_binds();
        }
    }

    /// Keep the difference's colour scale at the distance shown now, or let it
    /// follow the largest distance again.
    fn fix_difference_scale(&mut self, fixed: bool) {
        self.views.settings.difference_limit = if fixed {
            let pane = self.views.settings.difference_pane_kind();
            let wanted = self.wanted_methods_now();
            Some(self.views.colour_limit(
                self.model.document(),
                &wanted,
                Colouring::MethodDistance,
                pane,
            ))
        } else {
            None
        };
    }

    // ---- binds --------------------------------------------------------------------

    /// Take the binds that finished since the last frame.
    pub(super) fn poll_bind(&mut self) {
        while let Some(finished) = self.binding.queue.poll() {
            self.finish_bind(finished);
        }
    }

    /// A bind ended: its weights go to the model, or its failure is said.
    pub(super) fn finish_bind(&mut self, finished: Finished) {
        let Finished {
            options,
            result,
            on_gpu,
        } = finished;
        let outcome = match result {
            Ok(outcome) => outcome,
            Err(JobError::Cancelled) => {
                self.binding.paused = true;
                self.binding
                    .sync_parameters_with_weights(self.model.document());
                self.info("binding cancelled; the previous weights (if any) stay in use");
                return;
            }
            Err(error) => {
                if on_gpu {
                    // The CPU path always works; use it from now on. Not an error of
                    // the run: the weights still come, from the CPU.
                    self.binding.queue.fall_back_to_cpu();
                    self.info(format!("{error}; retrying the bind on the CPU"));
                    self.binding.queue.request_first(options);
                } else {
                    self.error(error.to_string());
                    // Views must not ask again for a bind that fails on the CPU.
                    self.binding.paused = true;
                    self.binding.queue.launch_next();
                }
                return;
            }
        };
        let method = options.method;
        if self.run.screenshot.is_some() {
            // A scripted run's record of the bind, for benchmarks.
            eprintln!(
                "pmvc editor: bound {} vertices × {} columns ({}, {}) in {:.2} s",
                outcome.weights.rows,
                outcome.weights.cols,
                options.family_name(self.model.document().cage()),
                outcome.device,
                outcome.elapsed.as_secs_f64()
            );
        }
        if let Some(notice) = options.quad_notice(self.model.document().cage()) {
            if !matches!(
                options.method.spec().quads,
                crate::coords::QuadSupport::Patches { .. }
            ) {
                self.info(notice.trim_start_matches("notice: ").to_owned());
            }
        }
        let weights = Arc::clone(&outcome.weights);
        let set = WeightSet {
            weights: outcome.weights,
            options,
            bind_time: outcome.elapsed,
            device: outcome.device,
            quality: outcome.quality,
        };
        // A bind with other options than the setting's is a twin.
        let id = crate::coords::WeightsId::of_bind(&options, &self.binding.options_for(method));
        let installed = self.apply(Command::InstallWeights {
            id,
            set,
            outside: outcome.outside,
        });
        // The upload that follows (`sync_gpu`) uses the bind's copy on the device.
        if let (true, Some(gpu), Some(buffer)) =
            (installed.changed(), self.gpu.as_mut(), outcome.resident)
        {
            gpu.resident_weights = Some((weights, buffer));
        }
        self.views.viewport.hover_readout = None;
    }

    // ---- poses --------------------------------------------------------------------

    /// A step of the blend slider's gesture.
    fn blend(&mut self, step: BlendStep) {
        match step {
            BlendStep::Begin => {
                self.apply(Command::BeginGesture(GestureKind::Blend));
            }
            BlendStep::Preview(amount) => {
                if self.model.gesture_under_way() == Some(GestureKind::Blend) {
                    self.preview_blend(amount);
                } else {
                    self.blend(BlendStep::Set(amount));
                }
            }
            BlendStep::End => {
                if self.model.gesture_under_way() == Some(GestureKind::Blend) {
                    self.end_blend();
                }
            }
            BlendStep::Set(amount) => {
                self.apply(Command::BeginGesture(GestureKind::Blend));
                self.preview_blend(amount);
                self.end_blend();
            }
        }
    }

    fn preview_blend(&mut self, amount: f64) {
        let document = self.model.document();
        let (amount, target) = self.panels.named_poses.blend_target(document, amount);
        let pose = blend_poses(document.cage().positions(), &target, amount);
        self.apply(Command::PreviewGesture(pose));
        let revision = self.model.document().pose_revision();
        self.panels.named_poses.blended(amount, target, revision);
    }

    /// The blend gesture ends as one undo step named by the blend reached.
    fn end_blend(&mut self) {
        let percent = (self.panels.named_poses.amount() * 100.0).round();
        self.apply(Command::EndGesture {
            action: format!("blend the pose to {percent}%"),
        });
    }

    fn store_pose_as(&mut self, name: &str) {
        let name = name.trim();
        if name.is_empty() {
            self.error("a stored pose needs a name");
            return;
        }
        self.apply(Command::StoreNamedPose(name.to_owned()));
        self.info(format!("stored the pose as \"{name}\""));
    }

    fn rename_named_pose(&mut self, index: usize, name: &str) {
        let name = name.trim().to_owned();
        if name.is_empty() {
            self.error("a stored pose needs a name");
            return;
        }
        let command = Command::RenameNamedPose {
            index,
            name: name.clone(),
        };
        if let Outcome::Refused(_) = self.apply(command).outcome {
            self.error(format!("there is already a pose called \"{name}\""));
        } else {
            self.panels.named_poses.renamed();
        }
    }

    fn cage_window(&mut self, request: CageRequest) {
        let window = &mut self.panels.cage_window;
        match request {
            CageRequest::Open => {
                window.open_window(self.model.document().cage().vertex_count());
            }
            CageRequest::Close => window.close_window(),
            CageRequest::Generate => window.start(Arc::clone(self.model.document().mesh())),
            CageRequest::Cancel => window.cancel(),
            CageRequest::Use => {
                self.use_generated_cage_now();
            }
        }
    }

    /// Replace the document's cage by the proposal, as one undo step, and bind.
    /// False when there is no proposal.
    pub(super) fn use_generated_cage_now(&mut self) -> bool {
        let Some(proposal) = self.panels.cage_window.take_proposal() else {
            return false;
        };
        let change = files::use_generated_cage(self.model.document(), proposal);
        self.change_scene(Ok(change));
        self.panels.cage_window.open = false;
        true
    }
}
