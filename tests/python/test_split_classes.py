"""A bind that splits a cage's quads (``triangulate=``) classes its rows against the triangles it binds
on, not against the bilinear patches it did not use: checked against a winding
number of the split triangles written in numpy, through Python and ``pmvc bind``.

The twisted box's side quads are bent, so points lie between each patch and its
two triangles: classed by the patches, some inside the split cage would be
called outside (and get MVC rows) and some outside it inside (and get PMVC rows
of a point the bound cage does not enclose, with negative weights)."""

from __future__ import annotations

import numpy as np
import pytest

import pmvc
from conftest import run_pmvc, write_cage_obj, write_points_obj
from test_classes_and_layout import winding_numbers
from test_quads import twisted_box

RESOLUTION = 8


def split_triangles(vertices: np.ndarray, faces, diagonal: str) -> np.ndarray:
    """Every face as triangles, quads cut along their shorter or longer
    diagonal (q0-q2 or q1-q3), in numpy."""
    triangles = []
    for face in faces:
        if len(face) == 3:
            triangles.append(face)
            continue
        q0, q1, q2, q3 = face
        first = np.linalg.norm(vertices[q0] - vertices[q2])
        second = np.linalg.norm(vertices[q1] - vertices[q3])
        along_first = first <= second if diagonal == "shorter" else first > second
        if along_first:
            triangles += [[q0, q1, q2], [q0, q2, q3]]
        else:
            triangles += [[q0, q1, q3], [q1, q2, q3]]
    return np.array(triangles)


def points_near_the_walls(count: int = 4000, seed: int = 5) -> np.ndarray:
    """Points in a shell around the box's bent sides, where a bent patch and
    its triangles disagree, away from the top and bottom."""
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * np.pi, count)
    radius = rng.uniform(0.7, 1.45, count)
    z = rng.uniform(0.3, 1.7, count)
    return np.c_[radius * np.cos(angle), radius * np.sin(angle), z]


def expected_classes(vertices, triangles, points) -> np.ndarray:
    winding = winding_numbers(vertices, triangles, points)
    assert np.abs(winding - 0.5).min() > 1e-3, "a test point is too close to the surface"
    return np.where(winding > 0.5, pmvc.INSIDE, pmvc.OUTSIDE).astype(np.int8)


@pytest.fixture(scope="module")
def scene():
    vertices, faces = twisted_box()
    return vertices, faces, pmvc.Cage(vertices, faces), points_near_the_walls()


@pytest.mark.parametrize("diagonal", ["shorter", "longer"])
def test_a_split_bind_classes_its_rows_against_the_split_cage(scene, diagonal):
    vertices, faces, cage, points = scene
    expected = expected_classes(vertices, split_triangles(vertices, faces, diagonal), points)
    # The scene tests something: the patches class hundreds of these points
    # otherwise than the split cage does (inside the shorter split's triangles
    # but outside the patches; outside the longer split's but inside the patches).
    patch_classes = pmvc.classify(points, cage)
    assert (patch_classes != expected).sum() >= 100
    for method, parameters in [("pmvc", {"resolution": RESOLUTION}), ("mvc", {})]:
        weights = pmvc.bind(points, cage, method=method, backend="cpu", triangulate=diagonal, **parameters)
        np.testing.assert_array_equal(weights.classes, expected)
        counts = weights.metadata["classes"]
        assert counts["outside"] == int((expected == pmvc.OUTSIDE).sum())
    # PMVC is never negative on the rows it calls inside.
    inside = weights.classes == pmvc.INSIDE
    pmvc_weights = pmvc.bind(
        points, cage, method="pmvc", resolution=RESOLUTION, backend="cpu", triangulate=diagonal
    )
    assert pmvc_weights.matrix[inside].min() >= 0.0
    # classify answers what a bind with the same split uses.
    np.testing.assert_array_equal(pmvc.classify(points, cage, triangulate=diagonal), expected)


def test_green_coordinates_class_their_rows_against_the_triangles_they_bind(scene):
    vertices, faces, cage, points = scene
    expected = expected_classes(vertices, split_triangles(vertices, faces, "shorter"), points)
    # On patches Green coordinates are QGC; split, they bind the triangles.
    weights = pmvc.bind(points, cage, method="green", backend="cpu", triangulate="shorter")
    np.testing.assert_array_equal(weights.classes, expected)
    np.testing.assert_array_equal(
        pmvc.classify(points, cage, method="green", triangulate="shorter"), expected
    )


def test_pmvc_bind_with_triangulate_writes_the_split_cages_classes(scene, pmvc_bin, tmp_path):
    vertices, faces, _, points = scene
    mesh = write_points_obj(tmp_path / "points.obj", points)
    cage_file = write_cage_obj(tmp_path / "cage.obj", vertices, faces)
    for diagonal in ["shorter", "longer"]:
        expected = expected_classes(vertices, split_triangles(vertices, faces, diagonal), points)
        out = tmp_path / f"W-{diagonal}.npy"
        run_pmvc(
            pmvc_bin, "bind", "--mesh", str(mesh), "--cage", str(cage_file), "--method", "pmvc",
            "--resolution", str(RESOLUTION), "--backend", "cpu", "--triangulate", diagonal,
            "--out", str(out),
        )
        classes = np.load(tmp_path / f"W-{diagonal}.classes.npy")
        np.testing.assert_array_equal(classes, expected)
        matrix = np.load(out)
        assert matrix[classes == pmvc.INSIDE].min() >= 0.0
