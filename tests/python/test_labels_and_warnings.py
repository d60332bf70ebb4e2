"""Honest labels and quiet output: QMVC is called QMVC, work asked for on the
GPU that runs on the CPU says so as a pmvc.BackendWarning naming the family,
and the GPU probe prints nothing on stderr."""

from __future__ import annotations

import os
import subprocess
import sys
import warnings

import pytest

import pmvc
from conftest import ASSETS, ROOT
from test_cli_equality import gpu_or_skip
from test_quads import inside_points, twisted_box


@pytest.fixture(scope="module")
def quad_cage():
    vertices, faces = twisted_box()
    return pmvc.Cage(vertices, faces)


def test_mvc_on_quads_is_labelled_qmvc_everywhere(quad_cage):
    points = inside_points(8)
    qmvc = pmvc.bind(points, quad_cage, method="mvc", backend="cpu")
    assert qmvc.metadata["method_name"] == "QMVC"
    assert repr(qmvc).startswith("Weights(QMVC, 8 × 8 float32")
    split = pmvc.bind(points, quad_cage, method="mvc", backend="cpu", triangulate="shorter")
    assert repr(split).startswith("Weights(MVC (shorter split),")
    sys.path.insert(0, str(ROOT / "tests" / "python"))
    from study import family_label

    assert family_label(qmvc) == "QMVC"
    harmonic = pmvc.bind(points, quad_cage, method="harmonic", grid=16, backend="cpu")
    assert family_label(harmonic) == "HC grid 16"


def test_the_cpu_and_auto_backends_warn_of_nothing(quad_cage):
    points = inside_points(8)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for backend in ("cpu", "auto"):
            for method in ("mvc", "harmonic", "pmvc"):
                pmvc.bind(points, quad_cage, method=method, backend=backend, grid=16, resolution=8)


@pytest.mark.parametrize(
    "method,parameters,on_quads,label",
    [
        ("harmonic", {"grid": 16}, False, "HC grid 16"),
        ("mvc", {}, True, "QMVC"),
        ("harmonic", {"grid": 16}, True, "HC grid 16"),
    ],
)
def test_a_family_without_a_gpu_kernel_warns_when_the_gpu_was_asked_for(
    comb_cage, quad_cage, method, parameters, on_quads, label
):
    gpu_or_skip()
    cage = quad_cage if on_quads else comb_cage
    points = inside_points(8) if on_quads else comb_cage.vertices.mean(axis=0)[None, :]
    with pytest.warns(pmvc.BackendWarning, match=f"bind: {label} has no GPU kernel; it was bound on the CPU"):
        weights = pmvc.bind(points, cage, method=method, backend="gpu", **parameters)
    assert weights.backend == "cpu"
    # The same through deform, which binds first.
    with pytest.warns(pmvc.BackendWarning, match=label):
        pmvc.deform(points, cage, cage.vertices, method=method, backend="gpu", **parameters)


def test_a_family_bound_on_the_gpu_warns_of_nothing(comb_cage):
    gpu_or_skip()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        weights = pmvc.bind(comb_cage.vertices * 0.5 + 1, comb_cage, method="pmvc", backend="gpu", resolution=8)
    assert weights.backend == "gpu"


def test_the_gpu_probe_prints_nothing_on_stderr(tmp_path):
    """In a process without XDG_RUNTIME_DIR (libwayland complained there once
    per probe), a GPU bind leaves stderr empty and the process a private
    runtime directory."""
    gpu_or_skip()
    script = (
        "import os, pmvc\n"
        f"cage = pmvc.Cage.load({str(ASSETS / 'comb_cage.obj')!r})\n"
        "pmvc.bind(cage.vertices * 0.5 + 1, cage, method='pmvc', backend='gpu', resolution=8)\n"
        "pmvc.bind(cage.vertices * 0.5 + 1, cage, method='mvc', backend='auto')\n"
        "print(os.environ['XDG_RUNTIME_DIR'])\n"
    )
    environment = {key: value for key, value in os.environ.items() if key != "XDG_RUNTIME_DIR"}
    environment["TMPDIR"] = str(tmp_path)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=environment)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    runtime = result.stdout.strip()
    assert runtime == str(tmp_path / f"pmvc-runtime-{os.getuid()}")
    assert os.stat(runtime).st_mode & 0o777 == 0o700
    # A process that has the variable keeps it.
    environment["XDG_RUNTIME_DIR"] = str(tmp_path)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=environment)
    assert result.returncode == 0 and result.stdout.strip() == str(tmp_path)


def test_a_runtime_directory_that_is_not_private_is_not_used(tmp_path, monkeypatch):
    from pmvc import _environment

    shared = tmp_path / f"pmvc-runtime-{os.getuid()}"
    shared.mkdir(mode=0o755)
    shared.chmod(0o755)
    monkeypatch.delenv("XDG_RUNTIME_DIR", raising=False)
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.setattr("tempfile.tempdir", None)
    _environment.ensure_runtime_dir()
    assert "XDG_RUNTIME_DIR" not in os.environ
    shared.chmod(0o700)
    _environment.ensure_runtime_dir()
    assert os.environ["XDG_RUNTIME_DIR"] == str(shared)
