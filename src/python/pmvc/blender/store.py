"""Where a binding lives: the bound object's hidden ID property ``_pmvc``
(family, parameters, the cage object, a token) and, for the arrays, the ID
properties of a hidden Text data-block it points to (``.pmvc <object>``, with a
fake user). Both are saved with the .blend and restored by undo. The arrays
are not on the object because Blender copies an object's ID properties each
time it evaluates it (36 MB per cage move for Ogre's Green weights); a Text is
never evaluated. A cache holds the arrays rebuilt from it, keyed by a token
that changes with every bind."""

import bpy

import json
import uuid

import numpy as np

import pmvc
from pmvc import _native

KEY = "_pmvc"
#: Point attribute the geometry nodes modifier adds to the positions.
OFFSET = ".pmvc_offset"
FORMAT = 1

_cache = {}


class Binding:
    """The arrays of one binding, rebuilt from the object's property."""

    def __init__(self, token, weights, cage, points, method, parameters):
        self.token = token
        self.weights = weights
        self.cage = cage
        self.points = points
        self.method = method
        self.parameters = parameters
        self.rest = cage.vertices
        self.layout = weights.metadata.get("columns_layout", "cage_vertices")
        self.linear = self.layout == "cage_vertices"
        m = len(self.rest)
        # Green coordinates: φ for the cage vertices, then ψ for the triangles
        # (docs/python.md, "Green coordinates' columns"); other layouts, and
        # QGC's corner normals of quads, go through the package's deform.
        self.green = (self.layout == "cage_vertices_then_triangles" and weights.triangles is not None
                      and not weights.metadata.get("quads"))
        if self.green:
            self.triangles = np.asarray(weights.triangles, dtype=np.int64)
            u, w = self._edges(self.rest)
            self.u2, self.w2, self.uw = (u * u).sum(1), (w * w).sum(1), (u * w).sum(1)
            cross = np.cross(u, w)
            self.area = np.linalg.norm(cross, axis=1) / 2
            self.normals = cross / np.linalg.norm(cross, axis=1)[:, None]
            self.psi = np.ascontiguousarray(weights.matrix[:, m:])
        # Rows times the cage's moves in the weights' own type: float32 (half
        # the memory traffic of float64) unless bound as float64; against `pmvc deform`'s float64
        # sums that is 1e-7 of Ogre's cage diagonal at its target pose, the
        # size of the float32 rounding of the positions Blender stores.
        self.matrix = np.ascontiguousarray(weights.matrix[:, :m]) if self.linear or self.green else None
        #: Object name -> the cage pose its offsets were last written for.
        self.last_posed = {}

    def _edges(self, vertices):
        corners = vertices[self.triangles]
        return corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]

    def offsets(self, posed, settings):
        """The move of every point for the cage at ``posed`` (mesh space), with
        the deformation ``settings`` the family reads (Somigliana's bulging)."""
        if np.array_equal(posed, self.rest):  # at rest: not moved, exactly
            return np.zeros_like(self.points)
        if self.linear or self.green:
            moves = (posed - self.rest).astype(self.matrix.dtype)
            moved = moves.any(axis=1)
            out = _product(self.matrix, moves, moved)
            if self.green:
                u, w = self._edges(posed)
                stretch = np.sqrt((u * u).sum(1) * self.w2 - 2 * (u * w).sum(1) * self.uw + (w * w).sum(1) * self.u2)
                stretch /= np.sqrt(8.0) * self.area
                cross = np.cross(u, w)
                turned = stretch[:, None] * cross / np.linalg.norm(cross, axis=1)[:, None] - self.normals
                # A triangle none of whose corners moved adds nothing (its
                # term is 0 up to rounding).
                out += _product(self.psi, turned.astype(self.psi.dtype), moved[self.triangles].any(axis=1))
            return out.astype(np.float64)
        return pmvc.deform(self.points, self.cage, posed, weights=self.weights, **settings) - self.points


def _product(matrix, values, mask):
    """matrix @ values over the rows of ``values`` that ``mask`` keeps: only
    those columns are read when they are few (a dragged vertex)."""
    columns = np.flatnonzero(mask)
    if len(columns) == 0:
        return np.zeros((matrix.shape[0], 3), dtype=matrix.dtype)
    if len(columns) < len(mask) // 2:
        return matrix[:, columns] @ values[columns]
    return matrix @ values


def deform_property_name(pid):
    """The object property holding deformation setting ``pid``."""
    return f"pmvc_{pid}"


def deform_settings(obj):
    """{setting id: value} of the deformation settings ``obj``'s family reads
    (Somigliana's bulging), from its properties, to the hundredth the package
    holds (Blender's floats are single precision)."""
    settings = {}
    for spec in _deform_specs().get(obj[KEY]["method"], []):
        value = getattr(obj, deform_property_name(spec["id"]), spec["default"])
        settings[spec["id"]] = round(float(value), 2) if isinstance(spec["default"], float) else int(value)
    return settings


