//! The viewport panes' own state, and what they see of the rest of the editor.
//!
//! [`Views`] owns what the panes show and keep between frames: the view
//! settings, the cameras and panes (`viewport/`), the CPU read-outs behind the
//! colour bars and the hover box (`readouts.rs`) and the outside highlight. The
//! panes draw and take input through a [`ViewportContext`]: the model, changed
//! only through [`Model::apply`], the posing tools, and the action queue for
//! everything else. The viewport applies its gestures' commands at once, not
//! through the queue, so that a dragged handle, the GPU copy and picking
//! follow the pointer within the same frame.

use super::actions::Action;
use super::cage_generation::Proposal;
use super::commands::Command;
use super::compare::{ValueRange, ViewSettings};
use super::document::Changes;
use super::model::{Applied, Model, Outcome};
use super::pose_tools::PoseToolSettings;
use super::viewport::ViewportState;
use crate::coords::{Method, WeightsId};
use crate::render::Colouring;
use glam::Vec3;
use std::collections::BTreeMap;
use std::sync::Arc;

/// What the viewport shows and keeps.
#[derive(Default)]
pub struct Views {
    /// What the panes compare and how the mesh is coloured.
    pub settings: ViewSettings,
    /// Cameras, panes, the drag and the transform under way, the hover.
    pub viewport: ViewportState,
    pub readouts: ReadoutCache,
    /// Draw the mesh vertices outside the cage in a warning colour.
    pub highlight_outside: bool,
}

impl Views {
    pub fn new(settings: ViewSettings) -> Self {
        Self {
            settings,
            ..Self::default()
        }
    }
}

/// A range is keyed by what it shows and the methods it reads.
type RangeKey = (Colouring, Method, Option<WeightsId>);

/// The read-outs computed so far (`readouts.rs` computes them).
#[derive(Default)]
pub struct ReadoutCache {
    /// The mesh deformed per method, with the pose revision it was made for.
    pub(super) deformed: BTreeMap<WeightsId, (u64, Arc<Vec<Vec3>>)>,
    /// Colour-bar ranges (a row-minimum scan of a large matrix is too slow to
    /// repeat every frame).
    pub(super) ranges: Vec<(RangeKey, Option<ValueRange>)>,
}

impl ReadoutCache {
    pub fn clear(&mut self) {
        self.deformed.clear();
        self.ranges.clear();
    }

    /// Forget what `changes` make stale.
    pub fn invalidate(&mut self, changes: &Changes) {
        if changes.scene {
            self.clear();
            return;
        }
        for method in &changes.weights {
            self.deformed.remove(method);
        }
        let weights_changed = |key: &RangeKey| {
            changes.weights.contains(&WeightsId::of(key.1))
                || key.2.is_some_and(|id| changes.weights.contains(&id))
        };
        // Distances depend on the pose; weights and their ranges do not.
        self.ranges.retain(|(key, _)| {
            let distance_moved = changes.pose && key.0 == Colouring::MethodDistance;
            !(weights_changed(key) || distance_moved)
        });
    }
}

/// What the panes see of the editor while they draw and take input.
pub struct ViewportContext<'a> {
    pub model: &'a mut Model,
    /// Pivot, symmetry, soft selection and the 3D cursor (which a pane places).
    pub pose_tools: &'a mut PoseToolSettings,
    actions: &'a mut Vec<Action>,
    pub facts: ViewportFacts<'a>,
}

/// What the panes read of the rest of the editor this frame.
pub struct ViewportFacts<'a> {
    /// The family a single view shows.
    pub active_method: Method,
    /// The families the views need, the active one first.
    pub wanted: Vec<Method>,
    /// A bind is running or queued.
    pub binding: bool,
    /// A `--screenshot` run, whose pointer rests wherever the display server put it.
    pub scripted: bool,
    /// Show no timings (snapshot tests).
    pub hide_timings: bool,
    /// The Generate cage window's proposal, drawn over the mesh.
    pub proposal: Option<&'a Proposal>,
    /// Whether there is a device to draw with.
    pub has_gpu: bool,
}

impl<'a> ViewportContext<'a> {
    pub fn new(
        model: &'a mut Model,
        pose_tools: &'a mut PoseToolSettings,
        actions: &'a mut Vec<Action>,
        facts: ViewportFacts<'a>,
    ) -> Self {
        Self {
            model,
            pose_tools,
            actions,
            facts,
        }
    }

    /// Change the model; a refused command is logged.
    pub fn apply(&mut self, command: Command) -> Applied {
        let applied = self.model.apply(command);
        if let Outcome::Refused(why) = &applied.outcome {
            log::warn!("refused: {why}");
        }
        applied
    }

    /// Ask for `action`; it runs after this frame's panels.
    pub fn send(&mut self, action: Action) {
        self.actions.push(action);
    }

    /// Ask for each of `actions`.
    pub fn send_all(&mut self, actions: impl IntoIterator<Item = Action>) {
        self.actions.extend(actions);
    }

    /// Tell the user something (a notice).
    pub fn info(&mut self, text: impl Into<String>) {
        self.send(Action::Info(text.into()));
    }
}
