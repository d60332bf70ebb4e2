//! The coordinate families the product offers, described as data. The command
//! line's `--method`, the bind queue, the GPU upload, the quality table, the
//! heatmaps and the view selector all iterate over [`Method::ALL`] and read
//! [`Method::spec`]; none of them names a family.
//!
//! Adding a family: write its module in `coords`, add a variant here with its
//! [`FamilySpec`], and dispatch to it in [`super::bind_cpu`] (a whole-scene solve)
//! or [`super::weights_at`] (one row at a time); if it has more columns than cage
//! vertices, also in [`Method::columns`] and [`Method::column_displacements`].

pub use super::parameter::{
    decimal, signed_decimal, NamedValue, Parameter, ParameterError, ParameterSpec,
};
use super::parameter::{BBW_GRID, GRID, LBC_GRID, RESOLUTION};
use crate::geometry::Cage;
use glam::DVec3;

/// A family of generalised barycentric coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Method {
    /// Mean value coordinates (Ju, Schaefer, Warren 2005), closed form; on bilinear
    /// quads, QMVC (Thiery, Memari, Boubekeur 2018).
    Mvc,
    /// Positive mean value coordinates (Lipman et al. 2007), by cube-map integration.
    Pmvc,
    /// Harmonic coordinates (Joshi et al. 2007), by a grid solve of Laplace's equation.
    Harmonic,
    /// Green coordinates (Lipman, Levin, Cohen-Or 2008), closed form: one column per
    /// cage vertex (φ) and one per cage triangle (ψ); on bilinear quads, QGC
    /// (Thiery and Boubekeur 2022): four ψ per quad.
    Green,
    /// Maximum entropy coordinates (Hormann and Sukumar 2008), by a convex
    /// minimisation in three unknowns per point.
    Mec,
    /// Maximum likelihood coordinates (Chang, Deng, Hormann 2023), by a convex
    /// maximisation in three unknowns per point.
    Mlc,
    /// Bounded biharmonic weights (Jacobson, Baran, Popović, Sorkine 2011), by a
    /// bound-constrained quadratic programme per cage vertex on the harmonic
    /// solve's grid.
    Bbw,
    /// Local barycentric coordinates (Zhang, Deng, Hormann, Zheng 2014), by a
    /// total-variation minimisation of every cage vertex's weight together,
    /// subject to the barycentric constraints, on the harmonic solve's grid.
    Lbc,
    /// Somigliana coordinates (Chen, de Goes, Desbrun 2023), the global variant:
    /// a 3×3 block per cage vertex and per triangle, by boundary integrals of the
    /// elastic kernels ([`super::somigliana`]).
    Somigliana,
}

/// What a family's weights matrix holds per mesh vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColumnLayout {
    /// One weight per cage vertex.
    CageVertices,
    /// One per cage vertex, then one per cage triangle in [`Cage::triangles`] order
    /// (Green coordinates' φ, then ψ). On a cage bound with quads (QGC): one per
    /// lone triangle ([`Cage::lone_triangles`]), then four per quad, one per
    /// corner in the quad's order ([`super::green::face_columns`]).
    CageVerticesThenTriangles,
    /// A 3×3 block per cage vertex, then per cage triangle in [`Cage::triangles`]
    /// order, each as 9 columns, row-major (Somigliana coordinates:
    /// [`super::somigliana`]).
    BlocksPerVertexThenTriangle,
}

impl ColumnLayout {
    /// Columns per cage vertex (and per cage triangle where there are triangle
    /// columns): 9 for 3×3 blocks, else 1.
    pub fn columns_per_element(self) -> usize {
        match self {
            ColumnLayout::BlocksPerVertexThenTriangle => super::somigliana::BLOCK_COLUMNS,
            _ => 1,
        }
    }

    /// The column a heatmap of cage vertex `vertex` shows: its weight, or the
    /// first entry (x from x) of its block, which sums to 1 over the vertices.
    pub fn vertex_function_column(self, vertex: usize) -> usize {
        self.columns_per_element() * vertex
    }

    /// The column a heatmap of cage triangle `triangle` shows, on a cage of
    /// `cage_vertices` vertices: Green's ψ of it, or the first entry of its
    /// face block; `None` for a layout with no triangle columns.
    pub fn triangle_function_column(self, cage_vertices: usize, triangle: usize) -> Option<usize> {
        let per = self.columns_per_element();
        match self {
            ColumnLayout::CageVertices => None,
            _ => Some(per * (cage_vertices + triangle)),
        }
    }

