//! `families()`: every family as data, for scripts and the Blender add-on.

use crate::coords::family::ColumnLayout;
use crate::coords::Method;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// Every coordinate family: a list of dicts with ``id`` (the ``method``
/// argument), ``name``, ``summary``, ``parameters`` (each with ``id``,
/// ``label``, ``default``, ``min``, ``max`` and the editor's ``choices``),
/// ``deform_parameters`` (the same for settings :func:`deform` reads, not
/// :func:`bind`: Somigliana's ``bulging``),
/// ``positive_inside`` (whether weights inside the cage are never negative),
/// ``outside_policy``, ``columns_layout``, ``gpu_kernel`` (whether
/// ``backend="gpu"`` runs it on the GPU on a cage of triangles; otherwise it
/// binds on the CPU) and ``gpu_kernel_quads`` (the same on a cage whose quads
/// the family binds as bilinear patches: MVC there is QMVC, CPU only).
#[pyfunction]
pub(super) fn families(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let list = PyList::empty(py);
    for method in Method::ALL {
        let spec = method.spec();
        let family = PyDict::new(py);
        family.set_item("id", spec.id)?;
        family.set_item("name", spec.name)?;
        family.set_item("summary", spec.summary)?;
        let parameters = PyList::empty(py);
        if let Some(parameter) = spec.parameter {
            parameters.append(parameter_entry(py, &parameter)?)?;
        }
        family.set_item("parameters", parameters)?;
        let deform_parameters = PyList::empty(py);
        for parameter in spec.deform_parameters {
            deform_parameters.append(parameter_entry(py, parameter)?)?;
        }
        family.set_item("deform_parameters", deform_parameters)?;
        family.set_item("positive_inside", spec.positive_inside)?;
        family.set_item("outside_policy", spec.outside_policy)?;
        family.set_item("columns_layout", columns_layout(spec.columns))?;
        family.set_item(
            "gpu_kernel",
            crate::gpu::kernels::Kernel::of_work(method, false).is_some(),
        )?;
        let on_quads = matches!(spec.quads, crate::coords::QuadSupport::Patches { .. });
        family.set_item(
            "gpu_kernel_quads",
            crate::gpu::kernels::Kernel::of_work(method, on_quads).is_some(),
        )?;
        list.append(family)?;
    }
    Ok(list)
}

/// A parameter as a dict: ``id``, ``label``, ``default``, ``min``, ``max``,
/// the editor's ``choices`` and its ``named`` values.
fn parameter_entry<'py>(
    py: Python<'py>,
    parameter: &crate::coords::ParameterSpec,
) -> PyResult<Bound<'py, PyDict>> {
    let entry = PyDict::new(py);
    entry.set_item("id", parameter.key.id())?;
    entry.set_item("label", parameter.label)?;
    entry.set_item(
        "default",
        parameter_number(py, parameter, parameter.default),
    )?;
    entry.set_item("min", parameter_number(py, parameter, parameter.min))?;
    entry.set_item("max", parameter_number(py, parameter, parameter.max))?;
    let choices = PyList::empty(py);
    for &choice in parameter.choices {
        match parameter.name_of(choice) {
            Some(name) => choices.append(name)?,
            None => choices.append(parameter_number(py, parameter, choice))?,
        }
    }
    entry.set_item("choices", choices)?;
    let named: Vec<&str> = parameter.named.iter().map(|n| n.name).collect();
    entry.set_item("named", named)?;
    Ok(entry)
}

/// The name saved files give a column layout.
pub(super) fn columns_layout(layout: ColumnLayout) -> &'static str {
    match layout {
        ColumnLayout::CageVertices => "cage_vertices",
        ColumnLayout::CageVerticesThenTriangles => "cage_vertices_then_triangles",
        ColumnLayout::BlocksPerVertexThenTriangle => "blocks_per_vertex_then_triangle",
    }
}

/// A parameter's value as Python reads it: an int, or a float for a decimal
/// parameter (the Poisson ratio's 300 thousandths are 0.3).
pub(super) fn parameter_number<'py>(
    py: Python<'py>,
    spec: &crate::coords::ParameterSpec,
    value: u32,
) -> Bound<'py, PyAny> {
    if spec.scale > 1 {
        spec.number(value)
            .into_pyobject(py)
            .unwrap_or_else(|never| match never {})
            .into_any()
    } else {
        value
            .into_pyobject(py)
            .unwrap_or_else(|never| match never {})
            .into_any()
    }
}
