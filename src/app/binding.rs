//! Binding control: which methods to bind and when, and what happens when a
//! bind ends. Families are bound on demand: the one shown first, then each that a
//! view asks for, so adding a family costs nothing until someone looks at it.

use super::bind_queue::{Finished, JobError, JobStatus};
use super::document::WeightSet;
use super::editor::{EditorApp, Replacement};
use super::model::Command;
use crate::coords::{Method, Parameter};
use crate::geometry::subdivide_midpoint;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// `options` with the parameters `pmvc edit` was given put over them, each
/// checked by its spec; a refused value leaves the option as it was and is
/// returned as a message.
pub(super) fn with_asked_parameters(
    options: &mut crate::coords::BindOptions,
    asked: &super::EditorOptions,
) -> Vec<String> {
    let mut refused = Vec::new();
    for (parameter, value) in [
        (Parameter::Resolution, asked.resolution),
        (Parameter::Grid, asked.grid),
    ] {
        if let Some(value) = value {
            match parameter.validate(value.into()) {
                Ok(value) => options.set(parameter, value),
                Err(error) => refused.push(error.to_string()),
            }
        }
    }
    refused
}

impl EditorApp {
    /// Bind the methods the views show, the active one first, replacing any
    /// running bind. Existing weights stay in use until new ones arrive.
    pub fn start_bind(&mut self) {
        self.binding_paused = false;
        self.queue.cancel();
        self.queue.launch_next();
        for method in self.wanted_methods() {
            self.queue.request(self.options_for(method));
        }
    }

    /// The methods the current views need, the active one first.
    pub fn wanted_methods(&self) -> Vec<Method> {
        let mut wanted = vec![self.active_method()];
        let panes = self
            .view
            .panes(self.active_method(), crate::render::MAX_VIEWS);
        // The side-by-side methods are wanted in every layout, so switching to
        // the comparison is instant.
        let compared = self.view.compared.iter();
        for method in panes.iter().flat_map(|p| p.methods()).chain(compared) {
            if !wanted.contains(&method) {
                wanted.push(method);
            }
        }
        wanted
    }

    /// Queue binds for the wanted methods that have no weights at the current
    /// parameters and none on the way (called once per frame).
    pub(super) fn request_wanted_binds(&mut self) {
        if self.binding_paused {
            return;
        }
        for method in self.wanted_methods() {
            let options = self.options_for(method);
            let current = self
                .model
                .document()
                .bound(method)
                .is_some_and(|set| set.options.same_weights_as(&options));
            if !current {
                self.queue.request(options);
            }
        }
    }

    /// A bind is running or queued.
    pub fn is_binding(&self) -> bool {
        self.queue.is_busy()
    }

    /// The running bind, for the progress bar.
    pub fn bind_status(&self) -> Option<JobStatus> {
        self.queue.status()
    }

    /// Bind progress as (done, total), while binding.
    pub fn bind_progress(&self) -> Option<(usize, usize)> {
        self.queue
            .status()
            .map(|status| (status.done, status.total))
    }

    /// The method a single view shows.
    pub fn active_method(&self) -> Method {
        self.bind_options.method
    }

    /// Show `method`: instant from weights already bound; otherwise its bind is
    /// queued first.
    pub fn set_active_method(&mut self, method: Method) {
        if method == self.bind_options.method {
            return;
        }
        self.bind_options.method = method;
        self.viewport.hover_readout = None;
        self.request_wanted_binds();
    }

    /// Show the next family (the M key).
    pub fn toggle_method(&mut self) {
        self.set_active_method(self.active_method().next());
    }

    /// Set a family parameter (PMVC's resolution, …) and rebind the families
    /// that read it; the others keep their weights.
    pub fn set_parameter(&mut self, parameter: Parameter, value: u32) {
        let value = match parameter.validate(value.into()) {
            Ok(value) => value,
            Err(error) => {
                self.error(error.to_string());
                return;
            }
        };
        if self.bind_options.get(parameter) == value {
            return;
        }
        self.bind_options.set(parameter, value);
        for method in Method::ALL {
            if method.spec().parameter.is_some_and(|p| p.key == parameter) {
                self.queue.drop_method(method);
            }
        }
        self.binding_paused = false;
        self.request_wanted_binds();
    }

