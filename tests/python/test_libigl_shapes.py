"""libigl's shapes: a cage given as (V, F) wherever a Cage is taken, F an
integer array or a list of polygons; load_mesh's faces as an (m, 3) int64
array for a triangle mesh; strict=; and every error, wrong types included, a
PmvcError naming the argument."""

from __future__ import annotations

import re
import subprocess

import numpy as np
import pytest

import pmvc
from conftest import ASSETS, middle_finger_pose, write_cage_obj, write_points_obj
from test_quads import inside_points, twisted_box


@pytest.fixture(scope="module")
def comb():
    vertices, faces = pmvc.load_mesh(ASSETS / "comb_cage.obj")
    points, _ = pmvc.load_mesh(ASSETS / "comb_mesh.obj")
    return vertices, faces, points[::7]


def test_load_mesh_gives_a_triangle_mesh_as_an_int64_array(comb):
    vertices, faces, _ = comb
    assert isinstance(faces, np.ndarray) and faces.dtype == np.int64 and faces.shape == (76, 3)
    assert vertices.dtype == np.float64 and vertices.shape == (40, 3)
    # The file's own `f` lines, read here: 1-based indices in file order.
    lines = [line.split()[1:] for line in open(ASSETS / "comb_cage.obj") if line.startswith("f ")]
    expected = np.array([[int(corner.split("/")[0]) - 1 for corner in line] for line in lines])
    np.testing.assert_array_equal(faces, expected)


def test_load_mesh_keeps_polygons_as_lists(tmp_path):
    vertices, faces = twisted_box(roof=True)
    path = write_cage_obj(tmp_path / "roofed.obj", vertices, faces)
    loaded_vertices, loaded_faces = pmvc.load_mesh(path)
    assert isinstance(loaded_faces, list) and loaded_faces == [list(face) for face in faces]
    np.testing.assert_array_equal(loaded_vertices, vertices)


@pytest.mark.parametrize("dtype", [np.int64, np.int32, np.uint32, np.uint16, np.intp])
def test_a_cage_from_an_integer_face_array_is_the_cage_from_lists(comb, dtype):
    vertices, faces, points = comb
    from_lists = pmvc.Cage(vertices, faces.tolist())
    from_array = pmvc.Cage(vertices, faces.astype(dtype))
    np.testing.assert_array_equal(from_array.triangles, from_lists.triangles)
    assert from_array.faces == from_lists.faces
    a = pmvc.bind(points, from_lists, method="mvc", backend="cpu").matrix
    b = pmvc.bind(points, from_array, method="mvc", backend="cpu").matrix
    assert a.tobytes() == b.tobytes()


def test_every_function_takes_a_cage_as_v_f(comb):
    vertices, faces, points = comb
    cage = pmvc.Cage(vertices, faces)
    pose = middle_finger_pose(cage)
    for given in [(vertices, faces), [vertices, faces], (vertices, faces.tolist()), (vertices.tolist(), faces)]:
        for method in ["mvc", "pmvc", "green"]:
            expected = pmvc.bind(points, cage, method=method, backend="cpu", resolution=8)
            weights = pmvc.bind(points, given, method=method, backend="cpu", resolution=8)
            assert weights.matrix.tobytes() == expected.matrix.tobytes()
            assert weights.metadata["cage"] == expected.metadata["cage"]
            # Weights bound on a Cage deform the same cage given as (V, F).
            moved = pmvc.deform(points, given, pose, weights=expected)
            assert moved.tobytes() == pmvc.deform(points, cage, pose, weights=expected).tobytes()
        np.testing.assert_array_equal(pmvc.classify(points, given), pmvc.classify(points, cage))
        bound_and_moved = pmvc.deform(points, given, pose, method="mvc", backend="cpu")
        np.testing.assert_array_equal(bound_and_moved, pmvc.deform(points, cage, pose, method="mvc", backend="cpu"))


