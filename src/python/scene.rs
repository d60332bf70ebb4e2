//! `Cage`, `load_mesh`, `classify`, `generate_cage` and `families`.

use super::arrays::{faces_list, positions, positions_array, triangles_array};
use super::binding::{run_interruptible, Interruptible};
use super::errors::{cage_load_error, error, load_error, Kind};
use crate::cagegen::{self, CageOptions};
use crate::formats::metadata::class_codes;
use crate::geometry::{self, Cage, CageReport};
use crate::geometry::{polygons_of, triangulate_faces};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::Arc;

/// A validated cage: closed, edge-manifold, consistently oriented, no degenerate
/// triangles, not crossing itself (the checks of the command line).
///
/// ``Cage(vertices, faces)`` takes an (m, 3) array-like of positions and a
/// sequence of faces, each a sequence of 0-based vertex indices. Quads stay
/// bilinear patches (``quads``) for the families that take them, and are also
/// cut along their shorter diagonal into ``triangles``; larger polygons are
/// fanned from their first corner. An inward-facing cage is
/// flipped (``flipped`` says so). ``Cage.load(path)`` reads an OBJ or OFF file.
#[pyclass(name = "Cage", module = "pmvc", frozen)]
pub(super) struct PyCage {
    pub(super) cage: Arc<Cage>,
    faces: Vec<Vec<u32>>,
    report: CageReport,
    pub(super) path: Option<PathBuf>,
    /// The object of that file read by name (`Cage.load(path, object=)`).
    pub(super) object: Option<String>,
    /// What the cage was validated from: its pickled state. Validating it
    /// again gives this cage bit for bit (validation is deterministic).
    source: Arc<geometry::TriMesh>,
}

impl PyCage {
    fn validated(mesh: geometry::TriMesh, path: Option<PathBuf>, py: Python<'_>) -> PyResult<Self> {
        let mut faces = polygons_of(&mesh);
        let source = Arc::new(mesh.clone());
        let (cage, report) = py.detach(|| Cage::new(mesh)).map_err(|cause| match &path {
            Some(path) => cage_load_error(&crate::formats::CageLoadError::Invalid {
                path: path.clone(),
                source: cause,
            }),
            None => error(
                Kind::Cage,
                format!("cage: {cause} (faces and vertices counted from 1)"),
            ),
        })?;
        if report.flipped {
            for face in &mut faces {
                face.reverse();
            }
        }
        Ok(Self {
            cage: Arc::new(cage),
            faces,
            report,
            path,
            object: None,
            source,
        })
    }
}

/// A `cage` argument: a `pmvc.Cage`, or libigl's `(V, F)` pair, validated now
/// as `Cage(V, F)` validates it.
pub(super) enum CageArgument<'py> {
    Cage(Bound<'py, PyCage>),
    Built(PyCage),
}

impl std::ops::Deref for CageArgument<'_> {
    type Target = PyCage;

    fn deref(&self) -> &PyCage {
        match self {
            CageArgument::Cage(cage) => cage.get(),
            CageArgument::Built(cage) => cage,
        }
    }
}

/// `value` as a cage: a `pmvc.Cage`, or a `(vertices, faces)` pair (a tuple or
/// list of two) with `faces` an integer array (m, k) or a sequence of polygons.
pub(super) fn cage_argument<'py>(value: &Bound<'py, PyAny>) -> PyResult<CageArgument<'py>> {
    if let Ok(cage) = value.cast::<PyCage>() {
        return Ok(CageArgument::Cage(cage.clone()));
    }
    let pair = value
        .cast::<PyTuple>()
        .map(|tuple| tuple.iter().collect::<Vec<_>>())
        .or_else(|_| value.cast::<PyList>().map(|list| list.iter().collect()));
    match pair {
        Ok(items) if items.len() == 2 => {
            PyCage::from_arrays(value.py(), &items[0], &items[1]).map(CageArgument::Built)
        }
        Ok(items) => Err(error(
            Kind::Input,
            format!(
                "cage: a (vertices, faces) pair has 2 items, not {}",
                items.len()
            ),
        )),
        Err(_) => Err(error(
            Kind::Input,
            format!(
                "cage: {} is neither a pmvc.Cage nor a (vertices, faces) pair",
                super::arguments::shown(value)
            ),
        )),
    }
}

