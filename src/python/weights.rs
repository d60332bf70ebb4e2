//! The `Weights` class, `save_weights` and `load_weights`: a bind's matrix with
//! its class mask and metadata (`formats::metadata`, the files `pmvc bind`
//! writes beside its weights).

use super::errors::{error, file_error, Kind};
use super::scene::PyCage;
use crate::budget::{bytes_for, check_memory};
use crate::coords::family::ColumnLayout;
use crate::coords::{AnyWeights, BindOptions, Dtype, Method, WeightValue, Weights, WeightsF64};
use crate::formats::metadata::{
    classes_path, load_any_weights_set, save_any_weights_set, MetadataError, WeightsMetadata,
};
use crate::formats::npy::row_sum_off;
use crate::formats::shown_path;
use glam::DVec3;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};
use std::path::{Path, PathBuf};

/// The weights of a bind: ``matrix`` (float32, or float64 where asked for; one
/// row per point, one column per entry of ``columns``), ``classes`` (int8 per row: 0 inside, 1 on the
/// cage, 2 outside, where the family's outside policy applies), the family
/// (``method``, ``parameters``), where it ran (``backend``, ``device``,
/// ``seconds``), and for Green coordinates the ``triangles`` that ψ refers to.
/// ``metadata`` is all of it as ``pmvc bind`` writes it in ``W.json``.
#[pyclass(name = "Weights", module = "pmvc", frozen)]
pub(super) struct PyWeights {
    /// A 2-D numpy array of the metadata's dtype (float32 or float64).
    matrix: Py<PyAny>,
    classes: Py<PyArray1<i8>>,
    metadata: WeightsMetadata,
    options: BindOptions,
    /// The file the weights were read from or last saved to, for messages.
    path: Option<PathBuf>,
}

impl PyWeights {
    pub(super) fn new(
        matrix: Py<PyAny>,
        classes: Py<PyArray1<i8>>,
        metadata: WeightsMetadata,
        options: BindOptions,
    ) -> Self {
        Self {
            matrix,
            classes,
            metadata,
            options,
            path: None,
        }
    }

    pub(super) fn method(&self) -> Method {
        self.options.method
    }

    /// How messages name these weights: their file, or "weights".
    fn shown(&self) -> PathBuf {
        self.path
            .clone()
            .unwrap_or_else(|| PathBuf::from("weights"))
    }

    /// The matrix as the library's weights (of its dtype), after the checks
    /// `pmvc deform --weights` makes on a file: the shape the metadata states,
    /// finite values, and cage-vertex weights summing to 1 in every row (the
    /// array is its owner's to change).
    fn checked_matrix(&self, py: Python<'_>) -> PyResult<AnyWeights> {
        let (rows, columns) = (self.metadata.rows, self.metadata.columns);
        Ok(match self.metadata.dtype() {
            Dtype::Float32 => AnyWeights::F32(Weights {
                rows,
                cols: columns,
                values: self.checked_values::<f32>(py)?,
            }),
            Dtype::Float64 => AnyWeights::F64(WeightsF64 {
                rows,
                cols: columns,
                values: self.checked_values::<f64>(py)?,
            }),
        })
    }

