//! What the viewport compares: one method or MVC and PMVC side by side, their
//! difference, and what the mesh is coloured by (a single coordinate function, the
//! most negative weight). Also the CPU read-outs behind the colour bars and the
//! hover box. No GPU or UI code: the editor turns these into panes and widgets.

use crate::coords::{quality, Method, Weights};
use crate::render::colormap::Scale;
use crate::render::Colouring;
use glam::{DVec3, Mat4, Vec3};

/// How many of a vertex's weights the hover read-out lists.
pub const HOVER_TOP_WEIGHTS: usize = 5;

/// The arrangement of views.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Layout {
    /// One view, of the active method.
    #[default]
    Single,
    /// MVC and PMVC next to each other (and their difference, if asked for).
    SideBySide,
    /// One view coloured by |p′_MVC − p′_PMVC|.
    Difference,
}

/// What the method views colour the mesh by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Overlay {
    #[default]
    Shaded,
    /// λᵢ of the chosen cage vertex.
    Heatmap,
    /// minⱼ λⱼ per mesh vertex.
    Negativity,
}

/// One view in the viewport.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pane {
    /// The mesh deformed (and coloured) with one method's weights.
    Method(Method),
    /// The PMVC mesh coloured by its distance to the MVC mesh.
    Difference,
}

impl Pane {
    /// The weights this pane deforms the mesh with.
    pub fn method(self) -> Method {
        match self {
            Pane::Method(method) => method,
            Pane::Difference => Method::Pmvc,
        }
    }
}

/// The comparison settings, as the toolbar and `pmvc edit --view …` set them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ViewSettings {
    pub layout: Layout,
    pub overlay: Overlay,
    /// The cage vertex whose coordinate function the heatmap shows.
    pub heat_vertex: usize,
    pub scale: Scale,
    /// In the side-by-side layout, a third view of the difference.
    pub difference_pane: bool,
    /// All views share one camera.
    pub cameras_locked: bool,
    /// Show the weights under the cursor even on a plainly shaded mesh.
    pub hover_in_shaded: bool,
}

impl Default for ViewSettings {
    fn default() -> Self {
        Self {
            layout: Layout::Single,
            overlay: Overlay::Shaded,
            heat_vertex: 0,
            scale: Scale::Linear,
            difference_pane: false,
            cameras_locked: true,
            hover_in_shaded: false,
        }
    }
}

impl ViewSettings {
    /// The views to draw, left to right, with `active` the method of a single view.
    pub fn panes(&self, active: Method) -> Vec<Pane> {
        match self.layout {
            Layout::Single => vec![Pane::Method(active)],
            Layout::SideBySide if self.difference_pane => vec![
                Pane::Method(Method::Mvc),
                Pane::Method(Method::Pmvc),
                Pane::Difference,
            ],
            Layout::SideBySide => vec![Pane::Method(Method::Mvc), Pane::Method(Method::Pmvc)],
            Layout::Difference => vec![Pane::Difference],
        }
    }

    /// What `pane` colours the mesh by.
    pub fn colouring(&self, pane: Pane) -> Colouring {
        match (pane, self.overlay) {
            (Pane::Difference, _) => Colouring::MethodDistance,
            (Pane::Method(_), Overlay::Shaded) => Colouring::Shaded,
            (Pane::Method(_), Overlay::Heatmap) => {
                Colouring::CageVertexWeight(self.heat_vertex as u32)
            }
            (Pane::Method(_), Overlay::Negativity) => Colouring::MostNegativeWeight,
        }
    }

    /// Whether hovering the mesh in `pane` shows the weights under the cursor.
    pub fn shows_hover(&self, pane: Pane) -> bool {
        self.hover_in_shaded || self.colouring(pane) != Colouring::Shaded
    }
}

/// The smallest and largest value a colour bar reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ValueRange {
    pub min: f32,
    pub max: f32,
}

impl ValueRange {
    fn of(values: impl IntoIterator<Item = f32>) -> Option<Self> {
        values.into_iter().fold(None, |range, v| {
            Some(match range {
                None => ValueRange { min: v, max: v },
                Some(ValueRange { min, max }) => ValueRange {
                    min: min.min(v),
                    max: max.max(v),
                },
            })
        })
    }

    /// The magnitude a symmetric colour scale needs to show the whole range.
    pub fn magnitude(&self) -> f32 {
        self.min.abs().max(self.max.abs())
    }
}

/// Range of λᵢ over the mesh for one cage vertex (column).
pub fn column_range(weights: &Weights, column: usize) -> Option<ValueRange> {
    if column >= weights.cols {
        return None;
    }
    ValueRange::of(
        weights
            .values
            .chunks_exact(weights.cols)
            .map(|row| row[column]),
    )
}

/// Range over the mesh of each vertex's most negative (smallest) weight.
pub fn row_minimum_range(weights: &Weights) -> Option<ValueRange> {
    if weights.cols == 0 {
        return None;
    }
    ValueRange::of(
        weights
            .values
            .chunks_exact(weights.cols)
            .map(|row| row.iter().copied().fold(f32::INFINITY, f32::min)),
    )
}