/// A cage from its pickled state (``Cage.__reduce__``): the vertices,
/// triangles and each triangle's face it was validated from, and its file.
/// Checked and validated as any cage is, since a pickle is input like any other.
#[pyfunction]
#[pyo3(name = "_restore_cage", signature = (vertices, triangles, triangle_faces, path=None, object=None))]
pub(super) fn restore_cage(
    py: Python<'_>,
    vertices: &Bound<'_, PyAny>,
    triangles: &Bound<'_, PyAny>,
    triangle_faces: &Bound<'_, PyAny>,
    path: Option<PathBuf>,
    object: Option<String>,
) -> PyResult<PyCage> {
    let what = "pickled cage";
    let positions = positions(vertices, &format!("{what}: vertices"))?;
    let rows = super::arrays::faces(triangles, positions.len(), &format!("{what}: triangles"))?;
    let triangles = rows
        .iter()
        .enumerate()
        .map(|(t, row)| {
            <[u32; 3]>::try_from(row.as_slice()).map_err(|_| {
                error(
                    Kind::Input,
                    format!("{what}: triangle {t} has {} corners, not 3", row.len()),
                )
            })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let triangle_faces: Vec<i64> = triangle_faces.extract().map_err(|_| {
        error(
            Kind::Input,
            format!("{what}: triangle_faces is not a sequence of face indices"),
        )
    })?;
    if triangle_faces.len() != triangles.len() {
        return Err(error(
            Kind::Input,
            format!(
                "{what}: {} triangle faces for {} triangles",
                triangle_faces.len(),
                triangles.len()
            ),
        ));
    }
    let triangle_faces = triangle_faces
        .iter()
        .enumerate()
        .map(|(t, &face)| {
            u32::try_from(face).map_err(|_| {
                error(
                    Kind::Input,
                    format!("{what}: triangle {t}'s face {face} is not a face index"),
                )
            })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let mut cage = PyCage::validated(
        geometry::TriMesh {
            positions,
            triangles,
            triangle_faces,
        },
        path,
        py,
    )?;
    cage.object = object;
    Ok(cage)
}

impl PyCage {
    /// `Cage(vertices, faces)`, and a `(V, F)` pair given where a cage is taken.
    fn from_arrays(
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        let vertices = positions(vertices, "cage vertices")?;
        let faces = super::arrays::faces(faces, vertices.len(), "cage faces")?;
        Self::validated(triangulate_faces(&faces, &vertices), None, py)
    }
}

#[pymethods]
impl PyCage {
    #[new]
    fn new(
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        Self::from_arrays(py, vertices, faces)
    }

    /// Read and validate a cage from an OBJ, OFF or glTF file: object
    /// ``object`` of a file with several, as ``load_mesh`` reads it.
    #[staticmethod]
    #[pyo3(signature = (path, object=None))]
    fn load(
        py: Python<'_>,
        path: &Bound<'_, PyAny>,
        object: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let file = read_object(py, path, object, "Cage.load")?;
        let mut cage = Self::validated(file.mesh, Some(file.path), py)?;
        cage.object = file.objects.read;
        Ok(cage)
    }

    /// Vertex positions, float64, shape (m, 3), in file order (weights columns
    /// follow it).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        positions_array(py, self.cage.positions())
    }

    /// The faces as given (polygons of 0-based vertex indices), reversed if the
    /// cage was flipped to face outward.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        faces_list(py, &self.faces)
    }

    /// The outward-facing triangles the faces were cut into, int64, shape (t, 3):
    /// the triangles Green coordinates' ψ columns refer to, corners in this order.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        triangles_array(py, self.cage.triangles())
    }

    /// The quads, as bilinear patches, int64, shape (q, 4): corners q0..q3 of
    /// P(u, v) = (1−u)(1−v)q0 + u(1−v)q1 + uv·q2 + (1−u)v·q3, outward.
    #[getter]
    fn quads<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let quads = self.cage.quads();
        let flat: Vec<i64> = quads
            .iter()
            .flat_map(|q| q.corners)
            .map(i64::from)
            .collect();
        super::arrays::matrix(py, flat, quads.len(), 4)
    }

    /// For each triangle, the face (0-based) it was cut from.
    #[getter]
    fn triangle_faces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let faces: Vec<i64> = self
            .cage
            .triangle_faces()
            .iter()
            .map(|&f| f.into())
            .collect();
        PyArray1::from_vec(py, faces)
    }

    /// Whether the faces pointed inward and were reversed.
    #[getter]
    fn flipped(&self) -> bool {
        self.report.flipped
    }

    /// Enclosed volume (positive).
    #[getter]
    fn volume(&self) -> f64 {
        self.report.volume
    }

    /// Length of the bounding-box diagonal.
    #[getter]
    fn diagonal(&self) -> f64 {
        self.cage.diagonal()
    }

    /// What validation noticed without refusing the cage, one line each (as
    /// the command line prints them).
    #[getter]
    fn notices(&self) -> Vec<String> {
        self.report.messages()
    }

    /// The file the cage was read from, or None.
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        self.path.clone()
    }

    /// The object of that file read as the cage (``Cage.load(path,
    /// object="Cage")``), or None; ``bind`` records it in the weights' metadata.
    #[getter]
    fn object(&self) -> Option<String> {
        self.object.clone()
    }

    /// Pickling, ``copy`` and ``copy.deepcopy``: the vertices and triangles the
    /// cage was validated from (float64 and int64 arrays, so a pickle costs
    /// their bytes) and its file; loading validates them again, which gives
    /// this cage bit for bit.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let restore = py.import("pmvc._native")?.getattr("_restore_cage")?;
        let source = &self.source;
        let faces: Vec<i64> = source.triangle_faces.iter().map(|&f| f.into()).collect();
        let path = match &self.path {
            Some(path) => path.into_pyobject(py)?.into_any(),
            None => py.None().into_bound(py),
        };
        let state = PyTuple::new(
            py,
            [
                positions_array(py, &source.positions)?.into_any(),
                triangles_array(py, &source.triangles)?.into_any(),
                PyArray1::from_vec(py, faces).into_any(),
                path,
                self.object.clone().into_pyobject(py)?.into_any(),
            ],
        )?;
        PyTuple::new(py, [restore, state.into_any()])
    }

    fn __repr__(&self) -> String {
        format!(
            "Cage({} vertices, {} faces, {} triangles{})",
            self.cage.vertex_count(),
            self.faces.len(),
            self.cage.triangle_count(),
            self.path
                .as_ref()
                .map(|p| format!(", from {}", crate::formats::shown_path(p)))
                .unwrap_or_default()
        )
    }
}

