//! What a reader needs to trust a weights file, written beside it: `W.json` says
//! which family and parameters made `W.npy` (or Green's `W.npz`), where and how
//! long it took, what each column is, and which inputs it belongs to;
//! `W.classes.npy` gives every row's class (inside, on the cage, outside), so
//! that rows a family filled by its outside policy can be told from the rest.
//! The command line and the Python package both read and write them here.

use super::npy::{
    npy_preamble_of, read_npy, read_npy_f64, write_values, ExpectedArray, LeBytes, NpyError,
};
use super::npz::{read_npz, read_npz_f64, write_npz_values};
use crate::coords::family::ColumnLayout;
use crate::coords::{AnyWeights, BindOptions, Dtype, Method, ParameterError, Weights};
use crate::formats::{shown_path, OutputSet, WriteError};
use crate::geometry::{Cage, PointClass, QuadSplit};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

mod classes;
mod sets;
pub use classes::{
    class_code, class_codes, classes_path, read_classes_npy, write_classes_npy_to, CLASS_INSIDE,
    CLASS_ON_CAGE, CLASS_OUTSIDE,
};
pub use sets::{
    load_any_weights_set, load_weights_set, save_any_weights_set, save_weights_set,
    LoadedAnyWeights, LoadedWeights,
};

/// The `format` field of every metadata file.
pub const FORMAT: &str = "pmvc-weights";
/// Raised when a field changes meaning; readers refuse versions they do not know.
pub const FORMAT_VERSION: u32 = 1;

/// A metadata file is a few kilobytes plus Green's triangle list; more than this
/// is not one.
const METADATA_LIMIT: u64 = 64 << 20;

/// `W.json` for weights `W.npy` or `W.npz`.
pub fn metadata_path(weights: &Path) -> PathBuf {
    weights.with_extension("json")
}

/// A content digest of positions (FNV-1a, 64 bits, over their f64 little-endian
/// bytes), to tell whether weights belong to a mesh or cage. Not cryptographic:
/// it guards against mixing files up, not against forgery.
pub fn positions_digest(points: &[DVec3]) -> String {
    let bytes = points
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(f64::to_le_bytes);
    format!("fnv1a64:{:016x}", fnv1a(bytes))
}

/// [`positions_digest`] of a cage's vertices, then its triangles' corners, so that
/// the same vertices joined differently differ.
pub fn cage_digest(cage: &Cage) -> String {
    let positions = cage
        .positions()
        .iter()
        .flat_map(|p| p.to_array())
        .flat_map(f64::to_le_bytes);
    let corners = cage
        .triangles()
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes());
    format!("fnv1a64:{:016x}", fnv1a(positions.chain(corners)))
}

fn fnv1a(bytes: impl Iterator<Item = u8>) -> u64 {
    bytes.fold(0xcbf2_9ce4_8422_2325, |hash, byte| {
        (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The class mask's record in the metadata: its file, what the codes mean, and
/// how many rows have each.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClassesRecord {
    /// The mask's file name, beside the metadata.
    pub file: String,
    pub codes: BTreeMap<String, String>,
    pub inside: usize,
    pub on_cage: usize,
    pub outside: usize,
}

/// The points that were bound.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MeshRecord {
    pub file: String,
    /// The object of the file that was bound, where one was named
    /// (`--mesh-object`, a Blender object).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object: Option<String>,
    pub points: usize,
    /// [`positions_digest`] of the points.
    pub digest: String,
}

/// The cage the weights refer to.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CageRecord {
    pub file: String,
    /// The object of the file that is the cage, where one was named.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object: Option<String>,
    pub vertices: usize,
    /// Triangles after quads and polygons were split ([`Cage::triangles`]).
    pub triangles: usize,
    /// The file's quads, bilinear patches unless `quad_split` split them.
    #[serde(default)]
    pub quads: usize,
    /// [`cage_digest`] of the cage.
    pub digest: String,
}

/// Everything `W.json` holds. Field names are the JSON's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WeightsMetadata {
    pub format: String,
    pub format_version: u32,
    /// "pmvc 0.1.0": the program and version that bound the weights.
    pub program: String,
    /// The family's identifier (`--method`).
    pub method: String,
    pub method_name: String,
    /// The family's own parameters and their values (none for MVC and Green).
    #[serde(with = "crate::coords::parameter_values")]
    pub parameters: BTreeMap<String, u32>,
    /// `--triangulate` as asked: "none" (quads stay bilinear patches), "shorter"
    /// or "longer". Files from before quads were patches have none and read as
    /// "none"; their cages' quads were split along the shorter diagonal.
    #[serde(default = "no_split")]
    pub quad_split: String,
    /// What the family bound the quads as, in words: "bilinear quads", or the
    /// diagonal they were split along.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub quads_bound_as: String,
    /// How the matrix is stored: "float32", or "float64" where it was asked for
    /// (`--dtype f64`, Python's `dtype=numpy.float64`). Files from before the
    /// field read as "float32", which they are.
    #[serde(default = "float32")]
    pub dtype: String,
    /// "cpu" or "gpu".
    pub backend: String,
    /// Where they were computed, in words (the adapter, or the CPU threads).
    pub device: String,
    /// Seconds the bind itself took (not loading or writing).
    pub seconds: f64,
    pub rows: usize,
    pub columns: usize,
    /// "cage_vertices", or "cage_vertices_then_triangles" (Green's φ then ψ).
    pub columns_layout: String,
    /// For Green coordinates, the triangle each ψ column refers to: column
    /// `cage.vertices + k` is `triangles[k]`, corners in the order used. For
    /// QGC (Green on a cage bound with quads), the lone triangles only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub triangles: Option<Vec<[u32; 3]>>,
    /// For QGC, the quads whose corner normals the last ψ columns multiply:
    /// after the triangles' columns, four per quad, one per corner in this order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quads: Option<Vec<[u32; 4]>>,
    /// Whether the family promises non-negative weights for inside rows.
    pub positive_inside: bool,
    /// How the family fills rows outside the cage, in one sentence.
    pub outside_policy: String,
    pub classes: ClassesRecord,
    pub mesh: MeshRecord,
    pub cage: CageRecord,
}

