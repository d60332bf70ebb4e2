//! The coordinate families the product offers, described as data. The command
//! line's `--method`, the bind queue, the GPU upload, the quality table, the
//! heatmaps and the view selector all iterate over [`Method::ALL`] and read
//! [`Method::spec`]; none of them names a family.
//!
//! Adding a family: write its module in `coords`, add a variant here with its
//! [`FamilySpec`], and dispatch to it in [`super::bind_cpu`] (a whole-scene solve)
//! or [`super::weights_at`] (one row at a time); if it has more columns than cage
//! vertices, also in [`Method::columns`] and [`Method::column_displacements`].

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
    /// Somigliana coordinates (Chen, de Goes, Desbrun 2023), the global variant:
    /// a 3×3 block per cage vertex and per triangle, by boundary integrals of the
    /// elastic kernels ([`super::somigliana`]).
    Somigliana,
}

/// A family's one parameter (a resolution, a grid size, a Poisson ratio), held
/// as a whole number of `1/scale` units.
#[derive(Clone, Copy, Debug)]
pub struct ParameterSpec {
    /// Which field of [`super::BindOptions`] holds it.
    pub key: Parameter,
    /// Shown beside its control, e.g. "PMVC resolution".
    pub label: &'static str,
    /// The command-line flag, e.g. "--resolution".
    pub flag: &'static str,
    /// The values the editor offers.
    pub choices: &'static [u32],
    pub default: u32,
    /// The smallest and largest values accepted from any source ([`Self::validate`]).
    pub min: u32,
    pub max: u32,
    /// Values outside `min..=max` that mean something else, by name
    /// (PMVC's "exact": no cube map).
    pub named: &'static [NamedValue],
    /// How a value reads in titles, e.g. "32²" or "exact".
    pub format: fn(u32) -> String,
    /// Units per one: 1 for whole numbers, 1000 for a value in thousandths
    /// (read and written as a decimal, "0.3").
    pub scale: u32,
}

/// A parameter value with a name, written and read as that name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NamedValue {
    pub value: u32,
    pub name: &'static str,
}

/// A parameter value outside its family's range.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "{id} {} is out of range: the {label} must be {} to {}{}",
    decimal(*.value, *.scale),
    decimal(u64::from(*.min), *.scale),
    decimal(u64::from(*.max), *.scale),
    or_named(named)
)]
pub struct ParameterError {
    /// The name saved files give it ("resolution").
    pub id: &'static str,
    pub label: &'static str,
    pub value: u64,
    pub min: u32,
    pub max: u32,
    pub named: &'static [NamedValue],
    pub scale: u32,
}

/// `value` units of `1/scale` as a decimal: "0.3" for 300 thousandths.
pub fn decimal(value: u64, scale: u32) -> String {
    if scale <= 1 {
        return value.to_string();
    }
    let digits = scale.ilog10() as usize;
    let text = format!(
        "{}.{:0digits$}",
        value / u64::from(scale),
        value % u64::from(scale)
    );
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// `, or "exact"` after a range, for a parameter with named values.
fn or_named(named: &[NamedValue]) -> String {
    named
        .iter()
        .map(|named| format!(", or \"{}\"", named.name))
        .collect()
}

impl ParameterSpec {
    /// The one check of a value, wherever it comes from (the command line, a
    /// session, the editor's controls): `value` when it is in `min..=max` or
    /// one of the named values.
    pub fn validate(&self, value: u64) -> Result<u32, ParameterError> {
        match u32::try_from(value) {
            Ok(value) if (self.min..=self.max).contains(&value) => Ok(value),
            Ok(value) if self.named.iter().any(|named| named.value == value) => Ok(value),
            _ => Err(self.out_of_range(value)),
        }
    }

    fn out_of_range(&self, value: u64) -> ParameterError {
        ParameterError {
            id: self.key.id(),
            label: self.label,
            value,
            min: self.min,
            max: self.max,
            named: self.named,
            scale: self.scale,
        }
    }

    /// The one reading of a value from text (the command line, Python, saved
    /// files): a whole number checked by [`Self::validate`], or a value's name.
    pub fn parse(&self, text: &str) -> Result<u32, String> {
        let text = text.trim();
        if let Some(named) = self
            .named
            .iter()
            .find(|n| n.name.eq_ignore_ascii_case(text))
        {
            return Ok(named.value);
        }
        if self.scale > 1 {
            return self.parse_decimal(text);
        }
        let value: u64 = text.parse().map_err(|_| {
            format!(
                "'{text}' is not a whole number{}",
                or_named(self.named).replacen(',', "", 1)
            )
        })?;
        self.validate_number(value)
            .map_err(|error| error.to_string())
    }

    /// A decimal (`scale` > 1) in units of `1/scale`: "0.3" is 300 thousandths.
    fn parse_decimal(&self, text: &str) -> Result<u32, String> {
        let number: f64 = match text.parse() {
            Ok(number) if f64::is_finite(number) => number,
            _ => return Err(format!("'{text}' is not a number")),
        };
        self.validate_decimal(number)
            .map_err(|error| error.to_string())
    }

    /// A decimal value checked as [`Self::validate_number`], in `1/scale`
    /// units, rounded to the nearest; below zero it is out of range.
    pub fn validate_decimal(&self, number: f64) -> Result<u32, String> {
        let units = (number * f64::from(self.scale)).round();
        if !(units >= 0.0 && units <= f64::from(u32::MAX)) {
            return Err(format!(
                "{} {number} is out of range: the {} must be {} to {}",
                self.key.id(),
                self.label,
                decimal(self.min.into(), self.scale),
                decimal(self.max.into(), self.scale)
            ));
        }
        self.validate_number(units as u64)
            .map_err(|error| error.to_string())
    }

    /// [`Self::validate`] of a value given as a number by a user: a named
    /// value is given by its name, so its code (PMVC's exact is 0) is refused.
    pub fn validate_number(&self, value: u64) -> Result<u32, ParameterError> {
        match u32::try_from(value) {
            Ok(value) if (self.min..=self.max).contains(&value) => Ok(value),
            _ => Err(self.out_of_range(value)),
        }
    }

    /// The name of `value`, if it is a named one.
    pub fn name_of(&self, value: u32) -> Option<&'static str> {
        self.named
            .iter()
            .find(|named| named.value == value)
            .map(|named| named.name)
    }
}

