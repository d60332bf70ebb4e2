"""Bad input raises a pmvc exception naming what is wrong, never a crash."""

from __future__ import annotations

import numpy as np
import pytest

import pmvc
from conftest import ASSETS

BOX = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    dtype=float,
)
BOX_FACES = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]


@pytest.fixture(scope="module")
def box():
    return pmvc.Cage(BOX, BOX_FACES)


@pytest.mark.parametrize(
    "points,words",
    [
        (np.zeros((4, 2)), "shape (4, 2) is not (n, 3)"),
        (np.zeros(3), "shape (3,) is not (n, 3)"),
        (np.zeros((2, 3, 1)), "is not (n, 3)"),
        ([[0.5, 0.5, 0.5], [0.5, np.nan, 0.5]], "row 1 is not finite (0.5, NaN, 0.5)"),
        ([[0.5, 0.5, np.inf]], "row 0 is not finite"),
        (np.array([["a", "b", "c"]]), "dtype <U1 is not a real number type"),
        (np.zeros((1, 3), dtype=complex), "dtype complex128 is not a real number type"),
        (np.zeros((1, 3), dtype=bool), "dtype bool is not a real number type"),
        ([[0, 0], [0, 0, 0]], "points: not an array of numbers"),
    ],
)
def test_bad_points_raise_input_errors(box, points, words):
    with pytest.raises(pmvc.InputError) as raised:
        pmvc.bind(points, box, method="mvc")
    assert words in str(raised.value) and str(raised.value).startswith("points: ")
    assert isinstance(raised.value, ValueError) and isinstance(raised.value, pmvc.PmvcError)


def test_any_real_dtype_and_array_like_is_accepted(box):
    inside = [[0.25, 0.5, 0.5], [0.5, 0.5, 0.75]]
    expected = pmvc.bind(np.array(inside), box, method="mvc").matrix
    for given in (inside, np.array(inside, dtype=np.float32), tuple(map(tuple, inside))):
        np.testing.assert_array_equal(pmvc.bind(given, box, method="mvc").matrix, expected)
    ints = pmvc.bind(np.array([[0, 0, 0]], dtype=np.int32), box, method="mvc")
    assert ints.classes[0] == pmvc.ON_CAGE


@pytest.mark.parametrize(
    "faces,error,words",
    [
        ([[0, 1, 8]] + BOX_FACES[1:], pmvc.InputError, "face 0 refers to vertex 8, but there are 8 vertices"),
        ([[0, 1, -1]] + BOX_FACES[1:], pmvc.InputError, "face 0 refers to vertex -1"),
        ([[0, 1]] + BOX_FACES[1:], pmvc.InputError, "face 0 has 2 corners"),
        ([[0, 1, 2.5]] + BOX_FACES[1:], pmvc.InputError, "face 0: 2.5 is not an integer vertex index"),
        (BOX_FACES[1:], pmvc.CageError, "the cage is not closed"),
        ([BOX_FACES[0][::-1]] + BOX_FACES[1:], pmvc.CageError, "oriented inconsistently"),
        (5, pmvc.InputError, "not a sequence of faces"),
    ],
)
def test_bad_cages_raise_with_the_face(faces, error, words):
    with pytest.raises(error) as raised:
        pmvc.Cage(BOX, faces)
    assert words in str(raised.value)


def test_a_bad_file_names_the_file_and_line(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 1 x 0\nf 1 2 3\n")
    with pytest.raises(pmvc.FileError) as raised:
        pmvc.load_mesh(bad)
    assert raised.value.path == str(bad) and raised.value.line == 3
    assert str(raised.value).startswith(f"{bad}:3: vertex 2: 'x' is not a number")
    with pytest.raises(pmvc.FileError) as raised:
        pmvc.Cage.load(bad)
    assert raised.value.line == 3
    out_of_range = tmp_path / "range.obj"
    out_of_range.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\n")
    with pytest.raises(pmvc.FileError, match=r"range.obj:4: face 1 refers to vertex 9"):
        pmvc.load_mesh(out_of_range)
    with pytest.raises(pmvc.FileError, match="No such file"):
        pmvc.load_mesh(tmp_path / "missing.obj")
    with pytest.raises(pmvc.FileError, match="unknown mesh format"):
        pmvc.load_mesh(tmp_path / "mesh.stl")
    open_box = tmp_path / "open.obj"
    open_box.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in BOX)
        + "".join("f " + " ".join(str(i + 1) for i in f) + "\n" for f in BOX_FACES[1:])
    )
    with pytest.raises(pmvc.CageError, match=r"open.obj: the cage is not closed"):
        pmvc.Cage.load(open_box)


