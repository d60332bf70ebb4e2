//! The panes: laid out side by side each frame, their input taken, then drawn
//! with their titles, axes, colour bars and the Generate cage proposal.

use super::{axes_rect, Drag, AXES_LENGTH};
use crate::app::cage_generation::{
    bridged_dot_stride, Proposal, BRIDGED_GAP_ORANGE, PROPOSAL_GREEN,
};
use crate::app::compare::Pane;
use crate::app::posing::pose_transformed;
use crate::app::views::{ViewportContext, Views};
use crate::app::widgets::draw_colour_bar;
use crate::render::{
    Colouring, FrameParams, OrbitCamera, ScreenProjection, ViewportCallback, MAX_VIEWS,
};
use eframe::egui_wgpu;
use egui::{Color32, Pos2, Rect, Sense, Stroke};
use glam::{DVec3, Vec2};

/// Gap between side-by-side views, in points.
const PANE_GAP: f32 = 2.0;

/// This frame's panes, laid out by [`Views::input`] for [`Views::draw`].
pub struct PaneLayout {
    kinds: Vec<Pane>,
    rects: Vec<Rect>,
    full: Rect,
    /// The pane under the pointer, and where the pointer is.
    hovered: Option<(usize, Option<Pos2>)>,
}

impl Views {
    /// The camera view `pane` is drawn with (in scene coordinates).
    pub fn camera_of(&self, pane: usize) -> OrbitCamera {
        self.viewport.camera_of(pane, self.settings.cameras_locked)
    }

    /// Screen position (in points) of a cage handle at `at` (world) in view `pane`.
    pub fn screen_position_in(&self, pane: usize, at: DVec3) -> Option<Pos2> {
        let screen = self.viewport.projection(pane)?.project_world(at)?;
        Some(Pos2::new(screen.x, screen.y))
    }

    fn pane_projection(&self, pane: usize, rect: Rect) -> ScreenProjection {
        let aspect = rect.width() / rect.height().max(1.0);
        ScreenProjection {
            view_projection: self.camera_of(pane).view_projection(aspect),
            origin: Vec2::new(rect.min.x, rect.min.y),
            size: Vec2::new(rect.width(), rect.height()),
            scene_origin: self.viewport.origin,
        }
    }

    /// Lay the panes out and take their input (which may change the model);
    /// the GPU copy is brought up to date before [`Self::draw`].
    pub fn input(&mut self, ui: &mut egui::Ui, cx: &mut ViewportContext) -> PaneLayout {
        let full = ui.available_rect_before_wrap();
        let kinds = self.settings.panes(cx.facts.active_method, MAX_VIEWS);
        let width = (full.width() - PANE_GAP * (kinds.len() as f32 - 1.0)) / kinds.len() as f32;
        let rects: Vec<Rect> = (0..kinds.len())
            .map(|i| {
                let left = full.left() + i as f32 * (width + PANE_GAP);
                Rect::from_min_max(
                    Pos2::new(left, full.top()),
                    Pos2::new(left + width, full.bottom()),
                )
            })
            .collect();
        // Projections first, so that picking sees every view with this frame's layout.
        self.viewport.panes = kinds
            .iter()
            .zip(&rects)
            .enumerate()
            .map(|(i, (&kind, &rect))| (kind, rect, self.pane_projection(i, rect)))
            .collect();
        let mut hovered = None;
        for (index, &rect) in rects.iter().enumerate() {
            let response = ui.interact(
                rect,
                ui.scope_id().with(("view", index)),
                Sense::click_and_drag(),
            );
            self.viewport_input(ui, cx, index, &response, rect);
            if response.hovered() {
                hovered = Some((index, response.hover_pos()));
            }
        }
        // The input may have moved the cameras; draw with the final ones.
        for (index, &rect) in rects.iter().enumerate() {
            self.viewport.panes[index].2 = self.pane_projection(index, rect);
        }
        if hovered.is_none() && self.viewport.drag.is_none() {
            self.viewport.set_hovered(None);
        }
        PaneLayout {
            kinds,
            rects,
            full,
            hovered,
        }
    }

    /// Draw the panes laid out by [`Self::input`], the hover box and the box
    /// selection's band.
    pub fn draw(&mut self, ui: &mut egui::Ui, cx: &mut ViewportContext, layout: PaneLayout) {
        for (index, (&kind, &rect)) in layout.kinds.iter().zip(&layout.rects).enumerate() {
            let projection = self.viewport.panes[index].2;
            self.draw_pane(ui, cx, index, kind, rect, projection);
        }
        ui.advance_cursor_after_rect(layout.full);
        self.update_hover(ui, cx, layout.hovered);
        if let Some(Drag::Box { origin, .. }) = &self.viewport.drag {
            if let Some(current) = ui.input(|i| i.pointer.interact_pos()) {
                let band = Rect::from_two_pos(*origin, current);
                ui.painter()
                    .rect_filled(band, 0.0, Color32::from_white_alpha(20));
                ui.painter().rect_stroke(
                    band,
                    0.0,
                    Stroke::new(1.0, Color32::WHITE),
                    egui::StrokeKind::Inside,
                );
            }
        }
    }

