//! `--drag CAGE_VERTEX` in a scripted run: after the bind, the pointer presses on
//! that cage vertex's handle in the first view, moves a little every frame and
//! lets go, through the same input path as a user's drag. The run then prints
//! how far the handle moved and the average frame time while it was dragged,
//! the figure the editor's drag benchmark quotes. A handle that is off screen or
//! that did not move is a failure of the run (exit status 1).

use super::document::Document;
use super::ui::statistics::FrameStats;
use super::viewport::Drag;
use super::views::Views;
use egui::{Event, Modifiers, PointerButton, Pos2, RawInput, Vec2};

/// Frames after the bind before the pointer presses (the views settle).
pub const DRAG_START_FRAME: u32 = 10;
/// Frames the pointer moves with the button held.
pub const DRAG_FRAMES: u32 = 60;
/// Pointer motion per frame, in points (120 points right and 60 up in all).
const STEP: Vec2 = Vec2::new(2.0, -1.0);

#[derive(Clone, Debug)]
enum Phase {
    Waiting,
    /// The button is down at `from`; `frames` moves sent so far.
    Held {
        from: Pos2,
        frames: u32,
    },
    Done,
}

/// The scripted drag of one handle.
#[derive(Clone, Debug)]
pub struct ScriptedDrag {
    handle: usize,
    phase: Phase,
    /// Where the handle was when the pointer pressed on it.
    start: Option<glam::DVec3>,
    /// Input time when the editor first saw the move begin.
    moving_since: Option<f64>,
    frames_moving: u32,
}

impl ScriptedDrag {
    pub fn new(handle: usize) -> Self {
        Self {
            handle,
            phase: Phase::Waiting,
            start: None,
            moving_since: None,
            frames_moving: 0,
        }
    }

    /// Whether the drag has ended (or could not start).
    pub fn is_done(&self) -> bool {
        matches!(self.phase, Phase::Done)
    }
}

/// What the scripted drag reads and steers besides its own state.
pub struct DragScene<'a> {
    pub document: &'a Document,
    pub views: &'a mut Views,
    /// A bind is running or queued: the drag waits for it.
    pub binding: bool,
    /// The frame times, restarted when the drag ends.
    pub frames: &'a mut FrameStats,
}

impl ScriptedDrag {
    /// Add this frame's pointer events (`frame` frames after the bind) to
    /// `input`; an error when the drag cannot start or did not move the handle.
    pub fn script_input(
        &mut self,
        frame: u32,
        input: &mut RawInput,
        scene: DragScene,
    ) -> Option<String> {
        let time = input.time.unwrap_or(0.0);
        let moving = matches!(scene.views.viewport.drag, Some(Drag::Move { .. }));
        if moving && self.moving_since.is_none() {
            self.moving_since = Some(time);
        }
        if moving {
            self.frames_moving += 1;
        }
        match self.phase.clone() {
            Phase::Waiting if frame >= DRAG_START_FRAME && !scene.binding => {
                match start_drag(self.handle, scene.document, scene.views) {
                    Ok(from) => {
                        input.events.push(Event::PointerMoved(from));
                        input.events.push(button(from, true));
                        self.start = scene.document.pose().get(self.handle).copied();
                        self.phase = Phase::Held { from, frames: 0 };
                    }
                    Err(text) => {
                        self.phase = Phase::Done;
                        return Some(text);
                    }
                }
            }
            Phase::Held { from, frames } if frames < DRAG_FRAMES => {
                let at = from + STEP * (frames + 1) as f32;
                input.events.push(Event::PointerMoved(at));
                self.phase = Phase::Held {
                    from,
                    frames: frames + 1,
                };
            }
            Phase::Held { from, frames } => {
                input
                    .events
                    .push(button(from + STEP * frames as f32, false));
                self.phase = Phase::Done;
                return self.report_drag(scene.document, time, scene.frames);
            }
            _ => {}
        }
        None
    }

    fn report_drag(
        &self,
        document: &Document,
        now: f64,
        frames: &mut FrameStats,
    ) -> Option<String> {
        let handle = self.handle;
        let now_at = document.pose().get(handle).copied();
        let moved = now_at.zip(self.start).map_or(0.0, |(a, b)| a.distance(b));
        let diagonal = document.cage().diagonal();
        let Some(since) = self.moving_since.filter(|_| moved > 0.0) else {
            return Some(format!("--drag {handle}: the handle did not move"));
        };
        // Frame intervals from the first frame that moved it to the release.
        let intervals = self.frames_moving.saturating_sub(1).max(1);
        eprintln!(
            "pmvc editor: dragged cage vertex {handle} by {:.3} % of the cage diagonal; average frame time while dragging {:.1} ms over {intervals} frames",
            100.0 * moved / diagonal,
            (now - since) * 1000.0 / intervals as f64,
        );
        frames.restart();
        None
    }
}

/// Where the handle to drag is on screen, or why it cannot be dragged.
fn start_drag(handle: usize, document: &Document, views: &mut Views) -> Result<Pos2, String> {
    let count = document.pose().len();
    if handle >= count {
        return Err(format!(
            "--drag {handle}: the cage has {count} vertices (0 to {})",
            count.saturating_sub(1)
        ));
    }
    // Handles are picked only while the cage is shown.
    views.settings.show_cage = true;
    let on_screen = views
        .screen_position_in(0, document.pose()[handle])
        .filter(|at| {
            views
                .viewport
                .pane_rects()
                .first()
                .is_some_and(|(_, rect)| rect.shrink(8.0).contains(*at))
        });
    on_screen.ok_or_else(|| format!("--drag {handle}: that handle is not in the first view"))
}

fn button(pos: Pos2, pressed: bool) -> Event {
    Event::PointerButton {
        pos,
        button: PointerButton::Primary,
        pressed,
        modifiers: Modifiers::NONE,
    }
}