    /// Rebind PMVC at `resolution` (MVC does not depend on it).
    pub fn set_resolution(&mut self, resolution: u32) {
        self.set_parameter(Parameter::Resolution, resolution);
    }

    /// Cancel the running bind and those queued after it. The controls go back to
    /// the parameters of the weights in use, and views stop asking for binds until
    /// the user binds again.
    pub fn cancel_bind(&mut self) {
        self.queue.cancel();
        self.binding_paused = true;
        self.sync_parameters_with_weights();
    }

    /// Make the parameter controls show what the weights in use were bound with.
    pub(super) fn sync_parameters_with_weights(&mut self) {
        if let Some(set) = self.model.document().bound(self.active_method()) {
            if let Some((spec, value)) = set.options.parameter() {
                self.bind_options.set(spec.key, value);
            }
        }
    }

    /// Wait for the running and queued binds (tests); true if they finished.
    pub fn wait_for_bind(&mut self, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        while self.queue.is_busy() {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.queue.wait(left) {
                Some(finished) => self.finish_bind(finished),
                None if left.is_zero() => return false,
                None => self.queue.launch_next(),
            }
        }
        true
    }

    pub(super) fn poll_bind(&mut self) {
        while let Some(finished) = self.queue.poll() {
            self.finish_bind(finished);
        }
    }

    fn finish_bind(&mut self, finished: Finished) {
        let Finished {
            options,
            result,
            on_gpu,
        } = finished;
        let outcome = match result {
            Ok(outcome) => outcome,
            Err(JobError::Cancelled) => {
                self.binding_paused = true;
                self.sync_parameters_with_weights();
                self.info("binding cancelled; the previous weights (if any) stay in use");
                return;
            }
            Err(error) => {
                if on_gpu {
                    // The CPU path always works; use it from now on. Not an error of
                    // the run: the weights still come, from the CPU.
                    self.queue.fall_back_to_cpu();
                    self.info(format!("{error}; retrying the bind on the CPU"));
                    self.queue.request_first(options);
                } else {
                    self.error(error.to_string());
                    // Views must not ask again for a bind that fails on the CPU.
                    self.binding_paused = true;
                    self.queue.launch_next();
                }
                return;
            }
        };
        let method = options.method;
        if self.screenshot.is_some() {
            // A scripted run's record of the bind, for benchmarks.
            eprintln!(
                "pmvc editor: bound {} vertices × {} columns ({}, {}) in {:.2} s",
                outcome.weights.rows,
                outcome.weights.cols,
                method.name(),
                outcome.device,
                outcome.elapsed.as_secs_f64()
            );
        }
        let weights = Arc::clone(&outcome.weights);
        let set = WeightSet {
            weights: outcome.weights,
            options,
            bind_time: outcome.elapsed,
            device: outcome.device,
            quality: outcome.quality,
        };
        let installed = self.apply(Command::InstallWeights {
            method,
            set,
            outside: outcome.outside,
        });
        // The upload that follows (`sync_gpu`) uses the bind's copy on the device.
        if let (true, Some(gpu), Some(buffer)) =
            (installed.changed(), self.gpu.as_mut(), outcome.resident)
        {
            gpu.resident_weights = Some((weights, buffer));
        }
        self.viewport.hover_readout = None;
    }

    /// Subdivide the cage 1-to-4 at edge midpoints, keeping the current pose
    /// (smoother coordinates near reflex edges, the paper's Figure 4), and rebind.
    pub fn subdivide_cage(&mut self) -> bool {
        let subdivided =
            match subdivide_midpoint(self.model.document().cage(), self.model.document().pose()) {
                Ok(subdivided) => subdivided,
                Err(error) => {
                    self.error(format!("cannot subdivide the cage: {error}"));
                    return false;
                }
            };
        let before = self.model.document().pose().len();
        let after = subdivided.cage.vertex_count();
        let document = self.model.document().with_cage(
            subdivided.cage,
            self.model.document().cage_path().map(Into::into),
            subdivided.pose,
        );
        self.replace_document_then_bind(Replacement::in_place(document, "subdivide the cage"));
        self.info(format!(
            "subdivided the cage: {before} -> {after} vertices; rebinding"
        ));
        true
    }
}
