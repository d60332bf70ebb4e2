//! Blender's modal transforms: with handles selected, G moves, R rotates and S
//! scales them, following the pointer from where the key was pressed. X, Y or Z
//! constrain to a world axis (press again to free it), a typed number sets the
//! amount (degrees, a factor, or a distance along the axis), a click or Enter
//! confirms, Esc or a right click restores the pose. Each transform is one undo
//! step. Soft selection and symmetry apply to every edit (`pose_tools`).

use super::{Modal, TransformKind};
use crate::app::commands::{Command, GestureKind};
use crate::app::document::Document;
use crate::app::pose_tools::{follow_weights, Pivot, PoseToolSettings, Transform, AXIS_NAMES};
use crate::app::posing::{pivot_of, pose_transformed};
use crate::app::views::{ViewportContext, Views};
use egui::{Color32, Key, Pos2, Rect, Stroke};
use glam::{DVec3, Vec2};

impl Views {
    /// Per handle, for the cage shader: 0 idle, 1 selected, 2 hovered, and with
    /// soft selection 3 + 255·w for a handle that follows with weight w.
    pub(in crate::app) fn handle_states(
        &self,
        document: &Document,
        tools: &PoseToolSettings,
    ) -> Vec<u32> {
        let selection = document.selection();
        let pose = document.pose();
        let soft = tools
            .soft_selection
            .then(|| tools.soft_radius * document.cage().diagonal());
        let weights = follow_weights(pose, selection, soft);
        (0..pose.len())
            .map(|i| {
                if selection.contains(&i) {
                    1
                } else if self.viewport.hovered == Some(i) {
                    2
                } else if weights[i] > 0.0 {
                    3 + (weights[i] * 255.0).round() as u32
                } else {
                    0
                }
            })
            .collect()
    }

    pub fn transform_under_way(&self) -> Option<TransformKind> {
        self.viewport.modal.as_ref().map(|m| m.kind)
    }

    /// G, R or S in view `pane` with the pointer at `pointer`.
    fn begin_transform(
        &mut self,
        cx: &mut ViewportContext,
        kind: TransformKind,
        pane: usize,
        pointer: Pos2,
    ) {
        if cx.model.document().selection().is_empty() {
            cx.info("select handles first: G moves, R rotates and S scales the selection");
            return;
        }
        // The model keeps the pose the transform starts from.
        cx.apply(Command::BeginGesture(GestureKind::Transform));
        let document = cx.model.document();
        self.viewport.modal = Some(Modal {
            kind,
            pane,
            pivot: pivot_of(document, cx.pose_tools, document.pose()),
            start_pointer: pointer,
            pointer,
            axis: None,
            typed: String::new(),
        });
    }

    /// G, R or S pressed: begin a transform in the view under the pointer. True
    /// when the pointer is over a view (the other shortcuts then wait).
    pub(in crate::app) fn begin_transform_at_pointer(
        &mut self,
        ctx: &egui::Context,
        cx: &mut ViewportContext,
        kind: TransformKind,
    ) -> bool {
        let pointer = ctx.input(|i| i.pointer.hover_pos());
        let pane = pointer.and_then(|p| self.viewport.pane_at(p));
        if let (Some(pointer), Some(pane)) = (pointer, pane) {
            self.begin_transform(cx, kind, pane, pointer);
            return true;
        }
        false
    }

    /// The keys of the transform under way, its own keymap as in Blender: an
    /// axis, a typed amount, Enter and Esc. False when none is under way.
    pub(in crate::app) fn steer_transform(
        &mut self,
        ctx: &egui::Context,
        cx: &mut ViewportContext,
    ) -> bool {
        let Some(modal) = &mut self.viewport.modal else {
            return false;
        };
        let (escape, enter, backspace, events) = ctx.input(|i| {
            (
                i.key_pressed(Key::Escape),
                i.key_pressed(Key::Enter),
                i.key_pressed(Key::Backspace),
                i.events.clone(),
            )
        });
        for (key, axis) in [(Key::X, 0), (Key::Y, 1), (Key::Z, 2)] {
            if ctx.input(|i| i.key_pressed(key)) {
                modal.axis = if modal.axis == Some(axis) {
                    None
                } else {
                    Some(axis)
                };
            }
        }
        for event in events {
            if let egui::Event::Text(text) = event {
                let accepted = text
                    .chars()
                    .all(|c| c.is_ascii_digit() || c == '.' || c == '-');
                if accepted {
                    modal.typed.push_str(&text);
                }
            }
        }
        if backspace {
            modal.typed.pop();
        }
        if escape {
            self.cancel_transform(cx);
        } else if enter {
            self.confirm_transform(cx);
        } else {
            self.preview_transform(cx);
        }
        true
    }

