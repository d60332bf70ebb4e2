//! What a panel sees, as in Rerun's viewer: read-only views of what it shows,
//! and a queue for the actions it asks for. The panel changes nothing else; the
//! editor runs the queue once the panels have drawn ([`super::actions`]).

use super::actions::Action;
use super::document::Document;
use super::model::Model;

pub struct PanelContext<'a> {
    model: &'a Model,
    actions: &'a mut Vec<Action>,
}

impl<'a> PanelContext<'a> {
    /// A context showing `model`, whose actions go to `actions`.
    pub fn new(model: &'a Model, actions: &'a mut Vec<Action>) -> Self {
        Self { model, actions }
    }

    /// The document, to read.
    pub fn document(&self) -> &Document {
        self.model.document()
    }

    /// The pose differs from the rest pose and from the last one saved or loaded.
    pub fn pose_unsaved(&self) -> bool {
        self.model.pose_unsaved()
    }

    /// Ask for `action`; it runs after this frame's panels.
    pub fn send(&mut self, action: Action) {
        self.actions.push(action);
    }
}