/// Read an OBJ or OFF file, the first mesh of a glTF file, or a ``.npy`` point
/// set: ``(vertices, faces)`` as libigl's ``read_triangle_mesh`` gives them.
/// ``vertices`` is float64 (n, 3) in file order; ``faces`` is an int64 array
/// (m, 3) of 0-based indices when every face is a triangle ((0, 3) for a point
/// set), and a list of polygons (lists of indices) when a face has more
/// corners, so that quads stay quads.
///
/// ``object`` names one object of a file with several (an OBJ's ``o`` name,
/// a glTF node's or mesh's name): its faces and the vertices they use,
/// re-indexed in file order. Without it an OBJ's objects are read as one
/// mesh and a glTF's first mesh alone, with a ``PmvcWarning`` naming the
/// others; a name the file does not have raises ``FileError`` listing them.
#[pyfunction]
#[pyo3(signature = (path, object=None))]
pub(super) fn load_mesh<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
    object: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let file = read_object(py, path, object, "load_mesh")?;
    let vertices = positions_array(py, &file.mesh.positions)?;
    let polygons = polygons_of(&file.mesh);
    let faces = if polygons.iter().all(|face| face.len() == 3) {
        let flat: Vec<i64> = polygons.iter().flatten().map(|&i| i64::from(i)).collect();
        super::arrays::matrix(py, flat, polygons.len(), 3)?.into_any()
    } else {
        faces_list(py, &polygons)?.into_any()
    };
    PyTuple::new(py, [vertices.into_any(), faces])
}