/// Range of |p′_a − p′_b| / `cage_size` over the mesh.
pub fn distance_range(a: &[Vec3], b: &[Vec3], cage_size: f32) -> Option<ValueRange> {
    let size = cage_size.max(f32::MIN_POSITIVE);
    ValueRange::of(a.iter().zip(b).map(|(p, q)| p.distance(*q) / size))
}

/// The diagonal of the cage's bounding box: the unit distances are measured in.
pub fn cage_size(cage: &[DVec3]) -> f64 {
    let (lo, hi) = crate::geometry::bounds_of(cage);
    (hi - lo).length().max(1e-12)
}

/// Mesh positions deformed by `weights` and the posed cage, in f32 as drawn.
pub fn deform(weights: &Weights, pose: &[DVec3]) -> Vec<Vec3> {
    weights.apply(pose).iter().map(|p| p.as_vec3()).collect()
}

/// What the hover box shows for one mesh vertex.
#[derive(Clone, Debug, PartialEq)]
pub struct HoverReadout {
    pub vertex: usize,
    pub method: Method,
    /// The largest weights, largest first: (cage vertex, λ).
    pub top: Vec<(usize, f32)>,
    /// The most negative weight, if any is negative.
    pub most_negative: Option<(usize, f32)>,
}

impl HoverReadout {
    pub fn new(weights: &Weights, method: Method, vertex: usize) -> Option<Self> {
        let row = weights.values.chunks_exact(weights.cols).nth(vertex)?;
        Some(Self {
            vertex,
            method,
            top: quality::top_weights(row, HOVER_TOP_WEIGHTS),
            most_negative: quality::most_negative(row),
        })
    }
}

/// The mesh vertex drawn under `pointer`: of the vertices projected within
/// `radius` points of it, the one nearest the camera (so hidden ones lose).
pub fn vertex_under_pointer(
    positions: &[Vec3],
    view_projection: Mat4,
    origin: glam::Vec2,
    size: glam::Vec2,
    pointer: glam::Vec2,
    radius: f32,
) -> Option<usize> {
    let mut best: Option<(usize, f32)> = None;
    for (index, p) in positions.iter().enumerate() {
        let clip = view_projection * p.extend(1.0);
        if clip.w <= 1e-6 {
            continue;
        }
        let ndc = clip.truncate() / clip.w;
        let screen = origin + glam::Vec2::new((ndc.x + 1.0) / 2.0, (1.0 - ndc.y) / 2.0) * size;
        if screen.distance(pointer) > radius {
            continue;
        }
        if best.is_none_or(|(_, depth)| ndc.z < depth) {
            best = Some((index, ndc.z));
        }
    }
    best.map(|(index, _)| index)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn matrix(rows: &[&[f32]]) -> Weights {
        Weights {
            rows: rows.len(),
            cols: rows[0].len(),
            values: rows.iter().flat_map(|r| r.iter().copied()).collect(),
        }
    }

    #[test]
    fn panes_follow_the_layout() {
        let mut settings = ViewSettings::default();
        assert_eq!(settings.panes(Method::Mvc), vec![Pane::Method(Method::Mvc)]);
        settings.layout = Layout::SideBySide;
        assert_eq!(settings.panes(Method::Mvc).len(), 2);
        settings.difference_pane = true;
        assert_eq!(settings.panes(Method::Pmvc)[2], Pane::Difference);
        settings.layout = Layout::Difference;
        assert_eq!(settings.panes(Method::Mvc), vec![Pane::Difference]);
        assert_eq!(
            settings.colouring(Pane::Difference),
            Colouring::MethodDistance
        );
    }

    #[test]
    fn ranges_of_a_column_and_of_row_minima() {
        let weights = matrix(&[&[0.5, 0.6, -0.1], &[0.2, 0.3, 0.5]]);
        assert_eq!(
            column_range(&weights, 2),
            Some(ValueRange {
                min: -0.1,
                max: 0.5
            })
        );
        assert_eq!(column_range(&weights, 3), None);
        assert_eq!(
            row_minimum_range(&weights),
            Some(ValueRange {
                min: -0.1,
                max: 0.2
            })
        );
        assert_eq!(
            ValueRange {
                min: -0.7,
                max: 0.5
            }
            .magnitude(),
            0.7
        );
    }

    #[test]
    fn the_front_vertex_under_the_pointer_wins() {
        let camera = crate::render::OrbitCamera::default();
        let view_projection = camera.view_projection(1.0);
        let towards_eye = (camera.eye() - camera.target).normalize() * 0.5;
        let positions = [camera.target - towards_eye, camera.target + towards_eye];
        let size = glam::Vec2::splat(100.0);
        let centre = glam::Vec2::splat(50.0);
        let picked = vertex_under_pointer(
            &positions,
            view_projection,
            glam::Vec2::ZERO,
            size,
            centre,
            3.0,
        );
        assert_eq!(picked, Some(1));
        let far = glam::Vec2::new(5.0, 5.0);
        assert_eq!(
            vertex_under_pointer(
                &positions,
                view_projection,
                glam::Vec2::ZERO,
                size,
                far,
                3.0
            ),
            None
        );
    }
}
