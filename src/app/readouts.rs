//! The CPU read-outs behind the views: the mesh deformed per method (hover
//! picking, the difference's colour bar) and the ranges the colour bars report.
//! Cached (the cache, `ReadoutCache`, is defined with `Views`, which holds it),
//! and invalidated by the document's changes, so a drag frame computes nothing
//! here unless a colour bar needs it.

use super::compare::{self, Pane, ValueRange};
use super::document::Document;
use super::views::Views;
use crate::coords::{Method, WeightsId};
use crate::render::{Colouring, Shading};
use glam::Vec3;
use std::sync::Arc;

impl Views {
    /// The mesh deformed with `method` on the CPU for the current pose (cached).
    pub(super) fn deformed_on_cpu(
        &mut self,
        document: &Document,
        id: impl Into<WeightsId>,
    ) -> Option<Arc<Vec<Vec3>>> {
        let id = id.into();
        let revision = document.pose_revision();
        if let Some((made_for, positions)) = self.readouts.deformed.get(&id) {
            if *made_for == revision {
                return Some(Arc::clone(positions));
            }
        }
        let set = document.bound_id(id)?;
        let weights = &set.weights;
        let moves =
            (document.deform_options(set.options)).column_moves(document.cage(), document.pose());
        let positions = Arc::new(compare::deform(
            weights,
            &document.mesh().positions,
            &moves,
            self.viewport.origin(),
        ));
        self.readouts
            .deformed
            .insert(id, (revision, Arc::clone(&positions)));
        Some(positions)
    }

    /// Screen position of mesh vertex `vertex` as drawn in view `pane`.
    pub fn mesh_vertex_screen_position(
        &mut self,
        document: &Document,
        pane: usize,
        vertex: usize,
    ) -> Option<egui::Pos2> {
        let (kind, projection) = self.viewport.pane(pane)?;
        let positions = self.deformed_on_cpu(document, kind.method())?;
        let screen = projection.project(*positions.get(vertex)?)?;
        Some(egui::Pos2::new(screen.x, screen.y))
    }

    /// The range of the values `colouring` shows in `pane`.
    pub fn value_range(
        &mut self,
        document: &Document,
        colouring: Colouring,
        pane: Pane,
    ) -> Option<ValueRange> {
        let against = match pane {
            Pane::Difference { against, .. } => Some(against),
            Pane::Method(_) => None,
        };
        let key = (colouring, pane.method(), against);
        if let Some((_, range)) = self.readouts.ranges.iter().find(|(k, _)| *k == key) {
            return *range;
        }
        let range = self.compute_value_range(document, colouring, pane);
        self.readouts.ranges.push((key, range));
        range
    }

    fn compute_value_range(
        &mut self,
        document: &Document,
        colouring: Colouring,
        pane: Pane,
    ) -> Option<ValueRange> {
        let method = pane.method();
        match colouring {
            Colouring::Shaded => None,
            Colouring::CageVertexWeight(_) | Colouring::TriangleWeight(_) => {
                let column = super::exports::shown_column(document, colouring, method)?;
                compare::column_range(document.weights(method)?, column)
            }
            Colouring::MostNegativeWeight => {
                let weights = document.weights(method)?;
                let vertex_columns = method.vertex_columns(document.cage());
                let stride = method.spec().columns.columns_per_element();
                compare::row_minimum_range(weights, vertex_columns, stride, document.outside())
            }
            Colouring::MethodDistance => {
                let Pane::Difference { against, shown } = pane else {
                    return None;
                };
                let a = self.deformed_on_cpu(document, against)?;
                let b = self.deformed_on_cpu(document, shown)?;
                let size = compare::cage_size(document.cage().positions()) as f32;
                compare::distance_range(&b, &a, size)
            }
        }
    }

    /// The magnitude at which `colouring`'s colours saturate: the same for every
    /// method in view, so methods are compared on one scale, side by side or when
    /// switching.
    pub(super) fn colour_limit(
        &mut self,
        document: &Document,
        wanted: &[Method],
        colouring: Colouring,
        pane: Pane,
    ) -> f32 {
        if colouring == Colouring::MethodDistance {
            if let Some(fixed) = self.settings.difference_limit {
                return fixed.max(f32::MIN_POSITIVE);
            }
        }
        let floor = match colouring {
            Colouring::MethodDistance => compare::DIFFERENCE_FLOOR,
            Colouring::MostNegativeWeight => compare::NEGATIVITY_FLOOR,
            _ => 0.0,
        };
        let panes: Vec<Pane> = match colouring {
            Colouring::MethodDistance => vec![pane],
            _ => wanted.iter().copied().map(Pane::Method).collect(),
        };
        let limit = panes
            .into_iter()
            .filter_map(|pane| self.value_range(document, colouring, pane))
            .map(|range| range.magnitude())
            .fold(floor, f32::max);
        if limit > 0.0 {
            limit
        } else {
            1.0
        }
    }

    /// How view `pane` is shaded this frame (method, colouring and colour scale).
    pub fn shading_of(&mut self, document: &Document, wanted: &[Method], pane: Pane) -> Shading {
        let colouring = self.settings.colouring(pane);
        Shading {
            method: pane.method(),
            against: match pane {
                Pane::Difference { against, .. } => Some(against),
                Pane::Method(_) => None,
            },
            colouring,
            scale: self.settings.scale_of(colouring),
            colour_limit: self.colour_limit(document, wanted, colouring, pane),
            cage_size: compare::cage_size(document.cage().positions()) as f32,
        }
    }
}
