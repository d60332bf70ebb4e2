//! What one view shows and how: the family, the colouring and its scale, and the
//! camera of a frame. Plain values that the editor fills in and the orchestrator
//! ([`super::viewport`]) turns into the frame uniform.

use super::colormap::Scale;
use crate::coords::family::ColumnLayout;
use crate::coords::{Method, WeightsId};
use glam::{Mat4, Vec3};

/// What the mesh is coloured by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Colouring {
    /// Plain shading.
    #[default]
    Shaded,
    /// Cage vertex i's function: its weight λᵢ (or its block's first entry,
    /// [`ColumnLayout::vertex_function_column`]).
    CageVertexWeight(u32),
    /// Cage triangle j's function: Green coordinates' ψⱼ (or a face block's
    /// first entry); a family without triangle columns shows the mesh shaded.
    TriangleWeight(u32),
    /// minⱼ λⱼ per mesh vertex: where the coordinates go negative.
    MostNegativeWeight,
    /// |p′ − p′_against| between two families' deformations, over the cage size.
    MethodDistance,
}

impl Colouring {
    /// The shader's `COLOURING_*` constant and the column it shows, for weights
    /// of `columns` columns laid out as `layout` on a cage of `cage_vertices`
    /// vertices.
    pub(super) fn code(self, layout: ColumnLayout, cage_vertices: u32, columns: u32) -> [u32; 2] {
        let shown = |column: Option<usize>| match column.and_then(|c| u32::try_from(c).ok()) {
            Some(column) if column < columns => [1, column],
            _ => [0, 0],
        };
        match self {
            Colouring::Shaded => [0, 0],
            Colouring::CageVertexWeight(vertex) => {
                shown(Some(layout.vertex_function_column(vertex as usize)))
            }
            Colouring::TriangleWeight(triangle) => {
                shown(layout.triangle_function_column(cage_vertices as usize, triangle as usize))
            }
            Colouring::MostNegativeWeight => [2, 0],
            Colouring::MethodDistance => [3, 0],
        }
    }
}

/// How one view colours the mesh, and with which method's weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shading {
    /// The weights the mesh is deformed (and coloured) with.
    pub method: Method,
    /// The weights compared with in the difference view ([`Colouring::MethodDistance`]):
    /// another family, or the shown family's triangulated twin.
    pub against: Option<WeightsId>,
    pub colouring: Colouring,
    pub scale: Scale,
    /// Magnitude at which the colour map saturates.
    pub colour_limit: f32,
    /// Distances of [`Colouring::MethodDistance`] are divided by this.
    pub cage_size: f32,
}

impl Default for Shading {
    fn default() -> Self {
        Self {
            method: Method::Pmvc,
            against: None,
            colouring: Colouring::Shaded,
            scale: Scale::Linear,
            colour_limit: 1.0,
            cage_size: 1.0,
        }
    }
}

/// Per-frame camera settings, carried by the paint callback.
#[derive(Clone, Copy, Debug)]
pub struct FrameParams {
    /// Which view this is, below [`MAX_VIEWS`].
    pub view: usize,
    pub shading: Shading,
    pub view_projection: Mat4,
    pub eye: Vec3,
    /// Viewport size in physical pixels.
    pub size_px: [u32; 2],
    pub handle_radius_px: f32,
    pub highlight_outside: bool,
    /// Draw the cage's edges and handles over the mesh.
    pub show_cage: bool,
    /// Draw the mesh's edges over it.
    pub wireframe: bool,
    /// Light with per-vertex normals of the deformed mesh (else per face).
    pub smooth_shading: bool,
}
