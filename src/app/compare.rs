//! What the viewport compares: one method, several side by side, the difference
//! of two, and what the mesh is coloured by (a single coordinate function, the
//! most negative weight). Also the CPU read-outs behind the colour bars and the
//! hover box. No GPU or UI code: the editor turns these into panes and widgets.
//! Methods are data here: nothing below names a coordinate family except the
//! defaults.

use crate::coords::{quality, Method, QuadSplit, Twin, Weights, WeightsId};
use crate::render::colormap::Scale;
use crate::render::Colouring;
use glam::{DVec3, Mat4, Vec3};
use serde::{Deserialize, Serialize};

/// How many of a vertex's weights the hover read-out lists.
pub const HOVER_TOP_WEIGHTS: usize = 5;

/// The arrangement of views.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Layout {
    /// One view, of the active method.
    #[default]
    Single,
    /// The compared methods next to each other (and their difference, if asked for).
    SideBySide,
    /// One view coloured by |p′_a − p′_b| for the difference pair.
    Difference,
}

/// What the method views colour the mesh by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
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
    /// The mesh deformed with `shown`, coloured by its distance to the mesh
    /// deformed with `against`: another family, or `shown`'s triangulated twin.
    Difference { against: WeightsId, shown: Method },
}

impl Pane {
    /// The weights this pane deforms the mesh with.
    pub fn method(self) -> Method {
        match self {
            Pane::Method(method) => method,
            Pane::Difference { shown, .. } => shown,
        }
    }

    /// Every method whose weights the pane needs.
    pub fn methods(self) -> Vec<Method> {
        match self {
            Pane::Method(method) => vec![method],
            Pane::Difference { against, shown } => vec![against.method, shown],
        }
    }
}

/// A set of coordinate families, iterated in [`Method::ALL`] order; saved as a
/// list of identifiers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(from = "Vec<Method>", into = "Vec<Method>")]
pub struct MethodSet(u32);

impl MethodSet {
    fn bit(method: Method) -> u32 {
        1 << Method::ALL.iter().position(|&m| m == method).unwrap_or(0)
    }

    pub fn of(methods: &[Method]) -> Self {
        Self(methods.iter().map(|&m| Self::bit(m)).fold(0, |a, b| a | b))
    }

    pub fn contains(self, method: Method) -> bool {
        self.0 & Self::bit(method) != 0
    }

    pub fn set(&mut self, method: Method, included: bool) {
        if included {
            self.0 |= Self::bit(method);
        } else {
            self.0 &= !Self::bit(method);
        }
    }

    pub fn iter(self) -> impl Iterator<Item = Method> {
        Method::ALL.into_iter().filter(move |&m| self.contains(m))
    }

    pub fn len(self) -> usize {
        self.0.count_ones() as usize
    }

    pub fn is_empty(self) -> bool {
        self.0 == 0
    }
}

/// The smallest distance, as a fraction of the cage diagonal, the difference
/// view's automatic scale reaches: a difference of 0.1% is barely a pixel at usual
/// zooms, and f32 rounding (about 1e-7 of the diagonal) stays white under it,
/// also on the log scale's three decades.
pub const DIFFERENCE_FLOOR: f32 = 1e-3;

/// The smallest magnitude the negativity view's scale ends at: a weight of
/// −0.001 moves a vertex by a thousandth of its handle's motion. With no larger
/// negative weight in view (a convex cage), rounding noise of −1e-9 then stays
/// white instead of being stretched to full blue.
pub const NEGATIVITY_FLOOR: f32 = 1e-3;