    /// The pointer of a transform under way: follow it, confirm on a click,
    /// cancel on a right click.
    pub(super) fn transform_pointer(
        &mut self,
        cx: &mut ViewportContext,
        response: &egui::Response,
    ) {
        let Some(modal) = &mut self.viewport.modal else {
            return;
        };
        if let Some(pointer) = response.ctx.input(|i| i.pointer.hover_pos()) {
            modal.pointer = pointer;
        }
        if response.clicked_by(egui::PointerButton::Primary) {
            self.confirm_transform(cx);
        } else if response.clicked_by(egui::PointerButton::Secondary) {
            self.cancel_transform(cx);
        } else {
            self.preview_transform(cx);
        }
    }

    fn preview_transform(&mut self, cx: &mut ViewportContext) {
        let Some(modal) = &self.viewport.modal else {
            return;
        };
        // A transform whose document was replaced has ended.
        let Some(start) = cx.model.gesture_start(GestureKind::Transform) else {
            self.viewport.modal = None;
            return;
        };
        let transform = self.modal_transform(modal);
        let pose = pose_transformed(cx.model.document(), cx.pose_tools, start, &transform);
        cx.apply(Command::PreviewGesture(pose));
    }

    fn confirm_transform(&mut self, cx: &mut ViewportContext) {
        self.preview_transform(cx);
        if let Some(modal) = self.viewport.modal.take() {
            let action = format!("{} handles", modal.kind.verb().to_lowercase());
            cx.apply(Command::EndGesture { action });
        }
    }

    fn cancel_transform(&mut self, cx: &mut ViewportContext) {
        if self.viewport.modal.take().is_some() {
            cx.apply(Command::CancelGesture);
        }
    }

    /// The transform the pointer (or the typed number) asks for.
    fn modal_transform(&self, modal: &Modal) -> Transform {
        let typed: Option<f64> = modal.typed.parse().ok();
        let axis = modal.axis.map(|a| DVec3::AXES[a]);
        let projection = self.viewport.pane(modal.pane).map(|(_, p)| p);
        let pivot_screen = projection
            .and_then(|p| p.project_world(modal.pivot))
            .map(|s| Pos2::new(s.x, s.y))
            .unwrap_or(modal.start_pointer);
        let from = modal.start_pointer - pivot_screen;
        let to = modal.pointer - pivot_screen;
        match modal.kind {
            TransformKind::Grab => {
                if let (Some(distance), Some(axis)) = (typed, axis) {
                    return Transform::Translate(axis * distance);
                }
                let rect = self
                    .viewport
                    .pane_rects()
                    .get(modal.pane)
                    .map_or(Rect::NOTHING, |(_, r)| *r);
                let motion = modal.pointer - modal.start_pointer;
                Transform::Translate(self.drag_offset(modal.pane, modal.pivot, motion, axis, rect))
            }
            TransformKind::Rotate => {
                // Screen y points down: a counter-clockwise turn on screen is a
                // positive turn about the axis towards the viewer.
                let on_screen = -(to.y.atan2(to.x) - from.y.atan2(from.x)) as f64;
                let camera = self.camera_of(modal.pane);
                let towards_viewer = (camera.eye() - camera.target)
                    .normalize_or_zero()
                    .as_dvec3();
                let (axis, angle) = match axis {
                    Some(axis) => {
                        let sign = if axis.dot(towards_viewer) < 0.0 {
                            -1.0
                        } else {
                            1.0
                        };
                        (axis, typed.map_or(on_screen * sign, f64::to_radians))
                    }
                    None => (towards_viewer, typed.map_or(on_screen, f64::to_radians)),
                };
                Transform::Rotate { axis, angle }
            }
            TransformKind::Scale => {
                let factor = typed
                    .unwrap_or_else(|| f64::from(to.length()) / f64::from(from.length().max(1.0)));
                Transform::Scale(match modal.axis {
                    Some(a) => {
                        let mut factors = DVec3::ONE;
                        factors[a] = factor;
                        factors
                    }
                    None => DVec3::splat(factor),
                })
            }
        }
    }

