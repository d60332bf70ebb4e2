"""resolution="exact": PMVC with no cube map from Python, as `pmvc bind
--resolution exact` gives them (bit for bit), labelled as such, never negative,
reproducing their points; numbers other than a resolution refused; asked for
on the GPU, they say they ran on the CPU."""

from __future__ import annotations

import numpy as np
import pytest

import pmvc
from conftest import run_pmvc, write_points_obj
from conftest import ASSETS
from test_cli_equality import gpu_or_skip


@pytest.fixture(scope="module")
def inside(comb_points):
    return comb_points[::15]


def test_exact_pmvc_equal_the_command_line_and_say_exact(tmp_path, pmvc_bin, comb_cage, inside):
    weights = pmvc.bind(inside, comb_cage, resolution="exact", backend="cpu")
    assert weights.parameters == {"resolution": "exact"}
    assert weights.metadata["parameters"] == {"resolution": "exact"}
    mesh = write_points_obj(tmp_path / "points.obj", inside)
    out = tmp_path / "W.npy"
    run_pmvc(
        pmvc_bin, "bind", "--mesh", str(mesh), "--cage", str(ASSETS / "comb_cage.obj"),
        "--resolution", "exact", "--backend", "cpu", "--out", str(out),
    )  # fmt: skip
    np.testing.assert_array_equal(weights.matrix, np.load(out))


def test_exact_pmvc_are_positive_and_reproduce_their_points(comb_cage, inside):
    weights = pmvc.bind(inside, comb_cage, resolution="exact", dtype=np.float64)
    matrix = weights.matrix
    assert matrix.dtype == np.float64
    assert (matrix >= 0).all()
    np.testing.assert_allclose(matrix.sum(axis=1), 1.0, atol=1e-12)
    size = np.ptp(comb_cage.vertices, axis=0).max()
    np.testing.assert_allclose(matrix @ comb_cage.vertices, inside, atol=1e-12 * size)


def test_the_cube_map_approaches_exact_as_its_resolution_grows(comb_cage, inside):
    exact = pmvc.bind(inside, comb_cage, resolution="exact", dtype=np.float64).matrix
    errors = [
        np.abs(pmvc.bind(inside, comb_cage, resolution=r, dtype=np.float64).matrix - exact).mean()
        for r in (8, 32)
    ]
    assert errors[1] < errors[0] / 2, errors


@pytest.mark.parametrize("value", [0, -1, "fine", 2.5])
def test_anything_but_a_resolution_or_exact_is_refused(comb_cage, inside, value):
    with pytest.raises(pmvc.PmvcError, match="exact"):
        pmvc.bind(inside, comb_cage, resolution=value)


def test_families_list_exact_among_pmvc_choices():
    (pmvc_family,) = [f for f in pmvc.families() if f["id"] == "pmvc"]
    (resolution,) = pmvc_family["parameters"]
    assert resolution["named"] == ["exact"]
    assert "exact" in resolution["choices"]


def test_exact_asked_for_on_the_gpu_runs_on_the_cpu_and_says_so(comb_cage, inside):
    gpu_or_skip()
    with pytest.warns(pmvc.BackendWarning, match="PMVC exact has no GPU kernel"):
        weights = pmvc.bind(inside, comb_cage, resolution="exact", backend="gpu")
    assert weights.backend == "cpu"