/// The mesh file `path` (object `object`, when given) for `caller`, with a
/// warning naming the file's objects where it has several and none was named.
fn read_object(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    object: Option<Bound<'_, PyAny>>,
    caller: &str,
) -> PyResult<crate::formats::MeshFile> {
    let path = super::arguments::path(path, caller)?;
    let object = super::arguments::object_name(object)?;
    let mut file = py
        .detach(|| crate::formats::load_mesh_object(&path, object.as_deref()))
        .map_err(|cause| load_error(&cause))?;
    if let Some(note) = file.object_note.take() {
        let message = format!(
            "{}: {note}; object=NAME reads one alone",
            crate::formats::shown_path(&path)
        );
        super::errors::object_warning(py, &message)?;
    }
    Ok(file)
}

/// Where each point lies, int8: 0 inside the cage, 1 on it, 2 outside (by the
/// generalised winding number), exactly as ``bind`` with the same ``method``
/// and ``triangulate`` classes its rows: against the cage it binds. Without
/// them, a cage's quads are bilinear patches; ``triangulate="shorter"`` or
/// ``"longer"`` classes against the quads split along that diagonal, and
/// ``method="green"`` against the shorter split Green coordinates bind on.
#[pyfunction]
#[pyo3(signature = (points, cage, method=None, triangulate=None))]
pub(super) fn classify<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    cage: &Bound<'py, PyAny>,
    method: Option<Bound<'py, PyAny>>,
    triangulate: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray1<i8>>> {
    let method = super::bind_arguments::method_argument(method.as_ref())?;
    let options =
        super::bind_arguments::bind_options(method, None, None, None, triangulate.as_ref())?;
    let cage = cage_argument(cage)?;
    let points = positions(points, "points")?;
    let cage = Arc::clone(&cage.cage);
    let codes = py.detach(|| class_codes(&options.classify(&cage, &points).classes));
    Ok(PyArray1::from_vec(py, codes))
}

