//! Binding control: the bind queue, the options the families are bound with,
//! and which methods to bind and when (what happens when a bind ends is the
//! editor's, `editor/runner.rs`, since it changes the model). Families are bound on demand: the one shown first, then each that a
//! view asks for, so adding a family costs nothing until someone looks at it.

use super::bind_queue::BindQueue;
use super::compare::ViewSettings;
use super::document::Document;
use crate::coords::{BindOptions, Method, Parameter, QuadSplit, QuadSupport};
use std::collections::BTreeMap;

/// Whether another family has a parameter of the same kind as `method`'s.
fn shares_parameter_kind(method: Method) -> bool {
    let Some(spec) = method.spec().parameter else {
        return false;
    };
    Method::ALL
        .iter()
        .any(|&other| other != method && other.spec().parameter.is_some_and(|p| p.key == spec.key))
}

/// The parameters `pmvc edit` was given put over `binding`'s, each checked by
/// its spec and given to every family that reads it; a refused value leaves the
/// parameter as it was and is returned as a message.
pub(super) fn with_asked_parameters(
    binding: &mut Binding,
    asked: &super::options::EditorOptions,
) -> Vec<String> {
    let mut refused = Vec::new();
    if let Some(split) = asked.triangulate {
        binding.options.quads = split;
    }
    for (parameter, value) in [
        (Parameter::Resolution, asked.resolution),
        (Parameter::Grid, asked.grid),
    ] {
        if let Some(value) = value {
            match parameter.validate(value.into()) {
                Ok(value) => binding.ask_for_every_family(parameter, value),
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
    /// The method a single view shows (`options.method`), its parameter, and
    /// the parameters of the families that share none with it.
    pub options: BindOptions,
    /// The parameter each family not shown was last bound with, where it
    /// shares its kind with another family (harmonic coordinates' and BBW's
    /// grids): each keeps its own value, so BBW does not take harmonic
    /// coordinates' grid of 64. A family not here has its default.
    shared_kind_values: BTreeMap<Method, u32>,
    /// After a cancel, views stop asking for binds until the user binds again.
    pub paused: bool,
}

impl Binding {
    pub fn new(queue: BindQueue, options: BindOptions) -> Self {
        Self {
            queue,
            options,
            shared_kind_values: BTreeMap::new(),
            paused: false,
        }
    }

    /// `pmvc edit --grid N` and the like: the value for every family that
    /// reads `parameter`, shown or not.
    pub fn ask_for_every_family(&mut self, parameter: Parameter, value: u32) {
        self.options.set(parameter, value);
        for method in Method::ALL {
            let reads_it = method.spec().parameter.is_some_and(|p| p.key == parameter);
            if reads_it && shares_parameter_kind(method) {
                self.shared_kind_values.insert(method, value);
            }
        }
    }

    /// Options put in place as a whole (a session, an undo step): the
    /// families not shown take their defaults again.
    pub fn replace_options(&mut self, options: BindOptions) {
        self.options = options;
        self.shared_kind_values.clear();
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
        let mut options = BindOptions {
            method,
            quads,
            ..self.options
        };
        if method != self.options.method && shares_parameter_kind(method) {
            if let Some(spec) = method.spec().parameter {
                let value = self.shared_kind_values.get(&method);
                options.set(spec.key, value.copied().unwrap_or(spec.default));
            }
        }
        options
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
        let shown = self.options.method;
        if shares_parameter_kind(shown) {
            if let Some(spec) = shown.spec().parameter {
                let value = self.options.get(spec.key);
                self.shared_kind_values.insert(shown, value);
            }
        }
        let parameter = self.options_for(method).parameter();
        self.options.method = method;
        if let Some((spec, value)) = parameter {
            self.options.set(spec.key, value);
        }
        true
    }

    /// Set a parameter (PMVC's resolution, …) checked by its spec: the shown
    /// family's where it reads it, else every family's that does. The
    /// families whose value changed are bound again, the others keep their
    /// weights. False when it was already set.
    pub fn set_parameter(&mut self, parameter: Parameter, value: u32) -> Result<bool, String> {
        let value = parameter
            .validate(value.into())
            .map_err(|error| error.to_string())?;
        let shown_reads_it = self
            .options
            .method
            .spec()
            .parameter
            .is_some_and(|p| p.key == parameter);
        let before: Vec<BindOptions> = Method::ALL.map(|m| self.options_for(m)).to_vec();
        if shown_reads_it {
            self.options.set(parameter, value);
        } else {
            self.ask_for_every_family(parameter, value);
        }
        self.drop_changed(&before)
    }

    /// Set `family`'s parameter, checked by its spec, whether it is shown or
    /// not (the side panel's controls); only the families whose value changed
    /// are bound again. False when it was already set.
    pub fn set_family_parameter(&mut self, family: Method, value: u32) -> Result<bool, String> {
        let Some(spec) = family.spec().parameter else {
            return Ok(false);
        };
        if family == self.options.method || !shares_parameter_kind(family) {
            let before: Vec<BindOptions> = Method::ALL.map(|m| self.options_for(m)).to_vec();
            let value = spec.validate(value.into()).map_err(|e| e.to_string())?;
            self.options.set(spec.key, value);
            return self.drop_changed(&before);
        }
        let value = spec.validate(value.into()).map_err(|e| e.to_string())?;
        let before: Vec<BindOptions> = Method::ALL.map(|m| self.options_for(m)).to_vec();
        self.shared_kind_values.insert(family, value);
        self.drop_changed(&before)
    }

    /// Forget the weights of the families whose options differ from `before`
    /// (one per [`Method::ALL`]); whether any did.
    fn drop_changed(&mut self, before: &[BindOptions]) -> Result<bool, String> {
        let mut changed = false;
        for (method, before) in Method::ALL.into_iter().zip(before) {
            if !self.options_for(method).same_weights_as(before) {
                self.queue.drop_method(method);
                changed = true;
            }
        }
        if changed {
            self.paused = false;
        }
        Ok(changed)
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