/// What [`WeightsMetadata::new`] records: one finished bind.
pub struct BindRecord<'a> {
    pub options: BindOptions,
    pub cage: &'a Cage,
    pub points: &'a [DVec3],
    pub classes: &'a [PointClass],
    /// "cpu" or "gpu".
    pub backend: &'a str,
    pub device: &'a str,
    pub seconds: f64,
    /// The input files as the user named them ("" for arrays from memory).
    pub mesh_file: &'a str,
    pub cage_file: &'a str,
    /// The objects of those files that were read, where one was named.
    pub mesh_object: Option<&'a str>,
    pub cage_object: Option<&'a str>,
    /// Where the weights go: the mask's name is derived from it.
    pub weights_file: &'a Path,
}

fn no_split() -> String {
    QuadSplit::None.id().to_owned()
}

fn float32() -> String {
    Dtype::Float32.id().to_owned()
}

impl WeightsMetadata {
    pub fn new(record: &BindRecord) -> Self {
        let method = record.options.method;
        let bound = record.options.cage_to_bind(record.cage);
        let quads_bound_as = match (
            record.cage.has_quads(),
            record.options.split_applied(record.cage),
        ) {
            (false, _) => String::new(),
            (true, None) => QuadSplit::None.describe().to_owned(),
            (true, Some(split)) => split.describe().to_owned(),
        };
        let spec = method.spec();
        let count = |code| {
            record
                .classes
                .iter()
                .filter(|class| class_code(class) == code)
                .count()
        };
        let layout = spec.columns;
        Self {
            format: FORMAT.to_owned(),
            format_version: FORMAT_VERSION,
            program: format!("pmvc {}", env!("CARGO_PKG_VERSION")),
            method: spec.id.to_owned(),
            method_name: record.options.family_name(record.cage),
            quad_split: record.options.quads.id().to_owned(),
            quads_bound_as,
            parameters: record
                .options
                .parameter()
                .map(|(parameter, value)| (parameter.key.id().to_owned(), value))
                .into_iter()
                .collect(),
            dtype: float32(),
            backend: record.backend.to_owned(),
            device: record.device.to_owned(),
            seconds: record.seconds,
            rows: record.points.len(),
            columns: method.columns(&bound),
            columns_layout: layout_id(layout).to_owned(),
            // The triangles that own columns, in column order.
            triangles: (layout != ColumnLayout::CageVertices).then(|| {
                bound
                    .lone_triangles()
                    .map(|t| bound.triangles()[t])
                    .collect()
            }),
            quads: (layout == ColumnLayout::CageVerticesThenTriangles && bound.has_quads())
                .then(|| bound.quads().iter().map(|quad| quad.corners).collect()),
            positive_inside: spec.positive_inside,
            outside_policy: spec.outside_policy.to_owned(),
            classes: ClassesRecord {
                file: file_name(&classes_path(record.weights_file)),
                codes: [
                    (CLASS_INSIDE, "inside"),
                    (CLASS_ON_CAGE, "on the cage"),
                    (CLASS_OUTSIDE, "outside"),
                ]
                .into_iter()
                .map(|(code, name)| (code.to_string(), name.to_owned()))
                .collect(),
                inside: count(CLASS_INSIDE),
                on_cage: count(CLASS_ON_CAGE),
                outside: count(CLASS_OUTSIDE),
            },
            mesh: MeshRecord {
                file: record.mesh_file.to_owned(),
                object: record.mesh_object.map(str::to_owned),
                points: record.points.len(),
                digest: positions_digest(record.points),
            },
            cage: CageRecord {
                file: record.cage_file.to_owned(),
                object: record.cage_object.map(str::to_owned),
                vertices: record.cage.vertex_count(),
                triangles: record.cage.triangle_count(),
                quads: record.cage.quads().len(),
                digest: cage_digest(record.cage),
            },
        }
    }