    /// How a heatmap names a vertex's function and a triangle's ("λ", "ψ").
    pub fn function_symbols(self) -> (&'static str, &'static str) {
        match self {
            ColumnLayout::BlocksPerVertexThenTriangle => ("Bxx", "Fxx"),
            _ => ("λ", "ψ"),
        }
    }
}

/// What a family does with a cage's quads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QuadSupport {
    /// Quads are bilinear patches; on a cage with quads the family is called `name`.
    Patches { name: &'static str },
    /// Only triangles: quads are split along a diagonal, with a notice saying so.
    Triangles,
}

/// Everything the product needs to know about a family to offer it.
#[derive(Clone, Copy, Debug)]
pub struct FamilySpec {
    /// Lower-case identifier: the `--method` value and the name in saved files.
    pub id: &'static str,
    /// Display name, e.g. "PMVC".
    pub name: &'static str,
    /// One line for menus and `--help`.
    pub summary: &'static str,
    /// The parameter of its bind (PMVC's resolution, ν), if it has one.
    pub parameter: Option<ParameterSpec>,
    /// Settings read when its weights deform a pose, not when they are bound
    /// (Somigliana's bulging): changing one binds nothing again.
    pub deform_parameters: &'static [ParameterSpec],
    pub columns: ColumnLayout,
    /// Whether the family promises non-negative weights inside the cage (so a
    /// negative weight there is a defect, not a property).
    pub positive_inside: bool,
    /// How a mesh vertex outside the cage is treated, in one sentence.
    pub outside_policy: &'static str,
    /// Whether each weights row depends only on its own point, so that a large
    /// bind can be computed and written in blocks of rows. False for a family
    /// that solves once for the whole cage (harmonic coordinates' grid).
    pub rows_independent: bool,
    /// Whether a bind at the default parameter takes seconds, not minutes, on
    /// a cage of a few hundred vertices: the families `pmvc check`'s split
    /// report and `pmvc bench`'s shared-data rows bind unasked (LBC's
    /// iterations take minutes there, as do Somigliana coordinates'
    /// quadratures: about 37 µs per point and cage triangle on one core).
    pub quick_to_bind: bool,
    pub quads: QuadSupport,
    /// Why a family of [`QuadSupport::Triangles`] cannot take quads, for its notice.
    pub quads_reason: &'static str,
}

/// PMVC's default cube-map resolution (texels along one face edge).
pub const DEFAULT_RESOLUTION: u32 = 32;

/// PMVC's resolution "exact": the visible cage integrated in closed form, with
/// no cube map ([`super::exact_pmvc`]).
pub const EXACT_RESOLUTION: u32 = 0;

// The distance is mvc::FAR_FIELD_DIAGONALS; a test keeps the two in step.
const OUTSIDE_BY_MVC: &str = "vertices outside the cage get MVC weights (their affine \
     extension beyond 4 cage diagonals), which sum to one and reproduce their points";

const MVC: FamilySpec = FamilySpec {
    id: "mvc",
    name: "MVC",
    summary: "mean value coordinates, closed form (QMVC on quads); negative in non-convex cages",
    parameter: None,
    deform_parameters: &[],
    columns: ColumnLayout::CageVertices,
    positive_inside: false,
    outside_policy: OUTSIDE_BY_MVC,
    quick_to_bind: true,
    rows_independent: true,
    quads: QuadSupport::Patches { name: "QMVC" },
    quads_reason: "",
};

const PMVC: FamilySpec = FamilySpec {
    id: "pmvc",
    name: "PMVC",
    summary: "positive mean value coordinates: only the visible cage counts (cube map, or exact)",
    parameter: Some(RESOLUTION),
    deform_parameters: &[],
    columns: ColumnLayout::CageVertices,
    positive_inside: true,
    outside_policy: OUTSIDE_BY_MVC,
    quick_to_bind: true,
    rows_independent: true,
    quads: QuadSupport::Patches { name: "PMVC" },
    quads_reason: "",
};

const HARMONIC: FamilySpec = FamilySpec {
    id: "harmonic",
    name: "HC",
    summary: "harmonic coordinates: a grid solve of Laplace's equation inside the cage",
    parameter: Some(GRID),
    deform_parameters: &[],
    columns: ColumnLayout::CageVertices,
    positive_inside: true,
    outside_policy: OUTSIDE_BY_MVC,
    quick_to_bind: true,
    rows_independent: false,
    quads: QuadSupport::Patches { name: "HC" },
    quads_reason: "",
};