/// Generate a cage of about ``target`` vertices around a triangle mesh, as
/// ``pmvc cage`` does. Returns ``(cage, report)``; ``report`` is a dict of what
/// ``pmvc cage`` prints. ``clearance`` and ``cell_size`` are fractions of the
/// mesh's bounding-box diagonal (None: chosen). ``progress``, if given, is
/// called with ``(done, total)`` (thousandths). ``quads=True`` pairs triangles
/// into quads (bilinear patches) where they fit, as ``pmvc cage --quads``.
/// Ctrl-C cancels.
#[pyfunction]
#[pyo3(
    signature = (vertices, faces, target, clearance=None, cell_size=None, progress=None, quads=None),
    text_signature = "(vertices, faces, target, clearance=None, cell_size=None, progress=None, quads=False)"
)]
#[allow(clippy::too_many_arguments)] // Python's keyword arguments
pub(super) fn generate_cage<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    target: &Bound<'py, PyAny>,
    clearance: Option<Bound<'py, PyAny>>,
    cell_size: Option<Bound<'py, PyAny>>,
    progress: Option<Bound<'py, PyAny>>,
    quads: Option<Bound<'py, PyAny>>,
) -> PyResult<(PyCage, Bound<'py, PyDict>)> {
    use super::arguments::{flag, integer, optional_number};
    let target = integer(target, "generate_cage: target")?;
    let clearance = optional_number(clearance.as_ref(), "generate_cage: clearance")?;
    let cell_size = optional_number(cell_size.as_ref(), "generate_cage: cell_size")?;
    let quads = match quads.filter(|value| !value.is_none()) {
        Some(value) => flag(&value, "generate_cage: quads")?,
        None => false,
    };
    let target = usize::try_from(target).map_err(|_| {
        error(
            Kind::Parameter,
            format!(
                "generate_cage: target {target}: a cage needs at least {} vertices",
                cagegen::MIN_TARGET_VERTICES
            ),
        )
    })?;
    let vertices = positions(vertices, "mesh vertices")?;
    let faces = super::arrays::faces(faces, vertices.len(), "mesh faces")?;
    let mesh = triangulate_faces(&faces, &vertices);
    let options = CageOptions {
        clearance,
        cell_size,
        quads,
        ..CageOptions::new(target)
    };
    cagegen::plan_cage(&mesh, &options).map_err(|cause| cagegen_error(&cause))?;
    const TOTAL: u32 = 1000;
    let done = AtomicU32::new(0);
    let cancelled = AtomicBool::new(false);
    let task = Interruptible {
        cancel: &|| cancelled.store(true, Ordering::Relaxed),
        progress: progress.as_ref(),
        done: &|| (done.load(Ordering::Relaxed) as usize, TOTAL as usize),
    };
    let generated = run_interruptible(py, task, || {
        cagegen::generate_cage(&mesh, &options, &|fraction| {
            let thousandths = (fraction.clamp(0.0, 1.0) * TOTAL as f32) as u32;
            done.fetch_max(thousandths, Ordering::Relaxed);
            !cancelled.load(Ordering::Relaxed)
        })
    })?
    .map_err(|cause| cagegen_error(&cause))?;
    let stats = &generated.stats;
    let report = PyDict::new(py);
    report.set_item("vertices", stats.vertices)?;
    report.set_item("triangles", stats.triangles)?;
    report.set_item("quads", stats.quads)?;
    report.set_item("target_vertices", stats.target_vertices)?;
    report.set_item("target_reached", stats.target_reached())?;
    report.set_item("shells", stats.shells)?;
    report.set_item("min_clearance", stats.min_clearance)?;
    report.set_item("mesh_diagonal", stats.mesh_diagonal)?;
    report.set_item("outside_vertices", stats.outside_vertices)?;
    report.set_item("cage_volume", stats.cage_volume)?;
    report.set_item("mesh_volume", stats.mesh_volume)?;
    report.set_item("mesh_volume_from_voxels", stats.mesh_volume_from_voxels)?;
    report.set_item("volume_ratio", stats.volume_ratio())?;
    report.set_item("min_angle_degrees", stats.min_angle_degrees)?;
    report.set_item("cell_size", stats.cell_size)?;
    report.set_item("cell_size_chosen", stats.cell_size_chosen)?;
    report.set_item("cell_size_asked", stats.cell_size_asked)?;
    report.set_item("start", stats.start.name())?;
    report.set_item(
        "start_reason",
        stats.start_reason.map(cagegen::StartReason::name),
    )?;
    report.set_item("merge_distance", stats.merge_distance())?;
    report.set_item("reach", stats.reach)?;
    report.set_item("gap_points", stats.gaps.points)?;
    report.set_item("gap_points_open", stats.gaps.open)?;
    report.set_item("narrowest_open_gap", stats.gaps.narrowest_open)?;
    report.set_item("widest_closed_gap", stats.gaps.widest_closed)?;
    report.set_item(
        "bridged_gap_points",
        positions_array(py, &stats.gaps.bridged)?,
    )?;
    report.set_item("grid", stats.grid.to_vec())?;
    report.set_item("surface_vertices", stats.surface_vertices)?;
    report.set_item("seconds", stats.seconds)?;
    let cage = PyCage::validated(
        geometry::TriMesh {
            positions: generated.cage.positions().to_vec(),
            triangles: generated.cage.triangles().to_vec(),
            // Keeps the quads.
            triangle_faces: generated.cage.triangle_faces().to_vec(),
        },
        None,
        py,
    )?;
    Ok((cage, report))
}

fn cagegen_error(cause: &cagegen::AutoCageError) -> PyErr {
    use cagegen::AutoCageError as E;
    let kind = match cause {
        E::TooFewVertices { .. } | E::TooManyVertices { .. } => Kind::Parameter,
        E::BadClearance { .. } | E::BadCellSize { .. } => Kind::Parameter,
        E::NoTriangles | E::Flat => Kind::Input,
        E::TooManySamples { .. } | E::GridTooLarge { .. } | E::NotEnoughMemory { .. } => {
            Kind::TooLarge
        }
        E::Cancelled | E::Invalid(_) | E::NotEnclosing { .. } => Kind::Bind,
    };
    error(kind, format!("generate_cage: {cause}"))
}
