//! Picking: the handle under the cursor, box selection, and the mesh vertex under
//! the cursor whose weights the hover box reads out.

use crate::app::commands::{Command, Selection};
use crate::app::compare::{self, HoverReadout};
use crate::app::document::Document;
use crate::app::views::{ViewportContext, Views};
use crate::app::widgets::hover_box;
use egui::{Pos2, Rect};
use glam::Vec2;

/// Handles are picked within this many points of the cursor, or of their rim
/// when they are drawn larger.
const PICK_RADIUS: f32 = 9.0;
const PICK_MARGIN: f32 = 5.0;
/// The hover read-out picks mesh vertices within this many points of the cursor.
const HOVER_RADIUS: f32 = 6.0;

impl Views {
    /// The handle nearest to `pointer` within the pick radius, in the view under it.
    pub(super) fn pick(&self, document: &Document, pointer: Pos2) -> Option<usize> {
        if !self.settings.show_cage {
            return None;
        }
        let radius = PICK_RADIUS.max(self.settings.handle_size + PICK_MARGIN);
        let pane = self.viewport.pane_at(pointer)?;
        let projection = self.viewport.projection(pane)?;
        let pointer = Vec2::new(pointer.x, pointer.y);
        document
            .pose()
            .iter()
            .enumerate()
            .filter_map(|(i, p)| {
                let screen = projection.project_world(*p)?;
                let distance = screen.distance(pointer);
                (distance <= radius).then_some((i, distance))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// Select the handles inside `band` in view `pane` (added to the selection
    /// when `additive`).
    pub(super) fn box_select(
        &mut self,
        cx: &mut ViewportContext,
        pane: usize,
        band: Rect,
        additive: bool,
    ) {
        if !self.settings.show_cage {
            return;
        }
        let Some(projection) = self.viewport.projection(pane) else {
            return;
        };
        let inside: Vec<usize> = cx
            .model
            .document()
            .pose()
            .iter()
            .enumerate()
            .filter(|(_, p)| {
                projection
                    .project_world(**p)
                    .is_some_and(|screen| band.contains(Pos2::new(screen.x, screen.y)))
            })
            .map(|(i, _)| i)
            .collect();
        let selection = if additive {
            Selection::More(inside)
        } else {
            Selection::Only(inside.into_iter().collect())
        };
        cx.apply(Command::Select(selection));
    }

    /// Find the mesh vertex under the cursor and read out its weights.
    pub(super) fn update_hover(
        &mut self,
        ui: &egui::Ui,
        cx: &ViewportContext,
        hovered: Option<(usize, Option<Pos2>)>,
    ) {
        let target = match hovered {
            // Not in `--screenshot` runs, where the pointer rests wherever the
            // display server put it, and not while dragging, so that a drag frame
            // never deforms the mesh on the CPU.
            Some((pane, Some(pointer))) if self.viewport.drag.is_none() && !cx.facts.scripted => {
                Some((pane, pointer))
            }
            _ => None,
        };
        let readout = target.and_then(|(pane, pointer)| {
            let (kind, projection) = self.viewport.pane(pane)?;
            if !self.settings.shows_hover(kind) {
                return None;
            }
            let method = kind.method();
            let document = cx.model.document();
            let positions = self.deformed_on_cpu(document, method)?;
            let vertex = compare::vertex_under_pointer(
                &positions,
                projection.view_projection,
                projection.origin,
                projection.size,
                Vec2::new(pointer.x, pointer.y),
                HOVER_RADIUS,
            )?;
            let cage_vertices = document.cage().vertex_count();
            let weights = document.weights(method)?;
            let readout = HoverReadout::new(weights, method, vertex, cage_vertices)?;
            Some((pane, pointer, readout))
        });
        self.viewport.hover_readout = readout.as_ref().map(|(pane, _, r)| (*pane, r.clone()));
        if let Some((_, pointer, readout)) = readout {
            egui::Area::new(egui::Id::unique("hover weights"))
                .order(egui::Order::Tooltip)
                .fixed_pos(pointer + egui::vec2(16.0, 16.0))
                .interactable(false)
                .show(ui.ctx(), |ui| {
                    egui::Frame::popup(ui.style()).show(ui, |ui| hover_box(ui, &readout));
                });
        }
    }
}