    fn checked_values<T: WeightValue + numpy::Element + std::fmt::Display>(
        &self,
        py: Python<'_>,
    ) -> PyResult<Vec<T>> {
        let (rows, columns) = (self.metadata.rows, self.metadata.columns);
        let vertices = self.metadata.cage.vertices;
        let matrix = self.matrix.bind(py).cast::<PyArray2<T>>().map_err(|_| {
            error(
                Kind::Weights,
                format!(
                    "{}: the matrix is not a 2-dimensional {} array",
                    shown_path(&self.shown()),
                    T::DTYPE.id()
                ),
            )
        })?;
        let matrix = matrix.readonly();
        let shape = matrix.shape().to_vec();
        if shape != [rows, columns] {
            return Err(error(
                Kind::Weights,
                format!(
                    "{}: the matrix has shape {}, but the weights are ({rows}, {columns})",
                    shown_path(&self.shown()),
                    crate::formats::npy::header::shape_text(
                        &shape.iter().map(|&n| n as u64).collect::<Vec<_>>()
                    )
                ),
            ));
        }
        let size = T::DTYPE.size();
        check_memory(
            || format!("a copy of the weights ({rows} rows × {columns} columns × {size} bytes)"),
            bytes_for(rows as u64, (size * columns) as u64),
        )
        .map_err(|cause| {
            error(
                Kind::TooLarge,
                format!("{}: {cause}", shown_path(&self.shown())),
            )
        })?;
        let values: Vec<T> = match matrix.as_slice() {
            Ok(values) => values.to_vec(),
            Err(_) => matrix.as_array().iter().copied().collect(),
        };
        for (row, values) in values.chunks(columns.max(1)).enumerate() {
            if let Some(column) = values.iter().position(|w| !w.to_f64().is_finite()) {
                return Err(error(
                    Kind::Weights,
                    format!(
                        "{}: row {row}, column {column} is not finite ({})",
                        shown_path(&self.shown()),
                        values[column]
                    ),
                ));
            }
            if let Some(off) = self.partition_off(values, vertices) {
                return Err(error(
                    Kind::Weights,
                    format!("{}: row {row}'s {off}", shown_path(&self.shown())),
                ));
            }
        }
        Ok(values)
    }

    /// What is wrong with a row's partition of unity, if anything: the cage
    /// vertices' weights must sum to 1; Somigliana's vertex blocks to the
    /// identity, checked on its diagonal entries (each sums to 1).
    fn partition_off<T: WeightValue>(&self, row: &[T], vertices: usize) -> Option<String> {
        let layout = self.method().spec().columns;
        let per = layout.columns_per_element();
        if per == 1 {
            let (sum, tolerance) = row_sum_off(&row[..vertices.min(row.len())])?;
            return Some(format!(
                "cage-vertex weights sum to {sum}, not 1 (± {tolerance:.1e})"
            ));
        }
        (0..3).find_map(|a| {
            let diagonal: Vec<T> = (0..vertices)
                .filter_map(|v| row.get(per * v + 4 * a).copied())
                .collect();
            let (sum, tolerance) = row_sum_off(&diagonal)?;
            Some(format!(
                "vertex blocks' entries ({a}, {a}) sum to {sum}, not 1 (± {tolerance:.1e})"
            ))
        })
    }

    /// `strict=True` with these weights: an error when a row is outside the cage.
    pub(super) fn check_strict(&self, py: Python<'_>) -> PyResult<()> {
        let classes = self.classes.bind(py).readonly();
        let outside: Vec<u32> = classes
            .as_array()
            .iter()
            .enumerate()
            .filter(|(_, &class)| class == crate::formats::metadata::CLASS_OUTSIDE)
            .map(|(row, _)| row as u32)
            .collect();
        if outside.is_empty() {
            Ok(())
        } else {
            Err(super::binding::outside_error(&outside, classes.len()))
        }
    }

    /// `points` moved as `pmvc deform --weights` moves them, after its checks:
    /// the weights were bound for these points and this cage (the metadata's
    /// counts and digests), and the matrix is sound. `deform` holds the
    /// deformation settings given (Somigliana's bulging and local blend), checked by their specs.
    pub(super) fn apply(
        &self,
        py: Python<'_>,
        points: &[DVec3],
        cage: &PyCage,
        pose: &[DVec3],
        deform: &[(crate::coords::Parameter, u32)],
    ) -> PyResult<Vec<DVec3>> {
        self.metadata
            .check_inputs(&self.shown(), points, &cage.cage)
            .map_err(|cause| metadata_error(&cause))?;
        let weights = self.checked_matrix(py)?;
        // Green's ψ columns follow the triangles the weights were bound on.
        let mut options = self.options;
        for &(parameter, value) in deform {
            options.set(parameter, value);
        }
        let moves = options.column_moves(&cage.cage, pose);
        Ok(py.detach(|| weights.apply_moves(points, &moves)))
    }
}

