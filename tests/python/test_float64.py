"""float64 weights (dtype=numpy.float64, `pmvc bind --dtype f64`): every row as
computed, checked against an independent numpy implementation of mean value
coordinates (Ju et al. 2005) to 1e-12 where float32 stops at 3e-8, stored as
'<f8' with the metadata saying so, read back and deformed bit for bit, and the
same bytes from Python and the command line."""

from __future__ import annotations

import json
import pickle
import subprocess

import numpy as np
import pytest

import pmvc
from conftest import ASSETS, middle_finger_pose, run_pmvc, write_cage_obj, write_points_obj
from test_quads import inside_points, twisted_box


def mvc_numpy(x: np.ndarray, vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Mean value coordinates of one point strictly inside a triangle cage, as
    Ju, Schaefer and Warren (2005) give them (their robust form), in float64."""
    weights = np.zeros(len(vertices))
    d = np.linalg.norm(vertices - x, axis=1)
    u = (vertices - x) / d[:, None]
    for triangle in triangles:
        ut = u[triangle]
        lengths = np.array([np.linalg.norm(ut[(i + 1) % 3] - ut[(i + 2) % 3]) for i in range(3)])
        theta = 2 * np.arcsin(lengths / 2)
        h = theta.sum() / 2
        if np.pi - h < 1e-12:
            raise AssertionError("a test point lies on a triangle")
        c = np.array(
            [
                2 * np.sin(h) * np.sin(h - theta[i]) / (np.sin(theta[(i + 1) % 3]) * np.sin(theta[(i + 2) % 3])) - 1
                for i in range(3)
            ]
        )
        sign = np.sign(np.linalg.det(ut))
        s = sign * np.sqrt(np.maximum(0.0, 1 - c * c))
        if np.any(np.abs(s) <= 1e-12):
            continue  # x in the triangle's plane, outside it: no contribution
        for i in range(3):
            j, k = (i + 1) % 3, (i + 2) % 3
            weights[triangle[i]] += (theta[i] - c[j] * theta[k] - c[k] * theta[j]) / (
                d[triangle[i]] * np.sin(theta[j]) * s[k]
            )
    return weights / weights.sum()


@pytest.fixture(scope="module")
def comb():
    cage = pmvc.Cage.load(ASSETS / "comb_cage.obj")
    points, _ = pmvc.load_mesh(ASSETS / "comb_mesh.obj")
    return cage, points


def inside_comb_points(cage, points, count=25):
    classes = pmvc.classify(points, cage)
    return points[classes == pmvc.INSIDE][:: max(1, (classes == pmvc.INSIDE).sum() // count)][:count]


def test_float64_mvc_matches_an_independent_numpy_mvc_to_1e_12(comb):
    cage, points = comb
    x = inside_comb_points(cage, points)
    f64 = pmvc.bind(x, cage, method="mvc", backend="cpu", dtype=np.float64)
    f32 = pmvc.bind(x, cage, method="mvc", backend="cpu")
    assert f64.matrix.dtype == np.float64 and f32.matrix.dtype == np.float32
    expected = np.array([mvc_numpy(p, cage.vertices, cage.triangles) for p in x])
    error64 = np.abs(f64.matrix - expected).max()
    error32 = np.abs(f32.matrix.astype(np.float64) - expected).max()
    assert error64 < 1e-12, error64
    assert error32 > 1e-9, "float32 is this test's control: it must miss 1e-12"
    # float32 weights are the float64 ones rounded: the same computation.
    assert f64.matrix.astype(np.float32).tobytes() == f32.matrix.tobytes()


@pytest.mark.parametrize("method", ["mvc", "pmvc", "green"])
def test_float64_rows_round_to_the_float32_rows(comb, method):
    cage, points = comb
    x = points[::31]
    f64 = pmvc.bind(x, cage, method=method, backend="cpu", resolution=8, dtype="float64")
    f32 = pmvc.bind(x, cage, method=method, backend="cpu", resolution=8)
    assert f64.matrix.astype(np.float32).tobytes() == f32.matrix.tobytes()
    assert f64.metadata["dtype"] == "float64" and f32.metadata["dtype"] == "float32"
    assert "float64" in repr(f64)
    vertices = len(cage.vertices)
    assert np.abs(f64.matrix[:, :vertices].sum(axis=1) - 1).max() < 1e-12


def test_qmvc_on_quads_binds_in_float64():
    vertices, faces = twisted_box()
    cage = pmvc.Cage(vertices, faces)
    x = inside_points(10)
    f64 = pmvc.bind(x, cage, method="mvc", backend="cpu", dtype=np.dtype("float64"))
    assert f64.metadata["method_name"] == "QMVC"
    np.testing.assert_allclose(f64.matrix @ vertices, x, rtol=0, atol=1e-12)


def test_a_far_point_keeps_its_row_sum_in_float64(comb):
    """A point 1e9 cage diagonals away: float32 rounds its large weights of
    opposite signs, float64 keeps their sum."""
    cage, _ = comb
    far = cage.vertices.mean(axis=0) + np.array([[1e9, 3e8, -2e8]]) * cage.diagonal
    f64 = pmvc.bind(far, cage, method="mvc", backend="cpu", dtype=np.float64)
    assert abs(f64.matrix.sum() - 1) < 1e-6
    moved = pmvc.deform(far, cage, cage.vertices + [1.0, 2.0, 3.0], weights=f64)
    np.testing.assert_allclose(moved - far, [[1.0, 2.0, 3.0]], rtol=0, atol=1e-3)


@pytest.mark.parametrize("method,extension", [("pmvc", "npy"), ("green", "npz")])
def test_float64_files_are_stored_as_such_and_read_back(comb, tmp_path, method, extension):
    cage, points = comb
    x = points[::19]
    weights = pmvc.bind(x, cage, method=method, backend="cpu", resolution=8, dtype=np.float64)
    path = tmp_path / f"W.{extension}"
    pmvc.save_weights(path, weights)
    assert json.loads((tmp_path / "W.json").read_text())["dtype"] == "float64"
    if extension == "npy":
        stored = np.load(path)
    else:
        with np.load(path) as arrays:
            assert arrays["phi"].dtype == np.float64 and arrays["psi"].dtype == np.float64
            stored = np.hstack([arrays["phi"], arrays["psi"]])
    assert stored.dtype == np.float64 and stored.tobytes() == weights.matrix.tobytes()
    loaded = pmvc.load_weights(path)
    assert loaded.matrix.dtype == np.float64 and loaded.matrix.tobytes() == weights.matrix.tobytes()
    pose = middle_finger_pose(cage)
    moved = pmvc.deform(x, cage, pose, weights=weights)
    assert pmvc.deform(x, cage, pose, weights=loaded).tobytes() == moved.tobytes()
    for copied in (pickle.loads(pickle.dumps(weights)), pickle.loads(pickle.dumps(loaded))):
        assert copied.matrix.dtype == np.float64 and copied.matrix.tobytes() == weights.matrix.tobytes()
    # A float32 file never reads as float64: the metadata decides, and the file must agree.
    meta = json.loads((tmp_path / "W.json").read_text())
    meta["dtype"] = "float32"
    (tmp_path / "W.json").write_text(json.dumps(meta))
    with pytest.raises(pmvc.WeightsError, match="found dtype '<f8'"):
        pmvc.load_weights(path)


@pytest.mark.parametrize("method,extension", [("mvc", "npy"), ("green", "npz")])
def test_pmvc_bind_dtype_f64_writes_what_python_binds(comb, tmp_path, pmvc_bin, method, extension):
    cage, points = comb
    x = points[::23]
    mesh = write_points_obj(tmp_path / "points.obj", x)
    out = tmp_path / f"W.{extension}"
    run_pmvc(
        pmvc_bin, "bind", "--mesh", str(mesh), "--cage", str(ASSETS / "comb_cage.obj"),
        "--method", method, "--backend", "cpu", "--dtype", "f64", "--out", str(out),
    )
    expected = pmvc.bind(x, cage, method=method, backend="cpu", dtype=np.float64)
    loaded = pmvc.load_weights(out)
    assert loaded.metadata["dtype"] == "float64"
    assert loaded.matrix.tobytes() == expected.matrix.tobytes()
    # pmvc deform --weights reads float64 files.
    pose_file = write_cage_obj(tmp_path / "pose.obj", middle_finger_pose(cage), cage.faces)
    moved_file = tmp_path / "moved.npy"
    run_pmvc(
        pmvc_bin, "deform", "--mesh", str(mesh), "--cage", str(ASSETS / "comb_cage.obj"),
        "--deformed-cage", str(pose_file), "--weights", str(out), "--out", str(moved_file),
    )
    moved = pmvc.deform(x, cage, middle_finger_pose(cage), weights=expected)
    assert np.load(moved_file).tobytes() == moved.tobytes()


def test_dtypes_that_cannot_be_used_are_refused(comb, tmp_path, pmvc_bin):
    cage, points = comb
    x = points[:5]
    with pytest.raises(pmvc.ParameterError, match="harmonic coordinates are solved in float32"):
        pmvc.bind(x, cage, method="harmonic", dtype=np.float64)
    for bad in (np.int16, "float16", 3):
        with pytest.raises(pmvc.ParameterError, match="dtype must be numpy.float32 or numpy.float64"):
            pmvc.bind(x, cage, method="mvc", dtype=bad)
    mesh = write_points_obj(tmp_path / "points.obj", x)
    for args, words in [
        (["--dtype", "f16"], 'dtype "f16" is not float32 or float64'),
        (["--dtype", "f64", "--method", "harmonic"], "harmonic coordinates are solved in float32"),
    ]:
        result = subprocess.run(
            [str(pmvc_bin), "bind", "--mesh", str(mesh), "--cage", str(ASSETS / "comb_cage.obj"),
             "--out", str(tmp_path / "W.npy"), *args],
            capture_output=True, text=True,
        )
        assert result.returncode != 0 and words in result.stderr, result.stderr


def test_float64_on_the_gpu_warns_and_binds_on_the_cpu(comb):
    cage, points = comb
    with pytest.warns(pmvc.BackendWarning, match="computed on the CPU"):
        weights = pmvc.bind(points[:20], cage, method="pmvc", resolution=8, backend="gpu", dtype=np.float64)
    assert weights.backend == "cpu" and weights.matrix.dtype == np.float64