/// The comparison settings, as the toolbar and `pmvc edit --view …` set them.
/// Sessions save them; a field missing from a session takes its default.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ViewSettings {
    pub layout: Layout,
    pub overlay: Overlay,
    /// The cage vertex whose coordinate function the heatmap shows.
    pub heat_vertex: usize,
    /// When set, the heatmap shows ψ of this cage triangle instead (Green
    /// coordinates' per-triangle functions; other families have none).
    pub heat_triangle: Option<usize>,
    /// The scale of the heatmap and the difference view.
    pub scale: Scale,
    /// The scale of the negativity view: logarithmic by default, because on real
    /// models MVC's negative weights are mostly a few thousandths and a linear
    /// scale leaves them almost white.
    pub negativity_scale: Scale,
    /// The methods the side-by-side layout shows, left to right in
    /// [`Method::ALL`] order.
    pub compared: MethodSet,
    /// The two methods the difference compares: the mesh is deformed with the
    /// second and coloured by its distance to the first.
    pub difference: [Method; 2],
    /// When set, the difference compares the shown family (the second of
    /// `difference`) with its triangulated twin, bound with the cage's quads split
    /// along this diagonal, instead of with the first family.
    pub difference_split: Option<QuadSplit>,
    /// When set (and no split is), the difference compares the shown family
    /// with itself at its parameter's reference value: PMVC at a cube-map
    /// resolution against exact PMVC.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub difference_reference: bool,
    /// In the side-by-side layout, one more view of the difference.
    pub difference_pane: bool,
    /// The difference view's colour scale ends here (a fraction of the cage
    /// diagonal) when set; otherwise at the largest distance, but never below
    /// [`DIFFERENCE_FLOOR`].
    #[serde(deserialize_with = "saturating_f32_option")]
    pub difference_limit: Option<f32>,
    /// All views share one camera.
    pub cameras_locked: bool,
    /// Show the weights under the cursor even on a plainly shaded mesh.
    pub hover_in_shaded: bool,
    /// Draw the cage's edges and handles; hidden ones cannot be picked.
    pub show_cage: bool,
    /// Handle radius in points (`HANDLE_SIZES`).
    #[serde(deserialize_with = "saturating_f32")]
    pub handle_size: f32,
    /// Draw the mesh's edges over its surface.
    pub wireframe: bool,
    /// Light the mesh with per-vertex normals of the deformed mesh; else per face.
    pub smooth_shading: bool,
}

/// An f32 of a file: a number past f32's range reads as ±infinity, which the
/// session's range checks then bring into range with a notice, instead of
/// refusing the whole file.
pub fn saturating_f32<'de, D: serde::Deserializer<'de>>(from: D) -> Result<f32, D::Error> {
    f64::deserialize(from).map(|value| value as f32)
}

/// [`saturating_f32`] for an optional value.
pub fn saturating_f32_option<'de, D: serde::Deserializer<'de>>(
    from: D,
) -> Result<Option<f32>, D::Error> {
    Option::<f64>::deserialize(from).map(|value| value.map(|value| value as f32))
}

/// The handle radii the View menu offers, in points; the default is 4.
pub const HANDLE_SIZES: std::ops::RangeInclusive<f32> = 1.5..=12.0;

/// The fixed ends the difference's colour scale may have, as fractions of the
/// cage diagonal (the toolbar shows them in percent: 0.0001% to 100%).
pub const DIFFERENCE_LIMITS: std::ops::RangeInclusive<f32> = 1e-6..=1.0;

/// The one check of a difference limit (a fraction of the cage diagonal) given
/// on the command line; the toolbar's control offers only this range, and a
/// session's value is brought into it with a notice.
pub fn check_difference_limit(fraction: f32) -> Result<f32, String> {
    if DIFFERENCE_LIMITS.contains(&fraction) {
        Ok(fraction)
    } else {
        Err(format!(
            "{}% is not a difference limit: it must be {}% to {}% of the cage diagonal",
            100.0 * fraction,
            100.0 * DIFFERENCE_LIMITS.start(),
            100.0 * DIFFERENCE_LIMITS.end()
        ))
    }
}

impl From<Vec<Method>> for MethodSet {
    fn from(methods: Vec<Method>) -> Self {
        Self::of(&methods)
    }
}

impl From<MethodSet> for Vec<Method> {
    fn from(set: MethodSet) -> Self {
        set.iter().collect()
    }
}

impl Default for ViewSettings {
    fn default() -> Self {
        Self {
            layout: Layout::Single,
            overlay: Overlay::Shaded,
            heat_vertex: 0,
            heat_triangle: None,
            scale: Scale::Linear,
            negativity_scale: Scale::LogMagnitude,
            compared: MethodSet::of(&[Method::Mvc, Method::Pmvc]),
            difference: [Method::Mvc, Method::Pmvc],
            difference_split: None,
            difference_reference: false,
            difference_pane: false,
            difference_limit: None,
            cameras_locked: true,
            hover_in_shaded: false,
            show_cage: true,
            handle_size: 4.0,
            wireframe: false,
            smooth_shading: true,
        }
    }
}

impl ViewSettings {
    /// Keep no more compared families than the side-by-side layout draws
    /// beside the difference pane (if shown), the first in [`Method::ALL`]
    /// order; says what was left out, for the caller to report.
    pub fn fit_compared(&mut self) -> Option<String> {
        let room = crate::render::MAX_VIEWS - usize::from(self.difference_pane);
        if self.compared.len() <= room {
            return None;
        }
        let kept: Vec<Method> = self.compared.iter().take(room).collect();
        let left: Vec<&str> = self.compared.iter().skip(room).map(Method::name).collect();
        self.compared = MethodSet::of(&kept);
        Some(format!(
            "the viewport shows at most {} views{}; left out {}",
            crate::render::MAX_VIEWS,
            if self.difference_pane {
                ", one of them the difference"
            } else {
                ""
            },
            left.join(", ")
        ))
    }