@pytest.mark.parametrize(
    "arguments,words",
    [
        ({"method": "nope"}, 'method "nope" is not a family; known: mvc, pmvc, harmonic, green'),
        ({"method": "pmvc", "resolution": 0}, "resolution 0 is out of range: the PMVC resolution must be 1 to 1024"),
        ({"method": "pmvc", "resolution": -3}, "resolution -3 is out of range"),
        ({"method": "pmvc", "resolution": 2**70}, f"resolution {2**70} is out of range"),
        ({"method": "pmvc", "resolution": 1.5}, "resolution must be an integer"),
        ({"method": "harmonic", "grid": 3}, "grid 3 is out of range: the harmonic grid must be 4 to 2048"),
        ({"method": "mvc", "backend": "tpu"}, 'backend "tpu" is not one of "auto", "cpu", "gpu"'),
        ({"method": "pmvc", "pmvc_kernel": "warp"}, "unknown PMVC kernel 'warp' (expected auto, tiles or bands)"),
    ],
)
def test_bad_parameters_raise_parameter_errors(box, arguments, words):
    with pytest.raises(pmvc.ParameterError) as raised:
        pmvc.bind([[0.5, 0.5, 0.5]], box, **arguments)
    assert words in str(raised.value)


def test_work_that_cannot_fit_in_memory_is_refused_with_its_size(box):
    with pytest.raises(pmvc.TooLargeError, match=r"(HC bind at grid|a grid of) 2048") as raised:
        pmvc.bind([[0.5, 0.5, 0.5]], box, method="harmonic", grid=2048)
    assert isinstance(raised.value, MemoryError)


def test_a_progress_that_is_not_callable_is_refused(box):
    with pytest.raises(pmvc.InputError, match="progress: int is not callable"):
        pmvc.bind([[0.5, 0.5, 0.5]], box, progress=5)


def test_a_parameter_of_another_family_is_not_read(box):
    weights = pmvc.bind([[0.5, 0.5, 0.5]], box, method="mvc", resolution=0, grid=1)
    assert weights.parameters == {}


def test_deform_refuses_what_does_not_fit(box):
    points = [[0.5, 0.5, 0.5], [0.25, 0.5, 0.5]]
    weights = pmvc.bind(points, box, method="mvc")
    with pytest.raises(pmvc.InputError, match="7 vertices, but the cage has 8"):
        pmvc.deform(points, box, BOX[:7], weights=weights)
    with pytest.raises(pmvc.WeightsError, match="bound for other inputs: rows is 2 there, 3 here"):
        pmvc.deform(points + [[0.5, 0.5, 0.25]], box, BOX, weights=weights)
    with pytest.raises(pmvc.WeightsError, match="bound for other inputs: mesh.digest is"):
        pmvc.deform([[0.5, 0.5, 0.5], [0.25, 0.5, 0.25]], box, BOX, weights=weights)
    moved_box = pmvc.Cage(BOX + 0.01, BOX_FACES)
    with pytest.raises(pmvc.WeightsError, match="bound for other inputs: cage.digest is"):
        pmvc.deform(points, moved_box, BOX, weights=weights)
    with pytest.raises(pmvc.WeightsError, match='method "green" was asked for, but the weights are mvc'):
        pmvc.deform(points, box, BOX, weights=weights, method="green")
    with pytest.raises(pmvc.ParameterError, match='"resolution" is for binding'):
        pmvc.deform(points, box, BOX, weights=weights, resolution=8)
    with pytest.raises(pmvc.ParameterError, match='unknown parameter "resolutoin"'):
        pmvc.deform(points, box, BOX, resolutoin=8)
    # The matrix is a numpy array its owner may change: it is checked when applied.
    weights.matrix[1, 3] = np.nan
    with pytest.raises(pmvc.WeightsError, match=r"^weights: row 1, column 3 is not finite"):
        pmvc.deform(points, box, BOX, weights=weights)
    weights.matrix[1, 3] = 0.5
    with pytest.raises(pmvc.WeightsError, match=r"row 1's cage-vertex weights sum to"):
        pmvc.deform(points, box, BOX, weights=weights)


def test_generate_cage_refuses_bad_targets_and_flat_meshes(comb_points):
    _, faces = pmvc.load_mesh(ASSETS / "comb_mesh.obj")
    with pytest.raises(pmvc.ParameterError, match="at least 8 vertices; 3 were asked for"):
        pmvc.generate_cage(comb_points, faces, target=3)
    with pytest.raises(pmvc.ParameterError, match="target -1: a cage needs at least 8 vertices"):
        pmvc.generate_cage(comb_points, faces, target=-1)
    with pytest.raises(pmvc.ParameterError, match="the clearance must be a positive fraction"):
        pmvc.generate_cage(comb_points, faces, target=60, clearance=-0.5)
    flat = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    with pytest.raises(pmvc.InputError, match="flat"):
        pmvc.generate_cage(flat, [[0, 1, 2]], target=8)