    /// The family and parameters that made the weights, each checked as the
    /// command line checks them.
    pub fn options(&self, path: &Path) -> Result<BindOptions, MetadataError> {
        let method = Method::from_id(&self.method).ok_or_else(|| MetadataError::Field {
            path: path.to_owned(),
            field: "method",
            reason: format!(
                "{:?} is not a family pmvc knows ({})",
                self.method,
                Method::ALL.map(Method::id).join(", ")
            ),
        })?;
        let mut options = BindOptions::for_method(method);
        options.quads =
            QuadSplit::from_id(&self.quad_split).ok_or_else(|| MetadataError::Field {
                path: path.to_owned(),
                field: "quad_split",
                reason: format!(
                    "{:?} is not a way to split quads ({})",
                    self.quad_split,
                    QuadSplit::ALL.map(QuadSplit::id).join(", ")
                ),
            })?;
        for (name, &value) in &self.parameters {
            let parameter = method
                .spec()
                .parameter
                .filter(|spec| spec.key.id() == name)
                .ok_or_else(|| MetadataError::Field {
                    path: path.to_owned(),
                    field: "parameters",
                    reason: format!("{} has no parameter {name:?}", method.name()),
                })?;
            let value =
                parameter
                    .validate(value.into())
                    .map_err(|source| MetadataError::Parameter {
                        path: path.to_owned(),
                        source,
                    })?;
            options.set(parameter.key, value);
        }
        Ok(options)
    }

    /// The stored dtype, checked by [`Dtype::parse`] (the parser of `--dtype`).
    pub fn checked_dtype(&self, path: &Path) -> Result<Dtype, MetadataError> {
        Dtype::parse(&self.dtype).map_err(|error| MetadataError::Field {
            path: path.to_owned(),
            field: "dtype",
            reason: error.to_string(),
        })
    }

    /// The stored dtype; float32 for a value [`Self::checked_dtype`] refuses.
    pub fn dtype(&self) -> Dtype {
        Dtype::parse(&self.dtype).unwrap_or_default()
    }