/// A metadata or weights-file error as the exception it is.
fn metadata_error(cause: &MetadataError) -> PyErr {
    let message = cause.to_string();
    match cause {
        MetadataError::Read { path, .. } => file_error(Kind::File, message, path, None),
        MetadataError::Json { path, line, .. } => {
            file_error(Kind::File, message, path, Some(*line))
        }
        MetadataError::Write(source) => file_error(Kind::File, message, &source.path, None),
        MetadataError::Field { path, .. }
        | MetadataError::Parameter { path, .. }
        | MetadataError::Mismatch { path, .. }
        | MetadataError::Classes { path, .. } => file_error(Kind::Weights, message, path, None),
        MetadataError::Weights(_) => error(Kind::Weights, message),
    }
}

#[pymethods]
impl PyWeights {
    /// The weights, shape (rows, columns): float32, or float64 where
    /// ``dtype=numpy.float64`` was asked for (``metadata["dtype"]`` says which).
    #[getter]
    fn matrix<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.matrix.bind(py).clone()
    }

    /// The class of each row, int8: 0 inside the cage, 1 on it, 2 outside (its
    /// row follows the family's outside policy; see :func:`families`).
    #[getter]
    fn classes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i8>> {
        self.classes.bind(py).clone()
    }

    /// The family's id, e.g. "pmvc" (:func:`families` lists them all).
    #[getter(method)]
    fn method_id(&self) -> &'static str {
        self.method().id()
    }

    /// The family's own parameters, e.g. ``{"resolution": 32}`` (empty for MVC
    /// and Green).
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let parameters = PyDict::new(py);
        for (name, &value) in &self.metadata.parameters {
            // A named value ("exact") as its name, as W.json writes it.
            let spec = (crate::coords::Parameter::ALL.into_iter())
                .find(|p| p.id() == name)
                .map(|p| p.spec());
            match spec {
                Some(spec) => match spec.name_of(value) {
                    Some(named) => parameters.set_item(name, named)?,
                    None => parameters
                        .set_item(name, super::families::parameter_number(py, spec, value))?,
                },
                None => parameters.set_item(name, value)?,
            }
        }
        Ok(parameters)
    }

    /// Where the weights were computed: "cpu" or "gpu".
    #[getter]
    fn backend(&self) -> String {
        self.metadata.backend.clone()
    }

    /// The device, e.g. "CPU" or the GPU adapter's name.
    #[getter]
    fn device(&self) -> String {
        self.metadata.device.clone()
    }

    /// Seconds the bind took (classification and copies excluded).
    #[getter]
    fn seconds(&self) -> f64 {
        self.metadata.seconds
    }

    /// What each column is, in order: ``("vertex", j)`` for cage vertex j (φ_j
    /// for Green coordinates), then for Green coordinates ``("triangle", k)``
    /// for ``triangles[k]`` (ψ_k, which multiplies that triangle's scaled
    /// normal), then for QGC (Green on quads) ``("quad_corner", 4 q + c)`` for
    /// corner c of quad q of the metadata's ``quads`` (its scaled corner normal).
    /// Somigliana coordinates' 3×3 blocks: ``("vertex_block", 9 j + 3 a + b)``
    /// for entry (a, b) of cage vertex j's block, then ``("triangle_block",
    /// 9 k + 3 a + b)`` for ``triangles[k]``'s (``matrix.reshape(n, -1, 3, 3)``).
    #[getter]
    fn columns<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let vertices = self.metadata.cage.vertices;
        if self.method().spec().columns == ColumnLayout::BlocksPerVertexThenTriangle {
            let per = self.method().spec().columns.columns_per_element();
            let triangles =
                (self.metadata.triangles.as_ref()).map_or(self.metadata.cage.triangles, Vec::len);
            let entries: Vec<(&str, usize)> = (0..per * vertices)
                .map(|k| ("vertex_block", k))
                .chain((0..per * triangles).map(|k| ("triangle_block", k)))
                .collect();
            return PyList::new(py, entries);
        }
        let mut entries: Vec<(&str, usize)> = (0..vertices).map(|j| ("vertex", j)).collect();
        if self.method().spec().columns == ColumnLayout::CageVerticesThenTriangles {
            let triangles =
                (self.metadata.triangles.as_ref()).map_or(self.metadata.cage.triangles, Vec::len);
            entries.extend((0..triangles).map(|k| ("triangle", k)));
            // QGC: four per quad, `4 q + corner` for corner normal N of `quads[q]`.
            let corners = self
                .metadata
                .quads
                .as_ref()
                .map_or(0, |quads| 4 * quads.len());
            entries.extend((0..corners).map(|k| ("quad_corner", k)));
        }
        PyList::new(py, entries)
    }

    /// "cage_vertices" or "cage_vertices_then_triangles" (Green coordinates).
    #[getter]
    fn columns_layout(&self) -> String {
        self.metadata.columns_layout.clone()
    }

    /// For Green coordinates, the cage triangles that ψ columns refer to, int64
    /// (t, 3), corners in the order used (outward normals by the right-hand
    /// rule); None for families whose columns are only cage vertices.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<i64>>>> {
        match &self.metadata.triangles {
            Some(triangles) => super::arrays::triangles_array(py, triangles).map(Some),
            None => Ok(None),
        }
    }

    /// Everything ``W.json`` holds, as a dict (``json.load`` of the file
    /// :func:`save_weights` writes).
    #[getter]
    fn metadata<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?
            .call_method1("loads", (self.metadata.to_json_pretty(),))
    }

    /// Pickling, ``copy`` and ``copy.deepcopy``: the matrix and classes as the
    /// arrays they are (a pickle costs their bytes, and protocol 5 hands them
    /// over without a copy), the metadata as ``W.json`` holds it, and the file
    /// they were read from. Loading checks the metadata as :func:`load_weights`
    /// does and the arrays against it.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let restore = py.import("pmvc._native")?.getattr("_restore_weights")?;
        let path = match &self.path {
            Some(path) => path.into_pyobject(py)?.into_any(),
            None => py.None().into_bound(py),
        };
        let state = PyTuple::new(
            py,
            [
                self.matrix.bind(py).clone().into_any(),
                self.classes.bind(py).clone().into_any(),
                PyString::new(py, &self.metadata.to_json_pretty()).into_any(),
                path,
            ],
        )?;
        PyTuple::new(py, [restore, state.into_any()])
    }

    fn __repr__(&self) -> String {
        format!(
            "Weights({}, {} × {} {}, {})",
            self.metadata.method_name,
            self.metadata.rows,
            self.metadata.columns,
            self.metadata.dtype,
            self.metadata.backend
        )
    }
}

