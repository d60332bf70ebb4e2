//! The mouse in the viewport: the drag state machine (orbit, pan, move handles,
//! box select), the wheel and clicks. Keys are in `shortcuts.rs`.

use super::Drag;
use crate::app::commands::{Command, GestureKind, Selection, POSE_EDIT};
use crate::app::compare::Overlay;
use crate::app::views::{ViewportContext, Views};
use egui::{Key, PointerButton, Rect};
use glam::{DVec3, Vec2};

/// The soft-selection radii the wheel reaches during a transform, as fractions
/// of the cage diagonal: those the Posing tools' slider offers.
const SOFT_RADII: (f64, f64) = (0.01, 1.0);

/// The axis held down (X, Y or Z) that constrains a move.
fn held_axis(ui: &egui::Ui) -> Option<DVec3> {
    ui.input(|i| {
        if i.key_down(Key::X) {
            Some(DVec3::X)
        } else if i.key_down(Key::Y) {
            Some(DVec3::Y)
        } else if i.key_down(Key::Z) {
            Some(DVec3::Z)
        } else {
            None
        }
    })
}

impl Views {
    pub(super) fn viewport_input(
        &mut self,
        ui: &egui::Ui,
        cx: &mut ViewportContext,
        pane: usize,
        response: &egui::Response,
        rect: Rect,
    ) {
        let locked = self.settings.cameras_locked;
        let (modifiers, press_origin, scroll, hover) = ui.input(|i| {
            (
                i.modifiers,
                i.pointer.press_origin(),
                i.smooth_scroll_delta.y,
                i.pointer.hover_pos(),
            )
        });

        // A G, R or S transform takes the pointer until it is confirmed or
        // cancelled; with soft selection on, its wheel sets the radius, as
        // Blender's proportional size.
        if self.viewport.modal.is_some() {
            if response.hovered() {
                if cx.pose_tools.soft_selection && scroll != 0.0 {
                    // Wheel up (scroll > 0) widens, as zooming in does not.
                    let radius = cx.pose_tools.soft_radius * f64::from((scroll * 0.004).exp());
                    cx.pose_tools.soft_radius = radius.clamp(SOFT_RADII.0, SOFT_RADII.1);
                }
                self.transform_pointer(cx, response);
            }
            return;
        }
        if response.clicked_by(PointerButton::Secondary) && modifiers.shift {
            if let Some(pointer) = response.interact_pointer_pos() {
                self.place_cursor(cx, pane, pointer);
            }
        }

        // Hover highlight (not while dragging, so the highlight does not flicker, and
        // not in `--screenshot` runs, where the pointer rests wherever the display
        // server put it).
        if self.viewport.drag.is_none() && !cx.facts.scripted && response.hovered() {
            let hovered = response
                .hover_pos()
                .and_then(|p| self.pick(cx.model.document(), p));
            self.viewport.set_hovered(hovered);
        }

        if response.hovered() && scroll != 0.0 {
            if let (Some(pointer), Some(projection)) = (hover, self.viewport.projection(pane)) {
                let ndc = projection.to_ndc(Vec2::new(pointer.x, pointer.y));
                let factor = (-scroll * 0.0015).exp();
                self.viewport.camera_mut(pane, locked).zoom_towards(
                    factor,
                    ndc,
                    rect.width() / rect.height().max(1.0),
                );
            }
        }

        if response.clicked_by(PointerButton::Primary) {
            let picked = response
                .interact_pointer_pos()
                .and_then(|p| self.pick(cx.model.document(), p));
            // In heatmap mode a click on a handle shows that vertex's coordinate.
            if let (Some(handle), Overlay::Heatmap) = (picked, self.settings.overlay) {
                self.settings.heat_vertex = handle;
                self.settings.heat_triangle = None;
            }
            let selection = match (picked, modifiers.shift) {
                (Some(handle), true) => Some(Selection::Toggle(handle)),
                (Some(handle), false) => Some(Selection::only([handle])),
                (None, false) => Some(Selection::only([])),
                (None, true) => None,
            };
            if let Some(selection) = selection {
                cx.apply(Command::Select(selection));
            }
        }

        if response.drag_started() {
            let origin = press_origin.unwrap_or(rect.center());
            self.viewport.drag = Some(if response.dragged_by(PointerButton::Primary) {
                // Alt+drag orbits wherever it starts, a handle included, as in
                // Blender with "emulate three-button mouse".
                if modifiers.alt {
                    Drag::Orbit
                } else if modifiers.command || ui.input(|i| i.key_down(Key::B)) {
                    Drag::Box {
                        origin,
                        additive: modifiers.shift,
                    }
                } else if let Some(handle) = self.pick(cx.model.document(), origin) {
                    if !cx.model.document().selection().contains(&handle) {
                        if modifiers.shift {
                            cx.apply(Command::Select(Selection::Toggle(handle)));
                        } else {
                            cx.apply(Command::Select(Selection::only([handle])));
                        }
                    }
                    cx.apply(Command::BeginGesture(GestureKind::Drag));
                    Drag::Move {
                        motion: egui::Vec2::ZERO,
                    }
                } else {
                    Drag::Orbit
                }
            } else if response.dragged_by(PointerButton::Middle) {
                if modifiers.shift {
                    Drag::Pan
                } else {
                    Drag::Orbit
                }
            } else {
                Drag::Pan
            });
        }

        if response.dragged() {
            let delta = response.drag_delta();
            match self.viewport.drag.take() {
                Some(Drag::Orbit) => {
                    self.viewport
                        .camera_mut(pane, locked)
                        .orbit(Vec2::new(delta.x, delta.y));
                    self.viewport.drag = Some(Drag::Orbit);
                }
                Some(Drag::Pan) => {
                    self.viewport
                        .camera_mut(pane, locked)
                        .pan(Vec2::new(delta.x, delta.y), rect.height().min(rect.width()));
                    self.viewport.drag = Some(Drag::Pan);
                }
                Some(Drag::Move { motion }) => {
                    // A drag whose document was replaced has ended.
                    if let Some(start) = cx.model.gesture_start(GestureKind::Drag) {
                        let motion = motion + delta;
                        let pose = self.moved_pose(cx, pane, start, motion, held_axis(ui), rect);
                        cx.apply(Command::PreviewGesture(pose));
                        self.viewport.drag = Some(Drag::Move { motion });
                    }
                }
                other => self.viewport.drag = other,
            }
        }

        if response.drag_stopped() {
            match self.viewport.drag.take() {
                Some(Drag::Move { .. }) => {
                    cx.apply(Command::EndGesture {
                        action: POSE_EDIT.into(),
                    });
                }
                Some(Drag::Box { origin, additive }) => {
                    let end = response.interact_pointer_pos().unwrap_or(origin);
                    self.box_select(cx, pane, Rect::from_two_pos(origin, end), additive);
                }
                _ => {}
            }
        }
    }
}