    /// Whether these weights belong to `points` and `cage`: the same number of
    /// rows and cage vertices and triangles, and the same digests.
    pub fn check_inputs(
        &self,
        path: &Path,
        points: &[DVec3],
        cage: &Cage,
    ) -> Result<(), MetadataError> {
        let mismatch = |field: &'static str, recorded: String, found: String| {
            Err(MetadataError::Mismatch {
                path: path.to_owned(),
                field,
                recorded,
                found,
            })
        };
        if self.rows != points.len() {
            return mismatch("rows", self.rows.to_string(), points.len().to_string());
        }
        if self.cage.vertices != cage.vertex_count() {
            let found = cage.vertex_count().to_string();
            return mismatch("cage.vertices", self.cage.vertices.to_string(), found);
        }
        if self.cage.triangles != cage.triangle_count() {
            let found = cage.triangle_count().to_string();
            return mismatch("cage.triangles", self.cage.triangles.to_string(), found);
        }
        let cage_found = cage_digest(cage);
        if self.cage.digest != cage_found {
            return mismatch("cage.digest", self.cage.digest.clone(), cage_found);
        }
        let mesh_found = positions_digest(points);
        if self.mesh.digest != mesh_found {
            return mismatch("mesh.digest", self.mesh.digest.clone(), mesh_found);
        }
        Ok(())
    }

    /// The metadata as indented JSON, ending in a newline.
    pub fn to_json_pretty(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).unwrap_or_default();
        text.push('\n');
        text
    }

    /// Its own fields agree with each other: the format and version are known,
    /// the family and parameters are valid, and the columns are what the family
    /// gives a cage of the recorded size.
    /// Green coordinates' ψ columns: one per triangle, or for QGC (the file
    /// lists `quads`) one per lone triangle and four per quad.
    pub fn face_columns(&self) -> usize {
        match &self.quads {
            // Each quad's two triangles give way to its four corners.
            Some(quads) => self.cage.triangles + 2 * quads.len(),
            None => self.cage.triangles,
        }
    }

    pub fn check_consistent(&self, path: &Path) -> Result<BindOptions, MetadataError> {
        let field = |field: &'static str, reason: String| MetadataError::Field {
            path: path.to_owned(),
            field,
            reason,
        };
        if self.format != FORMAT {
            return Err(field(
                "format",
                format!("is {:?}, not {FORMAT:?}", self.format),
            ));
        }
        if self.format_version != FORMAT_VERSION {
            return Err(field(
                "format_version",
                format!(
                    "is {}; this pmvc reads version {FORMAT_VERSION}",
                    self.format_version
                ),
            ));
        }
        let options = self.options(path)?;
        self.checked_dtype(path)?;
        let layout = options.method.spec().columns;
        let expected = match layout {
            ColumnLayout::CageVertices => self.cage.vertices,
            ColumnLayout::CageVerticesThenTriangles => self.cage.vertices + self.face_columns(),
            ColumnLayout::BlocksPerVertexThenTriangle => {
                crate::coords::somigliana::BLOCK_COLUMNS
                    * (self.cage.vertices + self.cage.triangles)
            }
        };
        if self.columns != expected || self.columns_layout != layout_id(layout) {
            return Err(field(
                "columns",
                format!(
                    "{} {} columns ({}) do not fit a cage of {} vertices and {} triangles",
                    self.columns,
                    self.method_name,
                    self.columns_layout,
                    self.cage.vertices,
                    self.cage.triangles
                ),
            ));
        }
        if self.rows != self.mesh.points {
            return Err(field(
                "rows",
                format!("{} rows for {} points", self.rows, self.mesh.points),
            ));
        }
        Ok(options)
    }
}

fn layout_id(layout: ColumnLayout) -> &'static str {
    match layout {
        ColumnLayout::CageVertices => "cage_vertices",
        ColumnLayout::CageVerticesThenTriangles => "cage_vertices_then_triangles",
        ColumnLayout::BlocksPerVertexThenTriangle => "blocks_per_vertex_then_triangle",
    }
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|name| name.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Why weights metadata or a class mask could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum MetadataError {
    #[error("{}: cannot read: {source}", shown_path(path))]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "{}: line {line}, column {column}: not weights metadata: {message}",
        shown_path(path)
    )]
    Json {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{}: field {field}: {reason}", shown_path(path))]
    Field {
        path: PathBuf,
        field: &'static str,
        reason: String,
    },
    #[error("{}: {source}", shown_path(path))]
    Parameter {
        path: PathBuf,
        source: ParameterError,
    },
    #[error(
        "{}: the weights were bound for other inputs: {field} is {recorded} there, {found} here",
        shown_path(path)
    )]
    Mismatch {
        path: PathBuf,
        field: &'static str,
        recorded: String,
        found: String,
    },
    #[error("{}: {reason}", shown_path(path))]
    Classes { path: PathBuf, reason: String },
    #[error(transparent)]
    Weights(#[from] NpyError),
    #[error(transparent)]
    Write(#[from] WriteError),
}

/// Read and check `W.json`: valid JSON of this format and version, a known
/// family with valid parameters, and columns that fit the recorded cage.
pub fn read_metadata(path: &Path) -> Result<WeightsMetadata, MetadataError> {
    let bytes = crate::budget::read_limited(path, METADATA_LIMIT).map_err(|source| {
        MetadataError::Read {
            path: path.to_owned(),
            source,
        }
    })?;
    let metadata: WeightsMetadata =
        serde_json::from_slice(&bytes).map_err(|error| MetadataError::Json {
            path: path.to_owned(),
            line: error.line(),
            column: error.column(),
            message: error.to_string(),
        })?;
    metadata.check_consistent(path)?;
    Ok(metadata)
}
