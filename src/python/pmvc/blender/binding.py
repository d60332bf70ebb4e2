"""From Blender objects to a bind and back: what the operators share."""

import numpy as np

import pmvc

from . import deform, store


class InputProblem(Exception):
    """Input the operators refuse, with the sentence they report."""


def families():
    """The package's families, as it lists them (new ones appear by themselves)."""
    return pmvc.families()


def family(method):
    for entry in families():
        if entry["id"] == method.lower():
            return entry
    raise InputProblem(f"unknown method {method!r}: one of {', '.join(f['id'].upper() for f in families())}")


def parameter_specs():
    """{parameter id: spec} over every family (the operators' integer settings)."""
    specs = {}
    for entry in families():
        for parameter in entry["parameters"]:
            specs.setdefault(parameter["id"], parameter)
    return specs


def deform_parameter_specs():
    """{setting id: spec} over every family of the settings read when deforming,
    not binding (Somigliana's bulging): each is a property of the bound object
    (:func:`store.deform_property_name`)."""
    specs = {}
    for entry in families():
        for parameter in entry.get("deform_parameters", []):
            specs.setdefault(parameter["id"], parameter)
    return specs


def parameters_for(method, values):
    """The parameters ``method`` reads, from ``values`` (a dict of every one).

    Families share a setting by its id (the grid of harmonic coordinates, BBW and LBC);
    left at the setting's default, each family takes its own default (BBW's
    grid is 32, not harmonic coordinates' 64)."""
    shared = parameter_specs()
    chosen = {}
    for p in family(method)["parameters"]:
        if p["id"] in values:
            value = parameter_value(p, values[p["id"]])
            chosen[p["id"]] = p["default"] if value == shared[p["id"]]["default"] else value
    return chosen


def is_decimal(spec):
    """Whether a parameter is a decimal (the Poisson ratio), not a whole number."""
    return isinstance(spec["default"], float)


def parameter_value(spec, value):
    """A setting's value as the package takes it: a whole number, or a decimal
    to the thousandth the package holds (Blender's floats are single precision)."""
    return round(float(value), 3) if is_decimal(spec) else int(value)


def mesh_and_cage(context):
    """(mesh object, cage object) from the selection: the active object and
    one other selected mesh object."""
    obj = context.active_object
    if obj is None:
        raise InputProblem("no active object: select the cage, then the mesh (active)")
    if obj.type != "MESH":
        raise InputProblem(f"the active object {obj.name!r} is a {obj.type.lower()}, not a mesh")
    others = [o for o in context.selected_objects if o != obj]
    if len(others) != 1:
        raise InputProblem(f"select exactly one cage besides the mesh {obj.name!r} ({len(others)} other objects are selected)")
    cage_obj = others[0]
    if cage_obj.type != "MESH":
        raise InputProblem(f"the cage {cage_obj.name!r} is a {cage_obj.type.lower()}, not a mesh")
    return obj, cage_obj


def inputs(obj, cage_obj, depsgraph):
    """(points, cage) in ``obj``'s space: its own vertices, and the cage's
    evaluated vertices and faces, validated as `pmvc check` validates a cage."""
    if obj.mode == "EDIT" or cage_obj.mode == "EDIT":
        raise InputProblem("leave Edit Mode first (the mesh and cage are read as Object Mode has them)")
    mesh = obj.data
    if len(mesh.vertices) == 0:
        raise InputProblem(f"the mesh {obj.name!r} has no vertices")
    points = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", points)
    points = points.reshape(-1, 3).astype(np.float64)
    coordinates, faces = deform.evaluated_cage(cage_obj, depsgraph)
    if not faces:
        raise InputProblem(f"the cage {cage_obj.name!r} has no faces")
    coordinates = deform.to_mesh_space(obj.evaluated_get(depsgraph), cage_obj.evaluated_get(depsgraph), coordinates)
    try:
        cage = pmvc.Cage(coordinates, faces)
    except pmvc.PmvcError as error:
        message = str(error).removeprefix("cage: ")
        if "counted from 1" in message:
            message += "; Blender's indices are one less"
        raise InputProblem(f"cage {cage_obj.name!r}: {message}") from error
    return points, cage


def run_bind(points, cage, method, parameters, progress=None):
    """The package's bind (the GIL is released while it works)."""
    return pmvc.bind(points, cage, method=method.lower(), progress=progress, backend="auto", **parameters)


def apply(context, obj, cage_obj, points, cage, weights, method, parameters):
    """Store the binding on ``obj`` and deform it for the cage as it is."""
    if len(obj.data.vertices) != len(points):
        raise InputProblem(f"the mesh {obj.name!r} changed while it was being bound: bind again")
    store.remove(obj)  # a rebind: the previous binding's data goes
    store.save(obj, cage_obj, points, cage, weights, method.lower(), parameters)
    deform.attach(obj)
    deform.update_object(obj, context.evaluated_depsgraph_get())


def release(obj):
    deform.detach(obj)
    store.remove(obj)