const GREEN: FamilySpec = FamilySpec {
    id: "green",
    name: "Green",
    summary: "Green coordinates: shape-preserving, one weight per cage vertex and per triangle; not positive",
    parameter: None,
    deform_parameters: &[],
    columns: ColumnLayout::CageVerticesThenTriangles,
    positive_inside: false,
    outside_policy: "vertices outside the cage get Green's exterior extension: the inside \
         coordinates continued through the nearest cage triangle, exact at rest and continuous across it",
    quick_to_bind: true,
    rows_independent: true,
    quads: QuadSupport::Patches { name: "QGC" },
    quads_reason: "",
};

const MEC: FamilySpec = FamilySpec {
    id: "mec",
    name: "MEC",
    summary: "maximum entropy coordinates: positive and smooth, a small convex solve per point",
    parameter: None,
    deform_parameters: &[],
    columns: ColumnLayout::CageVertices,
    positive_inside: true,
    outside_policy: OUTSIDE_BY_MVC,
    quick_to_bind: true,
    rows_independent: true,
    quads: QuadSupport::Patches { name: "MEC" },
    quads_reason: "",
};

const MLC: FamilySpec = FamilySpec {
    id: "mlc",
    name: "MLC",
    summary: "maximum likelihood coordinates: positive and smooth, a small convex solve per point",
    parameter: None,
    deform_parameters: &[],
    columns: ColumnLayout::CageVertices,
    positive_inside: true,
    outside_policy: OUTSIDE_BY_MVC,
    quick_to_bind: true,
    rows_independent: true,
    // Inside only vertex positions count: splitting a quad would change nothing.
    quads: QuadSupport::Patches { name: "MLC" },
    quads_reason: "",
};

const BBW: FamilySpec = FamilySpec {
    id: "bbw",
    name: "BBW",
    summary: "bounded biharmonic weights: a constrained grid solve per cage vertex, in [0, 1]",
    parameter: Some(BBW_GRID),
    deform_parameters: &[],
    columns: ColumnLayout::CageVertices,
    positive_inside: true,
    outside_policy: OUTSIDE_BY_MVC,
    quick_to_bind: true,
    rows_independent: false,
    quads: QuadSupport::Patches { name: "BBW" },
    quads_reason: "",
};

const LBC: FamilySpec = FamilySpec {
    id: "lbc",
    name: "LBC",
    summary:
        "local barycentric coordinates: a grid solve of least total variation, positive and local",
    parameter: Some(LBC_GRID),
    deform_parameters: &[],
    columns: ColumnLayout::CageVertices,
    positive_inside: true,
    outside_policy: OUTSIDE_BY_MVC,
    quick_to_bind: false,
    rows_independent: false,
    quads: QuadSupport::Patches { name: "LBC" },
    quads_reason: "",
};

const SOMIGLIANA: FamilySpec = FamilySpec {
    id: "somigliana",
    name: "Somigliana",
    summary: "Somigliana coordinates: elasticity-based, a 3×3 block per cage vertex and triangle; not positive",
    parameter: Some(super::somigliana::POISSON_RATIO_SETTING),
    deform_parameters: &[
        super::somigliana::BULGING_SETTING,
        super::somigliana::LOCAL_BLEND_SETTING,
    ],
    columns: ColumnLayout::BlocksPerVertexThenTriangle,
    positive_inside: false,
    outside_policy: "vertices outside the cage (or on it) get MVC weights (the triangle's barycentrics \
         on it) as identity blocks with no face term, so they follow MVC's deformation of the cage",
    quick_to_bind: false,
    rows_independent: true,
    quads: QuadSupport::Triangles,
    quads_reason: "the tractions are constant per triangle",
};

impl Method {
    /// Every family, in the order menus list them.
    pub const ALL: [Method; 9] = [
        Method::Mvc,
        Method::Pmvc,
        Method::Harmonic,
        Method::Green,
        Method::Mec,
        Method::Mlc,
        Method::Bbw,
        Method::Lbc,
        Method::Somigliana,
    ];

