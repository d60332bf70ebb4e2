"""Cages, weights, reports and errors pickle and copy exactly: every attribute
and every array equal bit for bit, and the copies bind and deform as the
originals do. Pickles are checked on loading as any input is."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import pmvc
from conftest import ASSETS, middle_finger_pose
from test_quads import inside_points, twisted_box

PROTOCOLS = range(0, pickle.HIGHEST_PROTOCOL + 1)
BOX = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    dtype=float,
)
BOX_FACES = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]


def hexagonal_prism():
    """A prism whose two caps are hexagons (fanned into triangles)."""
    angles = np.arange(6) * np.pi / 3
    ring = np.c_[np.cos(angles), np.sin(angles)]
    vertices = np.vstack([np.c_[ring, np.zeros(6)], np.c_[ring, np.ones(6)]])
    faces = [list(range(5, -1, -1)), list(range(6, 12))]
    faces += [[k, (k + 1) % 6, (k + 1) % 6 + 6, k + 6] for k in range(6)]
    return vertices, faces


def cages():
    vertices, faces = twisted_box()
    prism_vertices, prism_faces = hexagonal_prism()
    return {
        "comb from a file": pmvc.Cage.load(ASSETS / "comb_cage.obj"),
        "flipped box": pmvc.Cage(BOX, [face[::-1] for face in BOX_FACES]),
        "twisted box of quads": pmvc.Cage(vertices, faces),
        "hexagonal prism": pmvc.Cage(prism_vertices, prism_faces),
    }


def copies(value):
    """Every way a value is copied: each pickle protocol, copy and deepcopy."""
    for protocol in PROTOCOLS:
        yield f"pickle protocol {protocol}", pickle.loads(pickle.dumps(value, protocol=protocol))
    yield "copy.copy", copy.copy(value)
    yield "copy.deepcopy", copy.deepcopy(value)


def assert_same_array(a: np.ndarray, b: np.ndarray, what: str) -> None:
    assert a.dtype == b.dtype and a.shape == b.shape, what
    assert a.tobytes() == b.tobytes(), what


def assert_same_cage(a: pmvc.Cage, b: pmvc.Cage, what: str) -> None:
    for name in ("vertices", "triangles", "quads", "triangle_faces"):
        assert_same_array(getattr(a, name), getattr(b, name), f"{what}: {name}")
    assert a.faces == b.faces, what
    assert (a.flipped, a.volume, a.diagonal, a.notices, a.path, repr(a)) == (
        b.flipped,
        b.volume,
        b.diagonal,
        b.notices,
        b.path,
        repr(b),
    ), what


def assert_same_weights(a: pmvc.Weights, b: pmvc.Weights, what: str) -> None:
    assert_same_array(a.matrix, b.matrix, f"{what}: matrix")
    assert_same_array(a.classes, b.classes, f"{what}: classes")
    assert a.metadata == b.metadata, what
    for name in ("method", "parameters", "backend", "device", "seconds", "columns", "columns_layout"):
        assert getattr(a, name) == getattr(b, name), f"{what}: {name}"
    if a.triangles is None:
        assert b.triangles is None, what
    else:
        assert_same_array(a.triangles, b.triangles, f"{what}: triangles")
    assert repr(a) == repr(b), what


@pytest.mark.parametrize("name", list(cages()))
def test_a_cage_pickles_and_copies_exactly_and_binds_the_same(name):
    cage = cages()[name]
    points = cage.vertices.mean(axis=0) + 0.1 * (cage.vertices - cage.vertices.mean(axis=0))
    bound = pmvc.bind(points, cage, method="pmvc", resolution=8, backend="cpu")
    for how, copied in copies(cage):
        assert type(copied) is pmvc.Cage
        assert_same_cage(cage, copied, f"{name}, {how}")
        # The same cage to the weights: the metadata's digest of the cage agrees,
        # so weights bound on one deform with the other.
        again = pmvc.bind(points, copied, method="pmvc", resolution=8, backend="cpu")
        assert_same_array(bound.matrix, again.matrix, f"{name}, {how}: weights")
        assert again.metadata["cage"] == bound.metadata["cage"]
        moved = pmvc.deform(points, copied, copied.vertices * 1.5, weights=bound)
        assert_same_array(moved, pmvc.deform(points, cage, cage.vertices * 1.5, weights=bound), how)
    assert cages()["flipped box"].flipped


@pytest.mark.parametrize("method", ["mvc", "pmvc", "harmonic", "green"])
def test_weights_pickle_and_copy_exactly_and_deform_the_same(comb_cage, comb_points, method):
    points = comb_points[::17]
    weights = pmvc.bind(points, comb_cage, method=method, backend="cpu", resolution=8, grid=16)
    pose = middle_finger_pose(comb_cage)
    moved = pmvc.deform(points, comb_cage, pose, weights=weights)
    for how, copied in copies(weights):
        assert type(copied) is pmvc.Weights
        assert_same_weights(weights, copied, f"{method}, {how}")
        assert_same_array(moved, pmvc.deform(points, comb_cage, pose, weights=copied), how)
    # A deep copy owns its arrays; a pickle costs the arrays' bytes and little more.
    deep = copy.deepcopy(weights)
    assert not np.shares_memory(deep.matrix, weights.matrix)
    size = len(pickle.dumps(weights, protocol=pickle.HIGHEST_PROTOCOL))
    arrays = weights.matrix.nbytes + weights.classes.nbytes
    assert arrays < size < arrays + 20_000 + 200 * weights.matrix.shape[1]


def test_weights_read_from_a_file_keep_their_path(comb_cage, comb_points, tmp_path):
    weights = pmvc.bind(comb_points[::50], comb_cage, method="mvc", backend="cpu")
    pmvc.save_weights(tmp_path / "W.npy", weights)
    loaded = pmvc.load_weights(tmp_path / "W.npy")
    for how, copied in copies(loaded):
        assert_same_weights(loaded, copied, how)
        # Messages about the copy still name the file.
        with pytest.raises(pmvc.WeightsError, match="W.npy"):
            pmvc.deform(comb_points[:3], comb_cage, comb_cage.vertices, weights=copied)


def test_a_generated_cage_and_its_report_pickle(comb_points):
    _, faces = pmvc.load_mesh(ASSETS / "comb_mesh.obj")
    cage, report = pmvc.generate_cage(comb_points, faces, target=60)
    for how, (copied, copied_report) in copies((cage, report)):
        assert_same_cage(cage, copied, how)
        assert copied_report.keys() == report.keys()
        for key, value in report.items():
            if isinstance(value, np.ndarray):
                assert_same_array(value, copied_report[key], f"{how}: {key}")
            else:
                assert copied_report[key] == value or (value != value and copied_report[key] != copied_report[key])


def test_quads_weights_keep_their_split(comb_points):
    vertices, faces = twisted_box()
    cage = pmvc.Cage(vertices, faces)
    points = inside_points(20)
    for split in (None, "shorter", "longer"):
        weights = pmvc.bind(points, cage, method="mvc", backend="cpu", triangulate=split)
        for how, copied in copies(weights):
            assert_same_weights(weights, copied, f"{split}, {how}")
            assert copied.metadata["quad_split"] == (split or "none")


@pytest.mark.parametrize(
    "error",
    [pmvc.InputError, pmvc.ParameterError, pmvc.FileError, pmvc.CageError, pmvc.WeightsError,
     pmvc.BackendError, pmvc.BindError, pmvc.TooLargeError, pmvc.PmvcError],
)
def test_errors_pickle_with_their_file_and_line(error):
    raised = error("bad.obj:3: vertex 2: 'x' is not a number", path="bad.obj", line=3)
    for how, copied in copies(raised):
        assert type(copied) is error, how
        assert (str(copied), copied.path, copied.line) == (str(raised), "bad.obj", 3), how


def test_a_raised_error_pickles(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 x 0\n")
    with pytest.raises(pmvc.FileError) as raised:
        pmvc.load_mesh(bad)
    copied = pickle.loads(pickle.dumps(raised.value))
    assert type(copied) is pmvc.FileError and isinstance(copied, OSError)
    assert (str(copied), copied.path, copied.line) == (str(raised.value), str(bad), 2)


def test_a_tampered_pickle_is_refused_with_a_reason(comb_cage, comb_points):
    restore, (vertices, triangles, triangle_faces, path, _) = comb_cage.__reduce__()
    bad = triangles.copy()
    bad[5, 1] = len(vertices)
    with pytest.raises(pmvc.InputError, match="pickled cage: triangles: face 5 refers to vertex 40"):
        restore(vertices, bad, triangle_faces, path)
    with pytest.raises(pmvc.InputError, match="4 triangle faces for 76 triangles"):
        restore(vertices, triangles, triangle_faces[:4], path)
    with pytest.raises(pmvc.CageError):
        restore(vertices, triangles[1:], triangle_faces[1:], path)
    weights = pmvc.bind(comb_points[:10], comb_cage, method="mvc", backend="cpu")
    restore, (matrix, classes, metadata, path) = weights.__reduce__()
    with pytest.raises(pmvc.WeightsError, match="float32"):
        restore(matrix.astype(np.float16), classes, metadata, path)
    with pytest.raises(pmvc.WeightsError, match=r"shape \(9, 40\)"):
        restore(matrix[1:], classes, metadata, path)
    with pytest.raises(pmvc.WeightsError, match="9 classes for 10 rows"):
        restore(matrix, classes[1:], metadata, path)
    with pytest.raises(pmvc.WeightsError, match="not W.json"):
        restore(matrix, classes, "{", path)
    with pytest.raises(pmvc.WeightsError, match="method"):
        restore(matrix, classes, metadata.replace('"method": "mvc"', '"method": "qvc"'), path)


def misaligned(array: np.ndarray) -> np.ndarray:
    """A copy of `array` one byte into a buffer: contiguous but misaligned, as
    arrays rebuilt from a message (a Dask worker's) can be."""
    raw = np.zeros(array.nbytes + 1, dtype=np.uint8)
    copy = np.frombuffer(raw.data, dtype=array.dtype, count=array.size, offset=1).reshape(array.shape)
    copy[...] = array
    assert not copy.flags.aligned or array.dtype.itemsize == 1
    return copy


def test_misaligned_arrays_are_read_as_they_are(comb_cage, comb_points):
    points = comb_points[::40]
    expected = pmvc.bind(points, comb_cage, method="mvc", backend="cpu")
    weights = pmvc.bind(misaligned(points), comb_cage, method="mvc", backend="cpu")
    assert weights.matrix.tobytes() == expected.matrix.tobytes()
    restore, (vertices, triangles, triangle_faces, path, _) = comb_cage.__reduce__()
    cage = restore(misaligned(vertices), misaligned(triangles), misaligned(triangle_faces), path)
    assert_same_cage(comb_cage, cage, "misaligned")
    restore, (matrix, classes, metadata, path) = expected.__reduce__()
    copied = restore(misaligned(matrix), misaligned(classes), metadata, path)
    assert_same_weights(expected, copied, "misaligned")
    moved = pmvc.deform(points, comb_cage, misaligned(comb_cage.vertices * 2), weights=copied)
    assert moved.tobytes() == pmvc.deform(points, comb_cage, comb_cage.vertices * 2, weights=expected).tobytes()
