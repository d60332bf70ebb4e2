//! The `Weights` class: a bind's matrix and what a reader needs to trust it.

use super::errors::{error, Kind};
use super::scene::{columns_layout, PyCage};
use crate::coords::family::ColumnLayout;
use crate::coords::npy::row_sum_off;
use crate::coords::{BindOptions, Method};
use glam::DVec3;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// What a `Weights` knows besides its arrays.
#[derive(Clone, Debug)]
pub(super) struct WeightsData {
    /// The family and its parameters; None for a `.npy` read without metadata.
    pub options: Option<BindOptions>,
    pub layout: ColumnLayout,
    pub backend: Option<String>,
    pub device: Option<String>,
    pub seconds: Option<f64>,
    /// Columns that belong to cage vertices.
    pub vertex_columns: usize,
    /// The cage's triangles (ψ column k refers to triangle k for Green).
    pub triangles: Vec<[u32; 3]>,
    pub points_digest: Option<String>,
    pub cage_digest: Option<String>,
}

/// The weights of a bind: ``matrix`` (float32, one row per point, one column per
/// ``columns`` entry), ``classes`` (int8 per row: 0 inside, 1 on the cage, 2
/// outside, where the family's outside policy applies), the family
/// (``method``, ``parameters``), where it ran (``backend``, ``device``,
/// ``seconds``), and for Green coordinates the ``triangles`` that ψ refers to.
#[pyclass(name = "Weights", module = "pmvc", frozen)]
pub(super) struct PyWeights {
    matrix: Py<PyArray2<f32>>,
    classes: Option<Py<PyArray1<i8>>>,
    data: WeightsData,
}

impl PyWeights {
    pub(super) fn new(
        matrix: Py<PyArray2<f32>>,
        classes: Option<Py<PyArray1<i8>>>,
        data: WeightsData,
    ) -> PyResult<Self> {
        Ok(Self {
            matrix,
            classes,
            data,
        })
    }

    pub(super) fn method(&self) -> Option<Method> {
        self.data.options.map(|options| options.method)
    }

    pub(super) fn data(&self) -> &WeightsData {
        &self.data
    }

    pub(super) fn matrix_ref(&self) -> &Py<PyArray2<f32>> {
        &self.matrix
    }

    pub(super) fn classes_ref(&self) -> Option<&Py<PyArray1<i8>>> {
        self.classes.as_ref()
    }

    /// The family whose column vectors these weights multiply: Green for φ and
    /// ψ, any vertex family otherwise (their columns are the cage vertices).
    fn columns_method(&self) -> Method {
        match self.data.layout {
            ColumnLayout::CageVerticesThenTriangles => Method::Green,
            ColumnLayout::CageVertices => self.method().unwrap_or(Method::Mvc),
        }
    }

    /// `points` moved as `pmvc deform --weights` moves them, after the checks it
    /// makes: the shape fits the points and cage, every value is finite, and
    /// every row's cage-vertex weights sum to 1.
    pub(super) fn apply(
        &self,
        py: Python<'_>,
        points: &[DVec3],
        cage: &PyCage,
        pose: &[DVec3],
    ) -> PyResult<Vec<DVec3>> {
        let method = self.columns_method();
        let (rows, columns) = (points.len(), method.columns(&cage.cage));
        let vertices = cage.cage.vertex_count();
        let matrix = self.matrix.bind(py).readonly();
        let shape = matrix.shape().to_vec();
        if shape != [rows, columns] {
            return Err(error(
                Kind::Weights,
                format!(
                    "weights: shape {shape:?} does not fit {rows} points and a cage of {vertices} vertices{}: expected ({rows}, {columns})",
                    if method == Method::Green {
                        format!(" and {} triangles", cage.cage.triangle_count())
                    } else {
                        String::new()
                    }
                ),
            ));
        }
        let contiguous;
        let values: &[f32] = match matrix.as_slice() {
            Ok(values) => values,
            Err(_) => {
                contiguous = matrix.as_array().iter().copied().collect::<Vec<f32>>();
                &contiguous
            }
        };
        for (row, values) in values.chunks(columns.max(1)).enumerate() {
            if let Some(column) = values.iter().position(|w| !w.is_finite()) {
                return Err(error(
                    Kind::Weights,
                    format!(
                        "weights: row {row}, column {column} is not finite ({})",
                        values[column]
                    ),
                ));
            }
            if let Some((sum, tolerance)) = row_sum_off(&values[..vertices]) {
                return Err(error(
                    Kind::Weights,
                    format!(
                        "weights: row {row}'s cage-vertex weights sum to {sum}, not 1 (± {tolerance:.1e})"
                    ),
                ));
            }
        }
        let weights = crate::coords::Weights {
            rows,
            cols: columns,
            values: values.to_vec(),
        };
        let moves = method.column_displacements(&cage.cage, pose);
        Ok(py.detach(|| weights.apply_displacements(points, &moves)))
    }
}

