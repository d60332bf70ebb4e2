//! What a session file may hold, checked after it is parsed. The rule for each
//! value is the one its control uses: a family's parameter by its spec (out of
//! range: refused), a view value by its menu's range (out of range: brought into
//! it, with a notice saying so, since the view still shows the work). Poses far
//! beyond the cage are refused: they would draw nothing. Long text is cut.

use super::compare::{ViewSettings, DIFFERENCE_LIMITS, HANDLE_SIZES};
use super::session::{to_points, CameraEntry, SessionError};
use crate::geometry::{bounds_of, CageError};
use crate::render::{OrbitCamera, SceneOrigin};
use glam::DVec3;
use std::ops::RangeInclusive;
use std::path::Path;

/// The largest session file read (64 MiB). A session holds a pose and the
/// named poses, an edited cage at most, and names its mesh: a 100,000-vertex
/// edited cage with ten named poses is about 70 MiB of JSON.
pub const SESSION_SIZE_LIMIT: u64 = 64 << 20;

/// The most characters a session's title or a named pose's name keeps; longer
/// text is cut with a notice. The title heads the side panel, and laying out
/// millions of characters there took gigabytes.
pub const TEXT_LIMIT: usize = 200;

/// How far from the rest cage's centre a pose's position or a camera may be, in
/// cage diagonals. Far beyond this the view's single-precision arithmetic draws
/// nothing (a pose of 1e308 is infinite there).
pub const REACH_DIAGONALS: f64 = 1000.0;

/// The closest a camera comes to its target: where the wheel zoom stops
/// (`OrbitCamera::zoom_towards`; a test keeps the two in step).
const MIN_DISTANCE: f32 = 1e-3;

/// The steepest a camera looks up or down, as orbiting allows (89°).
const PITCH_LIMIT: f32 = 89.0 * std::f32::consts::PI / 180.0;

/// `text` cut to [`TEXT_LIMIT`] characters, and a notice naming `what` when it
/// was longer.
pub fn cut_text(text: &str, what: &str) -> (String, Option<String>) {
    match text.char_indices().nth(TEXT_LIMIT) {
        None => (text.to_owned(), None),
        Some((end, _)) => (
            text[..end].to_owned(),
            Some(format!(
                "{what} has {} characters; kept its first {TEXT_LIMIT}",
                text.chars().count()
            )),
        ),
    }
}

/// A number as a message shows it: plainly when that is short, else with an
/// exponent (1e30, not thirty-one digits).
fn shown(value: f64) -> String {
    let magnitude = value.abs();
    if magnitude == 0.0 || (1e-4..1e7).contains(&magnitude) {
        format!("{}", value as f32)
    } else {
        format!("{value:e}")
    }
}

/// `value` brought into `range`, with a notice naming `key` when it was outside.
fn into_range(key: &str, value: f32, range: RangeInclusive<f32>, notes: &mut Vec<String>) -> f32 {
    if range.contains(&value) {
        return value;
    }
    let clamped = if value.is_nan() {
        *range.start()
    } else {
        value.clamp(*range.start(), *range.end())
    };
    notes.push(format!(
        "{key} {} is outside {} to {}; using {}",
        shown(value.into()),
        shown((*range.start()).into()),
        shown((*range.end()).into()),
        shown(clamped.into()),
    ));
    clamped
}

/// The rest cage's centre and diagonal: what reach is measured from.
pub struct Reach {
    centre: DVec3,
    diagonal: f64,
}

impl Reach {
    pub fn of(rest: &[DVec3]) -> Self {
        let (lo, hi) = bounds_of(rest);
        Self {
            centre: (lo + hi) / 2.0,
            diagonal: (hi - lo).length(),
        }
    }

    fn limit(&self) -> f64 {
        REACH_DIAGONALS * self.diagonal
    }

    /// The first of `points` (1-based) farther from the cage than allowed, with
    /// its distance from the cage's centre.
    pub fn first_beyond(&self, points: &[DVec3]) -> Option<(usize, f64)> {
        points.iter().enumerate().find_map(|(index, point)| {
            let distance = point.distance(self.centre);
            (distance > self.limit()).then_some((index + 1, distance))
        })
    }

    /// A message for position `number` at `distance`.
    pub fn describe(&self, number: usize, distance: f64) -> String {
        format!(
            "position {number} (counting from 1) is {} from the cage's centre, more than \
             {REACH_DIAGONALS} cage diagonals ({})",
            shown(distance),
            shown(self.limit())
        )
    }
}

/// `points`, read as `what` (a pose of a cage of `vertices` vertices), when
/// there is one per cage vertex, each finite and within reach of the cage.
pub fn checked_pose(
    path: &Path,
    what: String,
    points: &[[f64; 3]],
    vertices: usize,
    reach: &Reach,
) -> Result<Vec<DVec3>, SessionError> {
    if points.len() != vertices {
        return Err(SessionError::PoseLength {
            path: path.to_owned(),
            what,
            found: points.len(),
            expected: vertices,
        });
    }
    if points.iter().flatten().any(|v| !v.is_finite()) {
        return Err(SessionError::NonFinite {
            path: path.to_owned(),
            what,
        });
    }
    let points = to_points(points);
    if let Some((number, distance)) = reach.first_beyond(&points) {
        return Err(SessionError::BeyondReach {
            path: path.to_owned(),
            what,
            message: reach.describe(number, distance),
        });
    }
    Ok(points)
}