/// The parameters families can have; each is a field of [`super::BindOptions`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Parameter {
    /// Cube-map texels along one face edge (PMVC).
    Resolution,
    /// Grid cells along the cage's longest side (harmonic coordinates, BBW).
    Grid,
    /// The material's Poisson ratio in thousandths (Somigliana coordinates).
    PoissonRatio,
}

impl Parameter {
    pub const ALL: [Parameter; 3] = [
        Parameter::Resolution,
        Parameter::Grid,
        Parameter::PoissonRatio,
    ];

    /// The name saved files give it.
    pub fn id(self) -> &'static str {
        match self {
            Parameter::Resolution => "resolution",
            Parameter::Grid => "grid",
            Parameter::PoissonRatio => "poisson_ratio",
        }
    }

    /// Its spec: label, flag, range and the editor's choices.
    pub fn spec(self) -> &'static ParameterSpec {
        match self {
            Parameter::Resolution => &RESOLUTION,
            Parameter::Grid => &GRID,
            Parameter::PoissonRatio => &super::somigliana::POISSON_RATIO_SETTING,
        }
    }

    /// [`ParameterSpec::validate`] of this parameter.
    pub fn validate(self, value: u64) -> Result<u32, ParameterError> {
        self.spec().validate(value)
    }
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
    pub parameter: Option<ParameterSpec>,
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
    columns: ColumnLayout::CageVertices,
    positive_inside: false,
    outside_policy: OUTSIDE_BY_MVC,
    rows_independent: true,
    quads: QuadSupport::Patches { name: "QMVC" },
    quads_reason: "",
};

/// PMVC's cube-map resolution. Past 1024 the six faces of one point's cube map
/// alone are 24 MiB and a bind of a real mesh takes hours.
const RESOLUTION: ParameterSpec = ParameterSpec {
    key: Parameter::Resolution,
    label: "PMVC resolution",
    flag: "--resolution",
    choices: &[16, 32, 64, 128, EXACT_RESOLUTION],
    default: DEFAULT_RESOLUTION,
    min: 1,
    max: 1024,
    named: &[NamedValue {
        value: EXACT_RESOLUTION,
        name: "exact",
    }],
    format: |value| match value {
        EXACT_RESOLUTION => "exact".to_owned(),
        side => format!("{side}²"),
    },
    scale: 1,
};

/// Harmonic coordinates' grid: fewer than `MIN_GRID` cells cannot resolve a
/// cage; 2048 cells along the longest side is already billions of nodes.
const GRID: ParameterSpec = ParameterSpec {
    key: Parameter::Grid,
    label: "harmonic grid",
    flag: "--grid",
    choices: &[32, 64, 128],
    default: super::harmonic::DEFAULT_GRID,
    min: super::harmonic::MIN_GRID,
    max: 2048,
    named: &[],
    format: |value| format!("grid {value}"),
    scale: 1,
};