    /// One view: the 3D image, its label, its colour bar and any notice.
    fn draw_pane(
        &mut self,
        ui: &egui::Ui,
        cx: &mut ViewportContext,
        index: usize,
        kind: Pane,
        rect: Rect,
        projection: ScreenProjection,
    ) {
        let shading = self.shading_of(cx.model.document(), &cx.facts.wanted, kind);
        let painter = ui.painter_at(rect);
        let pixels_per_point = ui.ctx().pixels_per_point();
        if cx.facts.has_gpu {
            let params = FrameParams {
                view: index,
                shading,
                view_projection: projection.view_projection,
                eye: self.camera_of(index).eye(),
                size_px: [
                    (rect.width() * pixels_per_point).round().max(1.0) as u32,
                    (rect.height() * pixels_per_point).round().max(1.0) as u32,
                ],
                handle_radius_px: self.settings.handle_size * pixels_per_point,
                highlight_outside: self.highlight_outside,
                show_cage: self.settings.show_cage,
                wireframe: self.settings.wireframe,
                smooth_shading: self.settings.smooth_shading,
            };
            painter.add(egui_wgpu::Callback::new_paint_callback(
                rect,
                ViewportCallback { params },
            ));
        } else {
            painter.text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "No wgpu device: the viewport is unavailable",
                egui::FontId::proportional(16.0),
                Color32::LIGHT_RED,
            );
        }
        let font = egui::FontId::proportional(14.0);
        painter.text(
            rect.left_top() + egui::vec2(10.0, 8.0),
            egui::Align2::LEFT_TOP,
            self.pane_title(cx, kind),
            font.clone(),
            Color32::from_gray(230),
        );
        let document = cx.model.document();
        if kind.methods().iter().any(|&m| document.bound(m).is_none()) {
            let message = if cx.facts.binding {
                "Binding… the mesh is shown at rest until the weights are ready"
            } else {
                "Not bound: the mesh is shown at rest (Bind in the side panel)"
            };
            painter.text(
                rect.left_top() + egui::vec2(10.0, 28.0),
                egui::Align2::LEFT_TOP,
                message,
                font,
                Color32::from_gray(200),
            );
        }
        self.draw_axes(&painter, index, rect);
        self.draw_transform(cx, &painter, index, rect);
        if let Some(proposal) = cx.facts.proposal {
            self.draw_proposed_cage(proposal, &painter, index);
        }
        if shading.colouring != Colouring::Shaded {
            let document = cx.model.document();
            if let Some(range) = self.value_range(document, shading.colouring, kind) {
                let note = self.colour_bar_note(document, shading.colouring, kind);
                let title = self.colour_bar_title(document, kind);
                draw_colour_bar(&painter, rect, &shading, range, title, note);
            }
        }
    }

    /// The world axes as view `pane`'s camera sees them, small, at its right
    /// edge below the title and notice lines: x red, y green, z blue, those
    /// pointing away drawn first and dimmer.
    fn draw_axes(&self, painter: &egui::Painter, pane: usize, rect: Rect) {
        const LENGTH: f32 = AXES_LENGTH;
        let camera = self.camera_of(pane);
        let (right, up) = camera.right_up();
        let towards_viewer = (camera.eye() - camera.target).normalize_or_zero();
        let centre = axes_rect(rect).center();
        let colours = [
            Color32::from_rgb(230, 80, 80),
            Color32::from_rgb(110, 200, 90),
            Color32::from_rgb(90, 140, 240),
        ];
        let mut axes: Vec<(usize, glam::Vec3)> = [glam::Vec3::X, glam::Vec3::Y, glam::Vec3::Z]
            .into_iter()
            .enumerate()
            .collect();
        axes.sort_by(|a, b| a.1.dot(towards_viewer).total_cmp(&b.1.dot(towards_viewer)));
        for (index, axis) in axes {
            let tip = centre + egui::vec2(axis.dot(right), -axis.dot(up)) * LENGTH;
            let colour = if axis.dot(towards_viewer) < -1e-3 {
                colours[index].gamma_multiply(0.5)
            } else {
                colours[index]
            };
            painter.line_segment([centre, tip], Stroke::new(2.0, colour));
            // An axis pointing at the viewer has no direction on screen.
            let along = tip - centre;
            let outward = if along.length() > 1e-3 {
                along / along.length()
            } else {
                egui::Vec2::ZERO
            };
            painter.text(
                tip + outward * 7.0,
                egui::Align2::CENTER_CENTER,
                ["x", "y", "z"][index],
                egui::FontId::proportional(12.0),
                colour,
            );
        }
    }

    /// The proposed cage's edges over view `pane`, in green.
    fn draw_proposed_cage(&self, proposal: &Proposal, painter: &egui::Painter, pane: usize) {
        let Some((_, projection)) = self.viewport.pane(pane) else {
            return;
        };
        let screen: Vec<Option<Pos2>> = proposal
            .generated
            .cage
            .positions()
            .iter()
            .map(|p| projection.project_world(*p).map(|at| Pos2::new(at.x, at.y)))
            .collect();
        let stroke = Stroke::new(1.5, PROPOSAL_GREEN);
        for [a, b] in &proposal.edges {
            if let (Some(Some(from)), Some(Some(to))) =
                (screen.get(*a as usize), screen.get(*b as usize))
            {
                painter.line_segment([*from, *to], stroke);
            }
        }
        let bridged = &proposal.generated.stats.gaps.bridged;
        for point in bridged.iter().step_by(bridged_dot_stride(bridged.len())) {
            if let Some(at) = projection.project_world(*point) {
                painter.circle_filled(Pos2::new(at.x, at.y), 2.5, BRIDGED_GAP_ORANGE);
            }
        }
    }

    /// "PMVC · 32² · bound in 0.41 s" and the like; a deformation setting away
    /// from its default too ("Somigliana · ν 0 · γ 4 · …"), so a picture says
    /// how it was deformed.
    fn pane_title(&self, cx: &ViewportContext, kind: Pane) -> String {
        match kind {
            Pane::Method(method) => match cx.model.document().bound(method) {
                Some(set) => {
                    let parameter = set
                        .options
                        .parameter()
                        .map(|(spec, value)| format!(" · {}", (spec.format)(value)))
                        .unwrap_or_default();
                    let document = cx.model.document();
                    let settings: String = (document.deform_options(set.options))
                        .deform_labels()
                        .iter()
                        .map(|label| format!(" · {label}"))
                        .collect();
                    let parameter = parameter + &settings;
                    let seconds = if cx.facts.hide_timings {
                        String::new()
                    } else {
                        format!(" · bound in {:.2} s", set.bind_time.as_secs_f32())
                    };
                    let name = set.options.family_name(cx.model.document().cage());
                    format!("{name}{parameter}{seconds}")
                }
                None => format!("{} · not bound", method.name()),
            },
            Pane::Difference { against, shown } => {
                format!("{against} vs {shown}: distance / cage diagonal")
            }
        }
    }

    /// `start_pose` with the selection moved by a pointer motion of `motion` points:
    /// in the view plane, or along `axis` by the motion's component along the axis's
    /// screen direction.
    /// How far a pointer motion of `motion` moves a point at `centre` in view
    /// `pane`: in the view plane, or along `axis` as far as the pointer went
    /// along the axis's image on screen.
    pub(super) fn drag_offset(
        &self,
        pane: usize,
        centre: DVec3,
        motion: egui::Vec2,
        axis: Option<DVec3>,
        rect: Rect,
    ) -> DVec3 {
        let camera = self.camera_of(pane);
        let short_side = rect.height().min(rect.width());
        let depth = camera.depth_of(self.viewport.origin.to_scene(centre));
        let scale = camera.units_per_pixel(depth, short_side);
        let (right, up) = camera.right_up();
        let in_plane = (right * motion.x - up * motion.y) * scale;
        match (axis, self.viewport.projection(pane)) {
            (Some(axis), Some(projection)) => {
                let from = projection.project_world(centre);
                let to = projection.project_world(centre + axis);
                match (from, to) {
                    (Some(from), Some(to)) if (to - from).length_squared() > 1e-6 => {
                        let screen_axis = to - from;
                        let along = Vec2::new(motion.x, motion.y).dot(screen_axis)
                            / screen_axis.length_squared();
                        axis * f64::from(along)
                    }
                    _ => axis * in_plane.as_dvec3().dot(axis),
                }
            }
            _ => in_plane.as_dvec3(),
        }
    }

    /// `start_pose` with the selection dragged by `motion`, soft selection and
    /// symmetry applied.
    pub(super) fn moved_pose(
        &self,
        cx: &ViewportContext,
        pane: usize,
        start_pose: &[DVec3],
        motion: egui::Vec2,
        axis: Option<DVec3>,
        rect: Rect,
    ) -> Vec<DVec3> {
        let selection = cx.model.document().selection();
        if selection.is_empty() {
            return start_pose.to_vec();
        }
        let centre = selection
            .iter()
            .filter_map(|&i| start_pose.get(i))
            .sum::<DVec3>()
            / selection.len() as f64;
        let offset = self.drag_offset(pane, centre, motion, axis, rect);
        pose_transformed(
            cx.model.document(),
            cx.pose_tools,
            start_pose,
            &crate::app::pose_tools::Transform::Translate(offset),
        )
    }
}