_deform_spec_cache = {}


def _deform_specs():
    """{method id: its deformation settings' specs}, read from the package once
    (the handlers ask at every depsgraph update)."""
    if not _deform_spec_cache:
        _deform_spec_cache.update({f["id"]: f.get("deform_parameters", []) for f in pmvc.families()})
    return _deform_spec_cache


def is_bound(obj):
    return obj is not None and obj.type == "MESH" and KEY in obj


def cage_of(obj):
    return obj[KEY].get("cage") if is_bound(obj) else None


def summary(obj):
    """(method id, parameters dict, cage object) of a bound object."""
    group = obj[KEY]
    return group["method"], json.loads(group["parameters"]), group.get("cage")


def save(obj, cage_obj, points, cage, weights, method, parameters):
    """Store a new binding on ``obj``; returns its Binding."""
    matrix = np.ascontiguousarray(weights.matrix)  # float32, or float64 where bound so
    faces = [list(map(int, f)) for f in cage.faces]
    metadata = weights.__reduce__()[1][2]
    token = uuid.uuid4().hex
    holder = bpy.data.texts.new(f".pmvc {obj.name}")
    holder.use_fake_user = True
    holder.write(f"pmvc binding of {obj.name} (its weights are this data-block's ID properties)\n")
    holder[KEY] = {
        "rows": matrix.shape[0],
        "columns": matrix.shape[1],
        "dtype": matrix.dtype.name,
        "matrix": matrix.ravel(),
        "classes": np.ascontiguousarray(weights.classes, dtype=np.int8).tobytes(),
        "metadata": metadata,
        "rest": np.ascontiguousarray(cage.vertices, dtype=np.float64).ravel(),
        "face_sizes": np.array([len(f) for f in faces], dtype=np.int32),
        "face_corners": np.array([i for f in faces for i in f], dtype=np.int32),
        "points": np.ascontiguousarray(points, dtype=np.float64).ravel(),
    }
    obj[KEY] = {
        "format": FORMAT,
        "token": token,
        "method": method,
        "parameters": json.dumps(parameters),
    }
    obj[KEY]["cage"] = cage_obj
    obj[KEY]["data"] = holder
    binding = Binding(token, weights, cage, points, method, parameters)
    _cache[token] = binding
    return binding


def load(obj):
    """The Binding of ``obj`` (from the cache, or rebuilt from the property).

    Raises pmvc.PmvcError or ValueError when the stored binding is unsound."""
    settings = obj[KEY]
    token = settings["token"]
    binding = _cache.get(token)
    if binding is not None:
        return binding
    if settings.get("format") != FORMAT:
        raise ValueError(f"{obj.name}: binding format {settings.get('format')} is not {FORMAT}")
    holder = settings.get("data")
    if holder is None or KEY not in holder:
        raise ValueError(f"{obj.name}: its binding's data-block was deleted: bind again")
    group = holder[KEY]
    rows, columns = int(group["rows"]), int(group["columns"])
    dtype = {"float32": np.float32, "float64": np.float64}[group.get("dtype", "float32")]
    matrix = np.frombuffer(group["matrix"], dtype=dtype).reshape(rows, columns).copy()
    classes = np.frombuffer(bytes(group["classes"]), dtype=np.int8).copy()
    weights = _native._restore_weights(matrix, classes, group["metadata"], None)
    rest = np.frombuffer(group["rest"], dtype=np.float64).reshape(-1, 3).copy()
    sizes = np.frombuffer(group["face_sizes"], dtype=np.int32)
    corners = np.frombuffer(group["face_corners"], dtype=np.int32).tolist()
    faces, start = [], 0
    for size in sizes.tolist():
        faces.append(corners[start:start + size])
        start += size
    cage = pmvc.Cage(rest, faces)
    points = np.frombuffer(group["points"], dtype=np.float64).reshape(-1, 3).copy()
    binding = Binding(token, weights, cage, points, settings["method"], json.loads(settings["parameters"]))
    _cache[token] = binding
    return binding


def forget(obj=None):
    """Drop cached arrays (of one object, or all) and pose memories."""
    if obj is None:
        _cache.clear()
        return
    if is_bound(obj):
        _cache.pop(obj[KEY]["token"], None)


def forget_poses():
    """After undo or load: the next update rewrites every offset."""
    for binding in _cache.values():
        binding.last_posed.clear()


def remove(obj):
    """Remove ``obj``'s binding, and its data-block unless another object uses it."""
    forget(obj)
    if KEY not in obj:
        return
    holder = obj[KEY].get("data")
    del obj[KEY]
    if holder is not None and not any(
            KEY in other and other[KEY].get("data") == holder for other in bpy.data.objects if other != obj):
        bpy.data.texts.remove(holder)