    pub fn spec(self) -> &'static FamilySpec {
        match self {
            Method::Mvc => &MVC,
            Method::Pmvc => &PMVC,
            Method::Harmonic => &HARMONIC,
            Method::Green => &GREEN,
            Method::Mec => &MEC,
            Method::Mlc => &MLC,
            Method::Bbw => &BBW,
            Method::Lbc => &LBC,
            Method::Somigliana => &SOMIGLIANA,
        }
    }

    pub fn name(self) -> &'static str {
        self.spec().name
    }

    pub fn id(self) -> &'static str {
        self.spec().id
    }

    /// The family with identifier `id` (case-insensitive).
    pub fn from_id(id: &str) -> Option<Method> {
        Method::ALL
            .into_iter()
            .find(|method| method.id().eq_ignore_ascii_case(id))
    }

    /// The family after this one in [`Method::ALL`], wrapping around (the M key).
    pub fn next(self) -> Method {
        let index = Method::ALL.iter().position(|&m| m == self).unwrap_or(0);
        Method::ALL[(index + 1) % Method::ALL.len()]
    }

    /// Weights columns per mesh vertex for `cage`.
    pub fn columns(self, cage: &Cage) -> usize {
        match self.spec().columns {
            ColumnLayout::CageVertices => cage.vertex_count(),
            ColumnLayout::CageVerticesThenTriangles => {
                cage.vertex_count() + super::green::face_columns(cage)
            }
            ColumnLayout::BlocksPerVertexThenTriangle => super::somigliana::column_count(cage),
        }
    }

    /// The vector each weights column multiplies at rest: the cage positions, then
    /// for Green coordinates each triangle's unit outward normal (on a cage with
    /// quads, QGC: each lone triangle's, then each quad's four corner normals
    /// `Nₖ`). A row reproduces its point when Σₖ wₖ cₖ equals it (linear precision).
    pub fn rest_columns(self, rest: &Cage) -> Vec<DVec3> {
        if self.spec().columns == ColumnLayout::BlocksPerVertexThenTriangle {
            return super::somigliana::rest_columns(rest);
        }
        let mut columns = rest.positions().to_vec();
        if self.spec().columns == ColumnLayout::CageVerticesThenTriangles {
            columns.extend(super::green::rest_face_vectors(rest));
        }
        columns
    }

    /// Per weights column, how far its vector moved from `rest` to `pose`; a mesh
    /// vertex then moves by Σₖ wₖ dₖ (the displacement form, exact at rest for any
    /// weights). For a cage vertex's column this is `pose − rest`; for a triangle's
    /// (Green coordinates) it is `sⱼ nⱼ' − nⱼ`, the stretched deformed normal less
    /// the rest normal, and for a quad corner's (QGC) `σₖ Nₖ' − Nₖ`. A pose of the
    /// wrong length moves nothing.
    pub fn column_displacements(self, rest: &Cage, pose: &[DVec3]) -> Vec<DVec3> {
        if self.spec().columns == ColumnLayout::BlocksPerVertexThenTriangle {
            // Without bulging, the tractions do not depend on ν.
            return super::somigliana::column_displacements(rest, pose, 0.0, 0.0);
        }
        let mut moves: Vec<DVec3> = pose
            .iter()
            .zip(rest.positions())
            .map(|(posed, rested)| *posed - *rested)
            .collect();
        if self.spec().columns == ColumnLayout::CageVerticesThenTriangles {
            match super::green::qgc_face_vectors(rest, pose) {
                Ok(faces) => moves.extend(
                    faces
                        .into_iter()
                        .zip(super::green::rest_face_vectors(rest))
                        .map(|(posed, rested)| posed - rested),
                ),
                Err(_) => moves.resize(self.columns(rest), DVec3::ZERO),
            }
        }
        moves
    }

    /// Columns that belong to cage vertices: where partition of unity and
    /// positivity are measured (Green coordinates' ψ columns are neither).
    pub fn vertex_columns(self, cage: &Cage) -> usize {
        self.spec().columns.columns_per_element() * cage.vertex_count()
    }
}

/// Saved files name a family by its identifier ("pmvc"), so adding or reordering
/// families never changes what an old file means.
impl serde::Serialize for Method {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.id())
    }
}

impl<'de> serde::Deserialize<'de> for Method {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let id = String::deserialize(deserializer)?;
        Method::from_id(&id).ok_or_else(|| {
            let known: Vec<&str> = Method::ALL.iter().map(|m| m.id()).collect();
            serde::de::Error::custom(format!(
                "unknown method \"{id}\" (known: {})",
                known.join(", ")
            ))
        })
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
#[path = "family_tests.rs"]
mod tests;