#[pymethods]
impl PyWeights {
    /// The weights, float32, shape (rows, columns).
    #[getter]
    fn matrix<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        self.matrix.bind(py).clone()
    }

    /// The class of each row, int8: 0 inside the cage, 1 on it, 2 outside (its
    /// row follows the family's outside policy; see :func:`families`). None for
    /// weights read from a file written without its classes.
    #[getter]
    fn classes<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<i8>>> {
        self.classes.as_ref().map(|c| c.bind(py).clone())
    }

    /// The family's id ("mvc", "pmvc", "harmonic", "green"); None for a plain
    /// `.npy` read without its metadata.
    #[getter(method)]
    fn method_id(&self) -> Option<&'static str> {
        self.method().map(Method::id)
    }

    /// The family's own parameters, e.g. ``{"resolution": 32}`` (empty for MVC
    /// and Green).
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let parameters = PyDict::new(py);
        if let Some((spec, value)) = self.data.options.and_then(|o| o.parameter()) {
            parameters.set_item(spec.key.id(), value)?;
        }
        Ok(parameters)
    }

    /// Where the weights were computed: "cpu" or "gpu" (None when unknown).
    #[getter]
    fn backend(&self) -> Option<String> {
        self.data.backend.clone()
    }

    /// The device, e.g. "CPU" or the GPU adapter's name.
    #[getter]
    fn device(&self) -> Option<String> {
        self.data.device.clone()
    }

    /// Seconds the bind took (classification excluded).
    #[getter]
    fn seconds(&self) -> Option<f64> {
        self.data.seconds
    }

    /// What each column is, in order: ``("vertex", j)`` for cage vertex j (φ_j
    /// for Green coordinates), then for Green coordinates ``("triangle", k)`` for
    /// ``triangles[k]`` (ψ_k, which multiplies that triangle's scaled normal).
    #[getter]
    fn columns<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let mut entries: Vec<(&str, usize)> = (0..self.data.vertex_columns)
            .map(|j| ("vertex", j))
            .collect();
        if self.data.layout == ColumnLayout::CageVerticesThenTriangles {
            entries.extend((0..self.data.triangles.len()).map(|k| ("triangle", k)));
        }
        PyList::new(py, entries)
    }

    /// "cage_vertices" or "cage_vertices_then_triangles" (Green coordinates).
    #[getter]
    fn columns_layout(&self) -> &'static str {
        columns_layout(self.data.layout)
    }

    /// For Green coordinates, the cage triangles that ψ columns refer to, int64
    /// (t, 3), corners in the order used (outward normals by the right-hand
    /// rule); None for families whose columns are only cage vertices.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<i64>>>> {
        if self.data.layout != ColumnLayout::CageVerticesThenTriangles {
            return Ok(None);
        }
        super::arrays::triangles_array(py, &self.data.triangles).map(Some)
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let shape = self.matrix.bind(py).shape().to_vec();
        format!(
            "Weights({}, {} × {} float32{})",
            self.method().map_or("unknown family", |m| m.name()),
            shape[0],
            shape[1],
            self.data
                .backend
                .as_ref()
                .map(|b| format!(", {b}"))
                .unwrap_or_default()
        )
    }
}
