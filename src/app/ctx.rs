//! What a panel sees, as in Rerun's viewer: read-only views of what it shows,
//! and a queue for the actions it asks for. The panel changes nothing else; the
//! editor runs the queue once the panels have drawn (`editor/runner.rs`).

use super::actions::Action;
use super::bind_queue::JobStatus;
use super::compare::ViewSettings;
use super::document::Document;
use super::model::Model;
use super::recent::RecentEntry;
use crate::coords::{BindOptions, Method};

/// What the panels show besides the document, gathered by the editor each frame.
#[derive(Clone, Debug, Default)]
pub struct Shown {
    /// The method a single view shows and its parameters.
    pub bind_options: BindOptions,
    /// Each family's parameter value, as it binds (harmonic coordinates and
    /// BBW each have a grid of their own).
    pub family_parameters: Vec<(Method, u32)>,
    pub view: ViewSettings,
    pub highlight_outside: bool,
    /// The running bind, for the progress bar.
    pub bind_status: Option<JobStatus>,
    /// The families the views need, the active one first.
    pub wanted: Vec<Method>,
    /// Show no timings, so frames are deterministic (snapshot tests).
    pub hide_timings: bool,
    /// File > Recent, most recent first.
    pub recent: Vec<RecentEntry>,
    /// File dialogs are pmvc's own, not the system's.
    pub in_window_dialog: bool,
    /// The viewport draws with more than one sample per pixel; `None` without
    /// a renderer.
    pub antialiased: Option<bool>,
    /// Why smooth shading cannot be shown, if it cannot.
    pub smooth_shading_refusal: Option<String>,
    pub statistics_shown: bool,
}

pub struct PanelContext<'a> {
    model: &'a Model,
    shown: &'a Shown,
    actions: &'a mut Vec<Action>,
}

impl<'a> PanelContext<'a> {
    /// A context showing `model` and `shown`, whose actions go to `actions`.
    pub fn new(model: &'a Model, shown: &'a Shown, actions: &'a mut Vec<Action>) -> Self {
        Self {
            model,
            shown,
            actions,
        }
    }

    /// The document, to read.
    pub fn document(&self) -> &Document {
        self.model.document()
    }

    /// The model, to read (the gesture under way, the undo labels).
    pub fn model(&self) -> &Model {
        self.model
    }

    /// The pose differs from the rest pose and from the last one saved or loaded.
    pub fn pose_unsaved(&self) -> bool {
        self.model.pose_unsaved()
    }

    /// What the panels show besides the document.
    pub fn shown(&self) -> &Shown {
        self.shown
    }

    /// Ask for `action`; it runs after this frame's panels.
    pub fn send(&mut self, action: Action) {
        self.actions.push(action);
    }
}