    /// The line from the pivot to the pointer, and what the transform does.
    pub(super) fn draw_transform(
        &self,
        cx: &ViewportContext,
        painter: &egui::Painter,
        pane: usize,
        rect: Rect,
    ) {
        let Some(modal) = &self.viewport.modal else {
            if cx.pose_tools.pivot == Pivot::Cursor {
                if let Some((_, projection)) = self.viewport.pane(pane) {
                    if let Some(at) = projection.project_world(cx.pose_tools.cursor) {
                        let at = Pos2::new(at.x, at.y);
                        painter.circle_stroke(
                            at,
                            7.0,
                            Stroke::new(2.0, Color32::from_rgb(230, 60, 60)),
                        );
                        painter.circle_stroke(at, 7.0, Stroke::new(1.0, Color32::WHITE));
                    }
                }
            }
            return;
        };
        if modal.pane != pane {
            return;
        }
        if let Some((_, projection)) = self.viewport.pane(pane) {
            if let Some(pivot) = projection.project_world(modal.pivot) {
                let pivot = Pos2::new(pivot.x, pivot.y);
                painter.line_segment(
                    [pivot, modal.pointer],
                    Stroke::new(1.0, Color32::from_gray(220)),
                );
                painter.circle_filled(pivot, 3.0, Color32::WHITE);
                if cx.pose_tools.soft_selection {
                    // The soft-selection radius about the pivot, in the view
                    // plane: what the wheel sets during the transform.
                    let radius = cx.pose_tools.soft_radius * cx.model.document().cage().diagonal();
                    let (right, _) = self.camera_of(pane).right_up();
                    let rim = projection.project_world(modal.pivot + right.as_dvec3() * radius);
                    if let Some(rim) = rim {
                        let on_screen = Pos2::new(rim.x, rim.y).distance(pivot);
                        painter.circle_stroke(
                            pivot,
                            on_screen,
                            Stroke::new(1.0, Color32::from_rgb(255, 170, 60)),
                        );
                    }
                }
            }
        }
        let transform = self.modal_transform(modal);
        let amount = match transform {
            // Along an axis the sign says which way; free, the distance.
            Transform::Translate(offset) => match modal.axis {
                Some(axis) => format!("by {:+.4}", offset[axis]),
                None => format!("by {:.4}", offset.length()),
            },
            Transform::Rotate { angle, .. } => format!("{:.1}°", angle.to_degrees()),
            Transform::Scale(factors) => {
                format!("× {:.3}", modal.axis.map_or(factors.x, |a| factors[a]))
            }
        };
        let along = modal.axis.map_or(String::new(), |a| {
            let relation = if modal.kind == TransformKind::Rotate {
                "about"
            } else {
                "along"
            };
            format!(" {relation} {}", AXIS_NAMES[a])
        });
        let typed = if modal.typed.is_empty() {
            String::new()
        } else {
            format!(" [{}]", modal.typed)
        };
        let text = format!(
            "{}{along}: {amount}{typed}  ·  click or Enter confirms, Esc or right click cancels, X/Y/Z axis",
            modal.kind.verb()
        );
        painter.text(
            rect.left_bottom() + egui::vec2(10.0, -10.0),
            egui::Align2::LEFT_BOTTOM,
            text,
            egui::FontId::proportional(14.0),
            Color32::from_rgb(255, 200, 120),
        );
    }

    fn mesh_point_under(
        &mut self,
        document: &Document,
        pane: usize,
        pointer: Pos2,
    ) -> Option<DVec3> {
        let (kind, projection) = self.viewport.pane(pane)?;
        let positions = self.deformed_on_cpu(document, kind.method())?;
        let vertex = crate::app::compare::vertex_under_pointer(
            &positions,
            projection.view_projection,
            projection.origin,
            projection.size,
            Vec2::new(pointer.x, pointer.y),
            12.0,
        )?;
        // The CPU's positions are in scene coordinates, as the view draws them.
        let at = positions.get(vertex)?;
        Some(projection.scene_origin.to_world(*at))
    }

    /// Shift+right click: the 3D cursor goes to the handle or mesh vertex under
    /// the pointer, and becomes the pivot.
    pub(super) fn place_cursor(&mut self, cx: &mut ViewportContext, pane: usize, pointer: Pos2) {
        let document = cx.model.document();
        let handle = self
            .pick(document, pointer)
            .and_then(|h| document.pose().get(h).copied());
        let target = match handle {
            Some(at) => Some(at),
            None => self.mesh_point_under(document, pane, pointer),
        };
        match target {
            Some(at) => {
                cx.pose_tools.cursor = at;
                cx.pose_tools.pivot = Pivot::Cursor;
            }
            None => cx.info("Shift+right click on a handle or the mesh places the 3D cursor"),
        }
    }
}