def test_a_quad_cage_as_v_f_keeps_its_quads():
    vertices, faces = twisted_box()
    points = inside_points(10)
    qmvc = pmvc.bind(points, (vertices, faces), method="mvc", backend="cpu")
    assert qmvc.metadata["method_name"] == "QMVC"
    as_array = pmvc.bind(points, (vertices, np.array(faces)), method="mvc", backend="cpu")
    assert as_array.matrix.tobytes() == qmvc.matrix.tobytes()


def test_generate_cage_takes_the_arrays_load_mesh_gives():
    vertices, faces = pmvc.load_mesh(ASSETS / "comb_mesh.obj")
    assert isinstance(faces, np.ndarray)
    cage, report = pmvc.generate_cage(vertices, faces, target=60)
    same, _ = pmvc.generate_cage(vertices, faces.tolist(), target=60)
    np.testing.assert_array_equal(cage.vertices, same.vertices)
    assert report["vertices"] == len(cage.vertices)


@pytest.mark.parametrize(
    "faces,words",
    [
        (np.array([[0, 1, 40]] * 3), "cage faces: face 0 refers to vertex 40, but there are 40 vertices"),
        (np.array([[0, 1, 2], [0, -1, 2]]), "cage faces: face 1 refers to vertex -1"),
        (np.zeros((4, 2), dtype=np.int64), "cage faces: face 0 has 2 corners"),
        (np.array([[0, 1, 2]], dtype=np.uint64) + np.uint64(2**63), "refers to vertex 9223372036854775807"),
        (np.array([[0.0, 1.0, 2.0]]), "is not an integer vertex index"),
    ],
)
def test_bad_face_arrays_name_the_face(comb, faces, words):
    vertices, _, points = comb
    with pytest.raises(pmvc.InputError) as raised:
        pmvc.bind(points, (vertices, faces), method="mvc")
    assert words in str(raised.value)


def arguments_of_the_wrong_type(comb, tmp_path):
    vertices, faces, points = comb
    cage = pmvc.Cage(vertices, faces)
    weights = pmvc.bind(points, cage, method="mvc", backend="cpu")
    return [
        (lambda: pmvc.bind(points, 3), pmvc.InputError, "cage: 3 (int) is neither a pmvc.Cage nor a (vertices, faces) pair"),
        (lambda: pmvc.bind(points, (vertices,)), pmvc.InputError, "a (vertices, faces) pair has 2 items, not 1"),
        (lambda: pmvc.bind(points, cage, method=3), pmvc.ParameterError, "method must be a string, not 3 (int)"),
        (lambda: pmvc.bind(points, cage, backend=1.5), pmvc.ParameterError, "bind: backend must be a string"),
        (lambda: pmvc.bind(points, cage, pmvc_kernel=[]), pmvc.ParameterError, "bind: pmvc_kernel must be a string"),
        (lambda: pmvc.bind(points, cage, strict="yes"), pmvc.ParameterError, "bind: strict must be True or False"),
        (lambda: pmvc.bind(points, cage, resolution="32"), pmvc.ParameterError, "resolution must be an integer"),
        (lambda: pmvc.bind(points, cage, triangulate=2), pmvc.ParameterError, "triangulate must be None"),
        (lambda: pmvc.bind(points, cage, progress=5), pmvc.InputError, "progress: int is not callable"),
        (lambda: pmvc.deform(points, cage, vertices, weights=3), pmvc.InputError, "weights: 3 (int) is not a pmvc.Weights"),
        (lambda: pmvc.deform(points, cage, vertices, weights=weights, method=2), pmvc.ParameterError, "deform: method must be a string"),
        (lambda: pmvc.deform(points, 7, vertices, weights=weights), pmvc.InputError, "cage: 7 (int)"),
        (lambda: pmvc.deform(points, cage, vertices, strict=1), pmvc.ParameterError, "deform: strict must be True or False"),
        (lambda: pmvc.classify(points, None), pmvc.InputError, "cage: None (NoneType)"),
        (lambda: pmvc.classify(points, cage, method=1), pmvc.ParameterError, "method must be a string"),
        (lambda: pmvc.load_mesh(3), pmvc.InputError, "load_mesh: 3 (int) is not a file path"),
        (lambda: pmvc.Cage.load(None), pmvc.InputError, "Cage.load: None (NoneType) is not a file path"),
        (lambda: pmvc.save_weights(3, weights), pmvc.InputError, "save_weights: 3 (int) is not a file path"),
        (lambda: pmvc.save_weights(tmp_path / "W.npy", cage), pmvc.InputError, "save_weights: weights: Cage("),
        (lambda: pmvc.load_weights(1.0), pmvc.InputError, "load_weights: 1.0 (float) is not a file path"),
        (lambda: pmvc.generate_cage(vertices, faces, target="60"), pmvc.ParameterError, "generate_cage: target must be an integer"),
        (lambda: pmvc.generate_cage(vertices, faces, 60, clearance="a"), pmvc.ParameterError, "clearance must be a number or None"),
        (lambda: pmvc.generate_cage(vertices, faces, 60, quads="yes"), pmvc.ParameterError, "quads must be True or False"),
        (lambda: pmvc.Cage(vertices, 5), pmvc.InputError, "cage faces: not a sequence of faces"),
    ]