    /// The difference pane of [`Self::difference`].
    pub fn difference_pane_kind(&self) -> Pane {
        let [against, shown] = self.difference;
        let against = match (self.difference_split, self.difference_reference) {
            (Some(split), _) => WeightsId::split(shown, split),
            (None, true) => WeightsId::twin(shown, Twin::Reference),
            (None, false) => WeightsId::of(against),
        };
        Pane::Difference { against, shown }
    }

    /// The views to draw, left to right, with `active` the method of a single
    /// view; at most `max_panes`.
    pub fn panes(&self, active: Method, max_panes: usize) -> Vec<Pane> {
        let mut panes = match self.layout {
            Layout::Single => vec![Pane::Method(active)],
            Layout::SideBySide => {
                let mut panes: Vec<Pane> = self.compared.iter().map(Pane::Method).collect();
                if panes.is_empty() {
                    panes.push(Pane::Method(active));
                }
                if self.difference_pane {
                    panes.truncate(max_panes.saturating_sub(1));
                    panes.push(self.difference_pane_kind());
                }
                panes
            }
            Layout::Difference => vec![self.difference_pane_kind()],
        };
        panes.truncate(max_panes.max(1));
        panes
    }

    /// What `pane` colours the mesh by.
    pub fn colouring(&self, pane: Pane) -> Colouring {
        match (pane, self.overlay) {
            (Pane::Difference { .. }, _) => Colouring::MethodDistance,
            (Pane::Method(_), Overlay::Shaded) => Colouring::Shaded,
            (Pane::Method(_), Overlay::Heatmap) => match self.heat_triangle {
                Some(triangle) => Colouring::TriangleWeight(triangle as u32),
                None => Colouring::CageVertexWeight(self.heat_vertex as u32),
            },
            (Pane::Method(_), Overlay::Negativity) => Colouring::MostNegativeWeight,
        }
    }

    /// The colour scale of `colouring`.
    pub fn scale_of(&self, colouring: Colouring) -> Scale {
        match colouring {
            Colouring::MostNegativeWeight => self.negativity_scale,
            _ => self.scale,
        }
    }

    /// The scale the toolbar's Linear/Log buttons set: the negativity view's while
    /// it is shown, the shared one otherwise.
    pub fn overlay_scale_mut(&mut self) -> &mut Scale {
        match self.overlay {
            Overlay::Negativity => &mut self.negativity_scale,
            _ => &mut self.scale,
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

/// Range over the mesh of each vertex's most negative (smallest) weight among its
/// first `vertex_columns` (the cage vertices' columns), leaving out the rows in
/// `outside` (ascending): their weights follow the outside policy, not the
/// family, and the negativity view paints them apart.
pub fn row_minimum_range(
    weights: &Weights,
    vertex_columns: usize,
    stride: usize,
    outside: &[u32],
) -> Option<ValueRange> {
    let columns = vertex_columns.min(weights.cols);
    if columns == 0 {
        return None;
    }
    let stride = stride.max(1);
    ValueRange::of(
        weights
            .values
            .chunks_exact(weights.cols)
            .enumerate()
            .filter(|(row, _)| outside.binary_search(&(*row as u32)).is_err())
            .map(|(_, row)| {
                (row[..columns].iter().step_by(stride).copied()).fold(f32::INFINITY, f32::min)
            }),
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

/// Mesh positions `rest` moved by `weights` and the columns' moves, in f32
/// scene coordinates (relative to `origin`) as drawn.
pub fn deform(
    weights: &Weights,
    rest: &[DVec3],
    moves: &crate::coords::ColumnMoves,
    origin: crate::render::SceneOrigin,
) -> Vec<Vec3> {
    weights
        .apply_moves(rest, moves)
        .iter()
        .map(|&p| origin.to_scene(p))
        .collect()
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
    /// The read-out of mesh vertex `vertex` over its first `vertex_columns`
    /// weights, those of the cage vertices.
    pub fn new(
        weights: &Weights,
        method: Method,
        vertex: usize,
        vertex_columns: usize,
    ) -> Option<Self> {
        let row = weights.values.chunks_exact(weights.cols).nth(vertex)?;
        let row = &row[..vertex_columns.min(row.len())];
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
#[path = "compare_tests.rs"]
mod tests;
