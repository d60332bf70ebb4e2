"""The package computes what the command line computes, bit for bit."""

from __future__ import annotations

import os

import numpy as np
import pytest

import pmvc
from conftest import ASSETS, read_obj_vertices, run_pmvc, write_cage_obj, write_points_obj

# Small parameters keep the suite quick; any value goes through the same code.
FAMILIES = [
    ("mvc", []),
    ("pmvc", ["--resolution", "16"]),
    ("harmonic", ["--grid", "24"]),
    ("green", []),
]
PYTHON_PARAMETERS = {"mvc": {}, "pmvc": {"resolution": 16}, "harmonic": {"grid": 24}, "green": {}}


def cli_weights(pmvc_bin, tmp_path, points, method, flags, backend):
    mesh = write_points_obj(tmp_path / "points.obj", points)
    out = tmp_path / ("W.npz" if method == "green" else "W.npy")
    run_pmvc(
        pmvc_bin,
        "bind", "--mesh", str(mesh), "--cage", str(ASSETS / "comb_cage.obj"),
        "--method", method, *flags, "--backend", backend, "--out", str(out),
    )  # fmt: skip
    if method == "green":
        with np.load(out) as arrays:
            return np.hstack([arrays["phi"], arrays["psi"]])
    return np.load(out)


def gpu_or_skip():
    try:
        pmvc.bind(np.zeros((0, 3)), pmvc.Cage.load(ASSETS / "comb_cage.obj"), backend="gpu")
    except pmvc.BackendError as error:
        if os.environ.get("PMVC_REQUIRE_GPU") == "1":
            raise
        pytest.skip(f"not run: {error}")


@pytest.mark.parametrize("method,flags", FAMILIES)
@pytest.mark.parametrize("backend", ["cpu", "gpu"])
@pytest.mark.filterwarnings("ignore::pmvc.BackendWarning")  # harmonic on "gpu" binds on the CPU
def test_every_family_is_bit_for_bit_the_command_lines(
    pmvc_bin, tmp_path, test_points, comb_cage, method, flags, backend
):
    if backend == "gpu":
        gpu_or_skip()
    expected = cli_weights(pmvc_bin, tmp_path, test_points, method, flags, backend)
    weights = pmvc.bind(
        test_points, comb_cage, method=method, backend=backend, **PYTHON_PARAMETERS[method]
    )
    assert weights.matrix.dtype == np.float32
    assert weights.matrix.shape == expected.shape
    assert weights.matrix.tobytes() == expected.astype(np.float32).tobytes()
    assert weights.method == method
    assert weights.parameters == PYTHON_PARAMETERS[method]


@pytest.mark.parametrize("kernel,name", [("tiles", "tile"), ("bands", "band")])
def test_each_pmvc_kernel_is_bit_for_bit_the_command_lines_and_named(
    pmvc_bin, tmp_path, test_points, comb_cage, kernel, name
):
    gpu_or_skip()
    flags = ["--resolution", "16", "--pmvc-kernel", kernel]
    expected = cli_weights(pmvc_bin, tmp_path, test_points, "pmvc", flags, "gpu")
    weights = pmvc.bind(test_points, comb_cage, resolution=16, backend="gpu", pmvc_kernel=kernel)
    assert weights.matrix.tobytes() == expected.astype(np.float32).tobytes()
    assert weights.device.endswith(f"PMVC {name} kernel"), weights.device


def test_deform_is_what_pmvc_deform_writes_with_stored_and_fresh_weights(
    pmvc_bin, tmp_path, test_points, comb_cage
):
    from conftest import middle_finger_pose

    pose = middle_finger_pose(comb_cage)
    mesh = write_points_obj(tmp_path / "points.obj", test_points)
    posed = write_cage_obj(tmp_path / "posed.obj", pose, comb_cage.faces)
    cage = str(ASSETS / "comb_cage.obj")
    # Fresh weights, both sides; the command line writes the points as float64
    # .npy, and as OBJ `v` lines (printed with round-trip precision).
    for out in ("fresh.npy", "fresh.obj"):
        run_pmvc(
            pmvc_bin, "deform", "--mesh", str(mesh), "--cage", cage, "--deformed-cage", str(posed),
            "--method", "pmvc", "--resolution", "16", "--backend", "cpu",
            "--out", str(tmp_path / out),
        )  # fmt: skip
    fresh = pmvc.deform(
        test_points, comb_cage, pose, method="pmvc", resolution=16, backend="cpu"
    )
    assert fresh.dtype == np.float64
    written = np.load(tmp_path / "fresh.npy")
    assert written.dtype == np.float64 and fresh.tobytes() == written.tobytes()
    np.testing.assert_array_equal(fresh, read_obj_vertices(tmp_path / "fresh.obj"))
    assert np.abs(fresh - test_points).max() > 0.1, "the pose moved nothing"
    # Stored weights (Green's two arrays), applied by both.
    run_pmvc(
        pmvc_bin, "bind", "--mesh", str(mesh), "--cage", cage, "--method", "green",
        "--backend", "cpu", "--out", str(tmp_path / "W.npz"),
    )  # fmt: skip
    run_pmvc(
        pmvc_bin, "deform", "--mesh", str(mesh), "--cage", cage, "--deformed-cage", str(posed),
        "--weights", str(tmp_path / "W.npz"), "--out", str(tmp_path / "green.npy"),
    )  # fmt: skip
    weights = pmvc.bind(test_points, comb_cage, method="green", backend="cpu")
    green = pmvc.deform(test_points, comb_cage, pose, weights=weights)
    assert green.tobytes() == np.load(tmp_path / "green.npy").tobytes()


def test_obj_vertices_print_float64_with_round_trip_precision(pmvc_bin, tmp_path):
    """The comparison above reads `v` lines back: they must hold every bit."""
    awkward = np.array([[0.1, 1 / 3, -2.5e-7], [1e17 / 3, 123456.789012345678, np.pi]])
    cage = pmvc.Cage.load(ASSETS / "comb_cage.obj")
    mesh = write_points_obj(tmp_path / "points.obj", awkward)
    write_cage_obj(tmp_path / "same.obj", cage.vertices, cage.faces)
    run_pmvc(
        pmvc_bin, "deform", "--mesh", str(mesh), "--cage", str(ASSETS / "comb_cage.obj"),
        "--deformed-cage", str(tmp_path / "same.obj"), "--method", "mvc",
        "--out", str(tmp_path / "out.obj"),
    )  # fmt: skip
    np.testing.assert_array_equal(read_obj_vertices(tmp_path / "out.obj"), awkward)