def test_arguments_of_the_wrong_type_raise_pmvc_errors_naming_them(comb, tmp_path):
    for call, error, words in arguments_of_the_wrong_type(comb, tmp_path):
        with pytest.raises(error) as raised:
            call()
        assert isinstance(raised.value, pmvc.PmvcError)
        assert words in str(raised.value), str(raised.value)


def test_strict_refuses_points_outside_the_cage_as_the_command_line_does(comb, tmp_path, pmvc_bin):
    vertices, faces, points = comb
    cage = pmvc.Cage(vertices, faces)
    outside = np.vstack([points, vertices.max(axis=0) + [[1.0, 0, 0], [2.0, 0, 0]]])
    # Inside points bind under strict=True as without it.
    strict = pmvc.bind(points, cage, method="mvc", backend="cpu", strict=True)
    assert strict.matrix.tobytes() == pmvc.bind(points, cage, method="mvc", backend="cpu").matrix.tobytes()
    with pytest.raises(pmvc.InputError) as raised:
        pmvc.bind(outside, cage, method="pmvc", strict=True)
    message = str(raised.value)
    n = len(points)
    assert message.startswith(f"points: 2 of {n + 2} vertices") and f"(first: {n}, {n + 1})" in message
    assert message.endswith("(strict=True)")
    # The command line's --strict says the same of the same points.
    mesh = write_points_obj(tmp_path / "outside.obj", outside)
    cage_file = write_cage_obj(tmp_path / "cage.obj", vertices, faces)
    result = subprocess.run(
        [str(pmvc_bin), "bind", "--mesh", str(mesh), "--cage", str(cage_file), "--strict",
         "--method", "mvc", "--out", str(tmp_path / "W.npy")],
        capture_output=True, text=True,
    )
    assert result.returncode != 0
    summary = re.search(r"\d+ of \d+ vertices .*\)", message.removeprefix("points: ")).group(0)
    summary = summary.removesuffix(" (strict=True)")
    assert summary in result.stderr, result.stderr
    # deform: when it binds, and with weights that have outside rows.
    pose = middle_finger_pose(cage)
    with pytest.raises(pmvc.InputError, match="strict=True"):
        pmvc.deform(outside, cage, pose, method="mvc", strict=True)
    loose = pmvc.bind(outside, cage, method="mvc", backend="cpu")
    with pytest.raises(pmvc.InputError, match=r"2 of \d+ vertices"):
        pmvc.deform(outside, cage, pose, weights=loose, strict=True)
    pmvc.deform(points, cage, pose, weights=strict, strict=True)
    assert not (tmp_path / "W.npy").exists()
