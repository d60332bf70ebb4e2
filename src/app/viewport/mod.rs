//! The viewport: its panes (one per compared view), their cameras and drawing.
//! This file holds what the viewport keeps between frames; the files below
//! implement [`Views`](super::views::Views) on it: the panes' layout and drawing
//! in [`panes`], mouse handling in [`input`], G/R/S transforms in [`modal`],
//! handle and vertex picking in [`picking`]. It imports none of them, so the
//! state sits below the code that uses it.

mod colour_bar;
mod input;
mod modal;
mod panes;
mod picking;

use super::commands::ViewCameras;
use super::compare::{HoverReadout, Pane};
use crate::render::{OrbitCamera, SceneOrigin, ScreenProjection, MAX_VIEWS};
use egui::{Pos2, Rect};
use glam::DVec3;

/// The length of a pane's world axes, in points.
const AXES_LENGTH: f32 = 22.0;

/// Where a pane whose rectangle is `pane` draws its world axes and their
/// letters: at its right edge, below the title (8 points down) and the notice
/// under it (28).
pub fn axes_rect(pane: Rect) -> Rect {
    let centre = pane.right_top() + egui::vec2(-34.0, 76.0);
    Rect::from_center_size(centre, egui::Vec2::splat(2.0 * (AXES_LENGTH + 14.0)))
}

/// What the viewport keeps between frames.
#[derive(Default)]
pub struct ViewportState {
    /// What the cameras, the projections and the GPU's positions are relative
    /// to: the document's [`SceneOrigin`].
    origin: SceneOrigin,
    /// Index 0: the first view's camera, and every view's while they are locked.
    cameras: [OrbitCamera; MAX_VIEWS],
    /// The views drawn last frame, each with its screen rectangle and projection.
    panes: Vec<(Pane, Rect, ScreenProjection)>,
    pub(super) drag: Option<Drag>,
    /// A G, R or S transform under way.
    pub(super) modal: Option<Modal>,
    /// The handle under the cursor.
    pub(super) hovered: Option<usize>,
    hover_changed: bool,
    /// The weights under the cursor, and the view they were read in.
    pub(super) hover_readout: Option<(usize, HoverReadout)>,
}

impl ViewportState {
    pub fn camera_of(&self, pane: usize, locked: bool) -> OrbitCamera {
        if locked {
            self.cameras[0]
        } else {
            self.cameras[pane.min(MAX_VIEWS - 1)]
        }
    }

    fn camera_mut(&mut self, pane: usize, locked: bool) -> &mut OrbitCamera {
        if locked {
            &mut self.cameras[0]
        } else {
            &mut self.cameras[pane.min(MAX_VIEWS - 1)]
        }
    }

    /// Every camera looks at a sphere of `radius` around `centre` (world coordinates).
    pub fn frame(&mut self, centre: DVec3, radius: f64) {
        self.cameras[0].frame(self.origin.to_scene(centre), radius as f32);
        self.unify_cameras();
    }

    /// The scene origin of the document shown.
    pub fn origin(&self) -> SceneOrigin {
        self.origin
    }

    /// Measure from `origin` from now on; the cameras keep looking at the same
    /// place in the world.
    pub fn set_origin(&mut self, origin: SceneOrigin) {
        if origin != self.origin {
            let saved = self.cameras();
            self.origin = origin;
            self.set_cameras(saved);
        }
    }

    /// Every camera looks from `yaw` and `pitch` (radians; the pitch kept
    /// within the cameras' limit), at the same target and distance.
    pub fn look_from(&mut self, yaw: f32, pitch: f32) {
        for camera in &mut self.cameras {
            camera.look_from(yaw, pitch);
        }
    }

    /// Every view switches between a parallel and a perspective view together,
    /// as the first view was.
    pub fn toggle_orthographic(&mut self) {
        let parallel = !self.cameras[0].orthographic;
        for camera in &mut self.cameras {
            camera.orthographic = parallel;
        }
    }

    /// Every view takes the first view's camera.
    pub fn unify_cameras(&mut self) {
        self.cameras = [self.cameras[0]; MAX_VIEWS];
    }

    pub fn cameras(&self) -> ViewCameras {
        ViewCameras {
            origin: self.origin,
            cameras: self.cameras,
        }
    }

    /// Cameras saved by [`Self::cameras`], moved to the current origin.
    pub fn set_cameras(&mut self, saved: ViewCameras) {
        self.cameras = saved.cameras.map(|camera| OrbitCamera {
            target: self.origin.rebased_point(saved.origin, camera.target),
            ..camera
        });
    }

    /// The cameras, as many as a session file keeps.
    pub fn camera_list(&self) -> Vec<OrbitCamera> {
        self.cameras.to_vec()
    }

    /// Take the first `cameras`, in this document's scene coordinates.
    pub fn set_first_cameras(&mut self, cameras: &[OrbitCamera]) {
        for (slot, camera) in self.cameras.iter_mut().zip(cameras) {
            *slot = *camera;
        }
    }

    /// A new document: no drag, no hover.
    pub fn reset_interaction(&mut self) {
        self.drag = None;
        self.set_hovered(None);
        self.hover_readout = None;
    }

    fn set_hovered(&mut self, hovered: Option<usize>) {
        if hovered != self.hovered {
            self.hovered = hovered;
            self.hover_changed = true;
        }
    }

    /// Whether the hovered handle changed since the last call.
    pub fn take_hover_changed(&mut self) -> bool {
        std::mem::take(&mut self.hover_changed)
    }

    /// View `index` as drawn last frame: what it shows and its projection.
    pub fn pane(&self, index: usize) -> Option<(Pane, ScreenProjection)> {
        self.panes.get(index).map(|(kind, _, p)| (*kind, *p))
    }

    fn projection(&self, index: usize) -> Option<ScreenProjection> {
        self.panes.get(index).map(|(_, _, projection)| *projection)
    }

    /// The view under `pointer`.
    fn pane_at(&self, pointer: Pos2) -> Option<usize> {
        self.panes
            .iter()
            .position(|(_, rect, _)| rect.contains(pointer))
    }

    pub fn pane_rects(&self) -> Vec<(Pane, Rect)> {
        self.panes
            .iter()
            .map(|(pane, rect, _)| (*pane, *rect))
            .collect()
    }
}

/// What a mouse drag in the viewport is doing.
#[derive(Clone, Debug)]
pub(in crate::app) enum Drag {
    Orbit,
    Pan,
    /// Moving the selected handles (a gesture of the model's, which keeps the
    /// pose it began from): the total pointer motion since it began, so axis
    /// constraints can change mid-drag.
    Move {
        motion: egui::Vec2,
    },
    /// Rubber-band selection from `origin`; `additive` keeps the old selection.
    Box {
        origin: Pos2,
        additive: bool,
    },
}

/// A G, R or S transform (Blender's grab, rotate and scale).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransformKind {
    Grab,
    Rotate,
    Scale,
}

impl TransformKind {
    fn verb(self) -> &'static str {
        match self {
            TransformKind::Grab => "Move",
            TransformKind::Rotate => "Rotate",
            TransformKind::Scale => "Scale",
        }
    }
}

/// A transform under way.
#[derive(Clone, Debug)]
pub struct Modal {
    kind: TransformKind,
    pane: usize,
    pivot: DVec3,
    start_pointer: Pos2,
    pointer: Pos2,
    axis: Option<usize>,
    typed: String,
}
