"""Shared fixtures: the bundled comb, the `pmvc` command, and files for it."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import pmvc
from study import middle_finger_pose  # noqa: F401 (a fixture helper for the tests)

ROOT = Path(__file__).resolve().parents[2]
ASSETS = ROOT / "assets"


@pytest.fixture(scope="session")
def pmvc_bin() -> Path:
    """The `pmvc` binary: $PMVC_BIN, or target/release/pmvc (built if missing)."""
    given = os.environ.get("PMVC_BIN")
    if given:
        return Path(given)
    binary = ROOT / "target" / "release" / "pmvc"
    if not binary.exists():
        subprocess.run(["cargo", "build", "--release", "--bin", "pmvc"], cwd=ROOT, check=True)
    return binary


def run_pmvc(binary: Path, *args: str) -> subprocess.CompletedProcess:
    result = subprocess.run([str(binary), *args], capture_output=True, text=True)
    assert result.returncode == 0, f"pmvc {' '.join(args)} failed:\n{result.stderr}"
    return result


@pytest.fixture(scope="session")
def comb_cage() -> pmvc.Cage:
    return pmvc.Cage.load(ASSETS / "comb_cage.obj")


@pytest.fixture(scope="session")
def comb_points() -> np.ndarray:
    points, _ = pmvc.load_mesh(ASSETS / "comb_mesh.obj")
    return points


@pytest.fixture(scope="session")
def test_points(comb_points: np.ndarray, comb_cage: pmvc.Cage) -> np.ndarray:
    """Every 9th comb vertex, the cage's own vertices and face centres (on the
    cage), and points around the cage (outside, some beyond 4 diagonals)."""
    vertices = comb_cage.vertices
    centres = vertices[comb_cage.triangles].mean(axis=1)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    middle, size = (lo + hi) / 2, hi - lo
    around = middle + size * np.array(
        [[0.7, 0.0, 0.0], [0.0, -0.8, 0.1], [0.2, 0.3, 0.9], [9.0, 3.0, -2.0]]
    )
    return np.vstack([comb_points[::9], vertices, centres[::3], around])


def write_points_obj(path: Path, points: np.ndarray) -> Path:
    """Points as OBJ `v` lines with round-trip precision (repr of a float64)."""
    with open(path, "w") as out:
        for x, y, z in points.tolist():
            out.write(f"v {x!r} {y!r} {z!r}\n")
    return path


def write_cage_obj(path: Path, vertices: np.ndarray, faces) -> Path:
    with open(path, "w") as out:
        for x, y, z in np.asarray(vertices, dtype=np.float64).tolist():
            out.write(f"v {x!r} {y!r} {z!r}\n")
        for face in faces:
            out.write("f " + " ".join(str(i + 1) for i in face) + "\n")
    return path


def read_obj_vertices(path: Path) -> np.ndarray:
    rows = [line.split()[1:4] for line in open(path) if line.startswith("v ")]
    return np.array(rows, dtype=np.float64)
