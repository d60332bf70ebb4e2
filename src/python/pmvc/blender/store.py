"""Where a binding lives: in the bound object's hidden ID property ``_pmvc``,
so that it is saved with the .blend and restored by undo, and a cache of the
arrays rebuilt from it (keyed by a token that changes with every bind)."""

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
        # Rows times the cage's moves in float32 (the weights' own type, half
        # the memory traffic of float64: 3.7 ms instead of 9 ms for Ogre's
        # 26,155 x 118 on 2 cores); against `pmvc deform`'s float64 sums that
        # is 7e-8 of Ogre's cage diagonal at its target pose, the size of
        # the float32 rounding of the positions Blender stores.
        # Column-major, so that the columns of the cage vertices that moved
        # (one, while a vertex is dragged) are read alone.
        self.matrix = np.asfortranarray(weights.matrix[:, :m]) if self.linear else None
        self.last_posed = None

    def offsets(self, posed):
        """The move of every point for the cage at ``posed`` (mesh space)."""
        if np.array_equal(posed, self.rest):  # at rest: not moved, exactly
            return np.zeros_like(self.points)
        if self.linear:
            moves = (posed - self.rest).astype(np.float32)
            moved = np.flatnonzero(moves.any(axis=1))
            if len(moved) < len(moves) // 2:
                return (self.matrix[:, moved] @ moves[moved]).astype(np.float64)
            return (self.matrix @ moves).astype(np.float64)
        return pmvc.deform(self.points, self.cage, posed, weights=self.weights) - self.points


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
    matrix = np.ascontiguousarray(weights.matrix, dtype=np.float32)
    faces = [list(map(int, f)) for f in cage.faces]
    metadata = weights.__reduce__()[1][2]
    token = uuid.uuid4().hex
    obj[KEY] = {
        "format": FORMAT,
        "token": token,
        "method": method,
        "parameters": json.dumps(parameters),
        "rows": matrix.shape[0],
        "columns": matrix.shape[1],
        "matrix": matrix.ravel(),
        "classes": np.ascontiguousarray(weights.classes, dtype=np.int8).tobytes(),
        "metadata": metadata,
        "rest": np.ascontiguousarray(cage.vertices, dtype=np.float64).ravel(),
        "face_sizes": np.array([len(f) for f in faces], dtype=np.int32),
        "face_corners": np.array([i for f in faces for i in f], dtype=np.int32),
        "points": np.ascontiguousarray(points, dtype=np.float64).ravel(),
    }
    obj[KEY]["cage"] = cage_obj
    binding = Binding(token, weights, cage, points, method, parameters)
    _cache[token] = binding
    return binding


def load(obj):
    """The Binding of ``obj`` (from the cache, or rebuilt from the property).

    Raises pmvc.PmvcError or ValueError when the stored binding is unsound."""
    group = obj[KEY]
    token = group["token"]
    binding = _cache.get(token)
    if binding is not None:
        return binding
    if group.get("format") != FORMAT:
        raise ValueError(f"{obj.name}: binding format {group.get('format')} is not {FORMAT}")
    rows, columns = int(group["rows"]), int(group["columns"])
    matrix = np.frombuffer(group["matrix"], dtype=np.float32).reshape(rows, columns).copy()
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
    binding = Binding(token, weights, cage, points, group["method"], json.loads(group["parameters"]))
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
        binding.last_posed = None


def remove(obj):
    forget(obj)
    if KEY in obj:
        del obj[KEY]