/// Weights of either dtype as the numpy array `Weights.matrix` holds, without a
/// copy.
pub(super) fn matrix_array(py: Python<'_>, weights: AnyWeights) -> PyResult<Py<PyAny>> {
    Ok(match weights {
        AnyWeights::F32(weights) => {
            super::arrays::matrix(py, weights.values, weights.rows, weights.cols)?
                .into_any()
                .unbind()
        }
        AnyWeights::F64(weights) => {
            super::arrays::matrix(py, weights.values, weights.rows, weights.cols)?
                .into_any()
                .unbind()
        }
    })
}

/// Weights from their pickled state (``Weights.__reduce__``): the metadata
/// checked as :func:`load_weights` checks ``W.json`` (format, family,
/// parameters, columns), and the arrays against it.
#[pyfunction]
#[pyo3(name = "_restore_weights", signature = (matrix, classes, metadata, path=None))]
pub(super) fn restore_weights(
    matrix: &Bound<'_, PyAny>,
    classes: &Bound<'_, PyAny>,
    metadata: &str,
    path: Option<PathBuf>,
) -> PyResult<PyWeights> {
    let what = Path::new("pickled weights");
    let metadata: WeightsMetadata = serde_json::from_str(metadata).map_err(|cause| {
        error(
            Kind::Weights,
            format!("pickled weights: the metadata is not W.json: {cause}"),
        )
    })?;
    let options = metadata
        .check_consistent(what)
        .map_err(|cause| error(Kind::Weights, cause.to_string()))?;
    let (rows, columns) = (metadata.rows, metadata.columns);
    // Arrays rebuilt from a buffer may be misaligned: aligned here, once.
    let dtype = metadata.dtype();
    let not_matrix = || {
        error(
            Kind::Weights,
            format!(
                "pickled weights: the matrix is not a 2-dimensional {} array (the metadata's dtype)",
                dtype.id()
            ),
        )
    };
    let is_matrix = match dtype {
        Dtype::Float32 => matrix.cast::<PyArray2<f32>>().is_ok(),
        Dtype::Float64 => matrix.cast::<PyArray2<f64>>().is_ok(),
    };
    if !is_matrix {
        return Err(not_matrix());
    }
    let matrix = super::arrays::aligned(matrix, dtype.id())?
        .cast_into::<PyUntypedArray>()
        .map_err(|_| not_matrix())?;
    if matrix.shape() != [rows, columns] {
        return Err(error(
            Kind::Weights,
            format!(
                "pickled weights: the matrix has shape {}, but the metadata says ({rows}, {columns})",
                crate::formats::npy::header::shape_text(
                    &matrix.shape().iter().map(|&n| n as u64).collect::<Vec<_>>()
                )
            ),
        ));
    }
    let not_classes = || {
        error(
            Kind::Weights,
            "pickled weights: the classes are not a 1-dimensional int8 array",
        )
    };
    classes.cast::<PyArray1<i8>>().map_err(|_| not_classes())?;
    let classes = super::arrays::aligned(classes, "int8")?
        .cast_into::<PyArray1<i8>>()
        .map_err(|_| not_classes())?;
    if classes.len() != rows {
        return Err(error(
            Kind::Weights,
            format!("pickled weights: {} classes for {rows} rows", classes.len()),
        ));
    }
    let mut weights = PyWeights::new(
        matrix.into_any().unbind(),
        classes.unbind(),
        metadata,
        options,
    );
    weights.path = path;
    Ok(weights)
}

