//! Binding control: the bind queue, the options the families are bound with,
//! and which methods to bind and when (what happens when a bind ends is the
//! editor's, `editor/runner.rs`, since it changes the model). Families are bound on demand: the one shown first, then each that a
//! view asks for, so adding a family costs nothing until someone looks at it.

use super::bind_queue::BindQueue;
use super::compare::ViewSettings;
use super::document::Document;
use crate::coords::{BindOptions, Method, Parameter, QuadSplit, QuadSupport};

/// `options` with the parameters `pmvc edit` was given put over them, each
/// checked by its spec; a refused value leaves the option as it was and is
/// returned as a message.
pub(super) fn with_asked_parameters(
    options: &mut crate::coords::BindOptions,
    asked: &super::options::EditorOptions,
) -> Vec<String> {
    let mut refused = Vec::new();
    if let Some(split) = asked.triangulate {
        options.quads = split;
    }
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

/// The methods `view` needs when `active` is shown, the active one first.
pub fn wanted_methods(active: Method, view: &ViewSettings) -> Vec<Method> {
    let mut wanted = vec![active];
    let panes = view.panes(active, crate::render::MAX_VIEWS);
    // The side-by-side methods are wanted in every layout, so switching to
    // the comparison is instant.
    let compared = view.compared.iter();
    for method in panes.iter().flat_map(|p| p.methods()).chain(compared) {
        if !wanted.contains(&method) {
            wanted.push(method);
        }
    }
    wanted
}

/// The bind queue and what it binds with.
pub struct Binding {
    pub queue: BindQueue,
    /// The method a single view shows (`options.method`) and every family's parameters.
    pub options: BindOptions,
    /// After a cancel, views stop asking for binds until the user binds again.
    pub paused: bool,
}

impl Binding {
    pub fn new(queue: BindQueue, options: BindOptions) -> Self {
        Self {
            queue,
            options,
            paused: false,
        }
    }

    /// The method a single view shows.
    pub fn active_method(&self) -> Method {
        self.options.method
    }

    /// The options `method` is bound with: its family's current parameters, and
    /// the quads as the setting says. A family that takes only triangles (none
    /// today: Green on quads is QGC) is bound on the cage's own triangles,
    /// split along the shorter diagonal, whatever the setting.
    pub fn options_for(&self, method: Method) -> BindOptions {
        let quads = match method.spec().quads {
            QuadSupport::Patches { .. } => self.options.quads,
            QuadSupport::Triangles => QuadSplit::None,
        };
        BindOptions {
            method,
            quads,
            ..self.options
        }
    }

    /// Bind the cage's quads as bilinear patches or split along a diagonal;
    /// every family that takes patches is bound again. False when already so.
    pub fn set_quad_split(&mut self, split: QuadSplit) -> bool {
        if self.options.quads == split {
            return false;
        }
        self.options.quads = split;
        for method in Method::ALL {
            if matches!(method.spec().quads, QuadSupport::Patches { .. }) {
                self.queue.drop_method(method);
            }
        }
        self.paused = false;
        true
    }

    /// Bind the methods `view` shows, the active one first, replacing any
    /// running bind. Existing weights stay in use until new ones arrive.
    pub fn start(&mut self, view: &ViewSettings) {
        self.paused = false;
        self.queue.cancel();
        self.queue.launch_next();
        for method in wanted_methods(self.active_method(), view) {
            self.queue.request(self.options_for(method));
        }
        for options in self.wanted_twins(view) {
            self.queue.request(options);
        }
    }

    /// The triangulated twins the views compare with, as bind options.
    fn wanted_twins(&self, view: &ViewSettings) -> Vec<BindOptions> {
        let panes = view.panes(self.active_method(), crate::render::MAX_VIEWS);
        panes
            .iter()
            .filter_map(|pane| match pane {
                super::compare::Pane::Difference { against, .. } => {
                    against.twin?.options(self.options_for(against.method))
                }
                super::compare::Pane::Method(_) => None,
            })
            .collect()
    }

    /// Queue binds for the wanted methods that have no weights at the current
    /// parameters and none on the way (called once per frame).
    pub fn request_wanted(&mut self, document: &Document, view: &ViewSettings) {
        if self.paused {
            return;
        }
        for method in wanted_methods(self.active_method(), view) {
            let options = self.options_for(method);
            let current = document
                .bound(method)
                .is_some_and(|set| set.options.same_weights_as(&options));
            if !current {
                self.queue.request(options);
            }
        }
        for options in self.wanted_twins(view) {
            let id = crate::coords::WeightsId::of_bind(&options, &self.options_for(options.method));
            let current = document
                .bound_id(id)
                .is_some_and(|set| set.options.same_weights_as(&options));
            if !current {
                self.queue.request(options);
            }
        }
    }

    /// Show `method`; false when it is already shown.
    pub fn set_active_method(&mut self, method: Method) -> bool {
        if method == self.options.method {
            return false;
        }
        self.options.method = method;
        true
    }

    /// Set a family parameter (PMVC's resolution, …) checked by its spec; the
    /// families that read it are bound again, the others keep their weights.
    /// False when it was already set.
    pub fn set_parameter(&mut self, parameter: Parameter, value: u32) -> Result<bool, String> {
        let value = parameter
            .validate(value.into())
            .map_err(|error| error.to_string())?;
        if self.options.get(parameter) == value {
            return Ok(false);
        }
        self.options.set(parameter, value);
        for method in Method::ALL {
            if method.spec().parameter.is_some_and(|p| p.key == parameter) {
                self.queue.drop_method(method);
            }
        }
        self.paused = false;
        Ok(true)
    }

    /// Cancel the running bind and those queued after it. The controls go back to
    /// the parameters of the weights in use, and views stop asking for binds until
    /// the user binds again.
    pub fn cancel(&mut self, document: &Document) {
        self.queue.cancel();
        self.paused = true;
        self.sync_parameters_with_weights(document);
    }

    /// Make the parameter controls show what the weights in use were bound with.
    pub fn sync_parameters_with_weights(&mut self, document: &Document) {
        if let Some(set) = document.bound(self.active_method()) {
            if let Some((spec, value)) = set.options.parameter() {
                self.options.set(spec.key, value);
            }
        }
    }
}