/// Bounded biharmonic weights' grid: the `--grid` of harmonic coordinates, with
/// a smaller default, since the factor of the biharmonic system grows about as
/// the grid's fourth power (a cube cage at grid 32 factorises into 45 million
/// entries, 360 MB).
const BBW_GRID: ParameterSpec = ParameterSpec {
    label: "BBW grid",
    choices: &[16, 32, 48],
    default: super::bbw::DEFAULT_GRID,
    ..GRID
};

const PMVC: FamilySpec = FamilySpec {
    id: "pmvc",
    name: "PMVC",
    summary: "positive mean value coordinates: only the visible cage counts (cube map, or exact)",
    parameter: Some(RESOLUTION),
    columns: ColumnLayout::CageVertices,
    positive_inside: true,
    outside_policy: OUTSIDE_BY_MVC,
    rows_independent: true,
    quads: QuadSupport::Patches { name: "PMVC" },
    quads_reason: "",
};

const HARMONIC: FamilySpec = FamilySpec {
    id: "harmonic",
    name: "HC",
    summary: "harmonic coordinates: a grid solve of Laplace's equation inside the cage",
    parameter: Some(GRID),
    columns: ColumnLayout::CageVertices,
    positive_inside: true,
    outside_policy: OUTSIDE_BY_MVC,
    rows_independent: false,
    quads: QuadSupport::Patches { name: "HC" },
    quads_reason: "",
};

const GREEN: FamilySpec = FamilySpec {
    id: "green",
    name: "Green",
    summary: "Green coordinates: shape-preserving, one weight per cage vertex and per triangle; not positive",
    parameter: None,
    columns: ColumnLayout::CageVerticesThenTriangles,
    positive_inside: false,
    outside_policy: "vertices outside the cage get Green's exterior extension: the inside \
         coordinates continued through the nearest cage triangle, exact at rest and continuous across it",
    rows_independent: true,
    quads: QuadSupport::Patches { name: "QGC" },
    quads_reason: "",
};

const MEC: FamilySpec = FamilySpec {
    id: "mec",
    name: "MEC",
    summary: "maximum entropy coordinates: positive and smooth, a small convex solve per point",
    parameter: None,
    columns: ColumnLayout::CageVertices,
    positive_inside: true,
    outside_policy: OUTSIDE_BY_MVC,
    rows_independent: true,
    quads: QuadSupport::Patches { name: "MEC" },
    quads_reason: "",
};

const MLC: FamilySpec = FamilySpec {
    id: "mlc",
    name: "MLC",
    summary: "maximum likelihood coordinates: positive and smooth, a small convex solve per point",
    parameter: None,
    columns: ColumnLayout::CageVertices,
    positive_inside: true,
    outside_policy: OUTSIDE_BY_MVC,
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
    columns: ColumnLayout::CageVertices,
    positive_inside: true,
    outside_policy: OUTSIDE_BY_MVC,
    rows_independent: false,
    quads: QuadSupport::Patches { name: "BBW" },
    quads_reason: "",
};

const SOMIGLIANA: FamilySpec = FamilySpec {
    id: "somigliana",
    name: "Somigliana",
    summary: "Somigliana coordinates: elasticity-based, a 3×3 block per cage vertex and triangle; not positive",
    parameter: Some(super::somigliana::POISSON_RATIO_SETTING),
    columns: ColumnLayout::BlocksPerVertexThenTriangle,
    positive_inside: false,
    outside_policy: "vertices outside the cage (or on it) get MVC weights (the triangle's barycentrics \
         on it) as identity blocks with no face term, so they follow MVC's deformation of the cage",
    rows_independent: true,
    quads: QuadSupport::Triangles,
    quads_reason: "the tractions are constant per triangle",
};

impl Method {
    /// Every family, in the order menus list them.
    pub const ALL: [Method; 8] = [
        Method::Mvc,
        Method::Pmvc,
        Method::Harmonic,
        Method::Green,
        Method::Mec,
        Method::Mlc,
        Method::Bbw,
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
            return super::somigliana::column_displacements(rest, pose);
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
        match self.spec().columns {
            ColumnLayout::BlocksPerVertexThenTriangle => {
                super::somigliana::BLOCK_COLUMNS * cage.vertex_count()
            }
            _ => cage.vertex_count(),
        }
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