/// Write ``weights`` as ``pmvc bind`` writes them: the matrix to ``path``
/// (``.npy``; Green coordinates' φ and ψ to a ``.npz``), the classes to
/// ``W.classes.npy`` and the metadata to ``W.json`` beside it, all three or none
/// (each through a temporary file renamed into place).
#[pyfunction]
pub(super) fn save_weights(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    weights: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let path = super::arguments::path(path, "save_weights")?;
    let weights = weights.cast::<PyWeights>().map_err(|_| {
        error(
            Kind::Input,
            format!(
                "save_weights: weights: {} is not a pmvc.Weights (from bind or load_weights)",
                super::arguments::shown(weights)
            ),
        )
    })?;
    let weights = weights.get();
    let npz = weights.method().spec().columns == ColumnLayout::CageVerticesThenTriangles;
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let wanted = if npz { "npz" } else { "npy" };
    if extension.as_deref() != Some(wanted) {
        return Err(file_error(
            Kind::File,
            format!(
                "{}: {} weights are written as .{wanted}; use {}",
                shown_path(&path),
                weights.method().name(),
                shown_path(&path.with_extension(wanted))
            ),
            &path,
            None,
        ));
    }
    let matrix = weights.checked_matrix(py)?;
    let classes: Vec<i8> = weights.classes.bind(py).readonly().as_array().to_vec();
    let mut metadata = weights.metadata.clone();
    metadata.classes.file = classes_path(&path)
        .file_name()
        .map(|name| name.to_string_lossy().into_owned())
        .unwrap_or_default();
    py.detach(|| save_any_weights_set(&path, &matrix, &metadata, &classes))
        .map_err(|cause| metadata_error(&cause))
}

/// Read weights written by ``pmvc bind`` or :func:`save_weights`: the metadata
/// (``W.json``) first, then the matrix with the shape it states (checked as
/// ``pmvc deform --weights`` checks it), then the classes (``W.classes.npy``).
#[pyfunction]
pub(super) fn load_weights(py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<PyWeights> {
    let path = super::arguments::path(path, "load_weights")?;
    let loaded = py
        .detach(|| load_any_weights_set(&path))
        .map_err(|cause| metadata_error(&cause))?;
    let mut weights = PyWeights::new(
        matrix_array(py, loaded.weights)?,
        PyArray1::from_vec(py, loaded.classes).unbind(),
        loaded.metadata,
        loaded.options,
    );
    weights.path = Some(path);
    Ok(weights)
}