/// `view` with each value in the range its control offers; notices say what
/// changed. `vertices` and `triangles` are the cage's counts.
pub fn view_in_range(
    mut view: ViewSettings,
    vertices: usize,
    triangles: usize,
    notes: &mut Vec<String>,
) -> ViewSettings {
    view.handle_size = into_range("view.handle_size", view.handle_size, HANDLE_SIZES, notes);
    view.difference_limit = view
        .difference_limit
        .map(|limit| into_range("view.difference_limit", limit, DIFFERENCE_LIMITS, notes));
    if view.heat_vertex >= vertices {
        notes.push(format!(
            "view.heat_vertex {} is not a cage vertex (0 to {}); using 0",
            view.heat_vertex,
            vertices.saturating_sub(1)
        ));
        view.heat_vertex = 0;
    }
    if let Some(triangle) = view.heat_triangle.filter(|&t| t >= triangles) {
        notes.push(format!(
            "view.heat_triangle {triangle} is not a cage triangle (0 to {}); showing vertex {}",
            triangles.saturating_sub(1),
            view.heat_vertex
        ));
        view.heat_triangle = None;
    }
    if let Some(note) = view.fit_compared() {
        notes.push(format!("view.compared: {note}"));
    }
    view
}

/// The camera `entry` (the `index`-th, from 0 as the file's list) with its
/// values in range: a target near the cage, a distance between the closest
/// zoom and the reach, a pitch short of the poles. Notices say what changed.
pub fn camera_in_range(
    entry: &CameraEntry,
    index: usize,
    reach: &Reach,
    origin: SceneOrigin,
    notes: &mut Vec<String>,
) -> OrbitCamera {
    let key = |field: &str| format!("cameras[{index}].{field}");
    let mut target = DVec3::from_array(entry.target);
    let offset = target.distance(reach.centre);
    if !offset.is_finite() || offset > reach.limit() {
        notes.push(format!(
            "{} is {} from the cage's centre, more than {REACH_DIAGONALS} cage diagonals; \
             using the centre",
            key("target"),
            shown(offset)
        ));
        target = reach.centre;
    }
    let farthest = reach.limit() as f32;
    let distance = into_range(
        &key("distance"),
        entry.distance,
        MIN_DISTANCE..=farthest.max(MIN_DISTANCE),
        notes,
    );
    let pitch = into_range(
        &key("pitch"),
        entry.pitch,
        -PITCH_LIMIT..=PITCH_LIMIT,
        notes,
    );
    // Any angle is a view; only its representation is brought near zero.
    let yaw = if entry.yaw.is_finite() {
        entry.yaw.rem_euclid(std::f32::consts::TAU)
    } else {
        0.0
    };
    OrbitCamera {
        target: origin.to_scene(target),
        distance,
        yaw,
        pitch,
        orthographic: entry.orthographic,
    }
}

/// A defect of an edited cage written in the session, in the file's terms: its
/// triangles counted from 1 in the list, position indices as written (from 0).
pub fn inline_cage_defect(error: &CageError) -> String {
    let positions = |count: usize| match count {
        0 => "no positions".to_owned(),
        _ => format!("{count} positions (indices 0 to {})", count - 1),
    };
    match error {
        CageError::TooFewVertices { count } => {
            format!("a cage needs at least 4 positions, this one has {count}")
        }
        CageError::NoFaces => "\"triangles\" is empty".to_owned(),
        CageError::NonFinite { vertex } => {
            format!("position index {vertex} has a coordinate that is not a finite number")
        }
        CageError::IndexOutOfRange { face, index, count } => format!(
            "triangle {} refers to position index {index}, but the cage has {}",
            face + 1,
            positions(*count)
        ),
        CageError::DegenerateTriangle { face, a, b, c } => format!(
            "triangle {} [{a}, {b}, {c}] is degenerate (zero area)",
            face + 1
        ),
        CageError::OpenEdge { a, b, face } => format!(
            "the cage is not closed: edge {a}–{b} of triangle {} has no neighbouring triangle",
            face + 1
        ),
        CageError::NonManifoldEdge { a, b, count, faces } => format!(
            "the cage is not edge-manifold: edge {a}–{b} is shared by {count} triangles \
             ({faces}, counting from 1)"
        ),
        CageError::InconsistentOrientation {
            a,
            b,
            first,
            second,
        } => format!(
            "triangles {} and {} are oriented inconsistently: both run along edge {a}→{b}",
            first + 1,
            second + 1
        ),
        // The rest name triangles only, counted from 1 as here.
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_cut_at_a_character_boundary_with_its_length_named() {
        let (kept, note) = cut_text(&"é".repeat(TEXT_LIMIT + 5), "the title");
        assert_eq!(kept.chars().count(), TEXT_LIMIT);
        assert!(note
            .unwrap()
            .contains(&format!("{} characters", TEXT_LIMIT + 5)));
        assert_eq!(cut_text("short", "x"), ("short".to_owned(), None));
    }

    #[test]
    fn camera_ranges_are_where_zooming_and_orbiting_stop() {
        let mut camera = OrbitCamera::default();
        camera.zoom_towards(1e-12, glam::Vec2::ZERO, 1.0);
        assert_eq!(camera.distance, MIN_DISTANCE);
        camera.orbit(glam::Vec2::new(0.0, 1e9));
        assert!(
            (camera.pitch - PITCH_LIMIT).abs() < 1e-6,
            "{}",
            camera.pitch
        );
        camera.orbit(glam::Vec2::new(0.0, -1e9));
        assert!(
            (camera.pitch + PITCH_LIMIT).abs() < 1e-6,
            "{}",
            camera.pitch
        );
    }

    #[test]
    fn large_and_small_numbers_are_shown_with_an_exponent() {
        assert_eq!(shown(1e30), "1e30");
        assert_eq!(shown(1e-30), "1e-30");
        assert_eq!(shown(12.0), "12");
        assert_eq!(shown(1.5), "1.5");
    }
}
