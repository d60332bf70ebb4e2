"""Somigliana coordinates from Python: the block layout, the Poisson ratio as a
signed decimal, and the deformation written out in numpy from the documented
formula (an Umeyama fit of our own) against pmvc.deform."""

from __future__ import annotations

import numpy as np
import pytest

import pmvc
from study import middle_finger_pose


def umeyama(rest: np.ndarray, posed: np.ndarray):
    """Scale s, rotation R and centroids of the least-squares similarity
    posed ≈ s R rest + t, every vertex weighted equally."""
    rest_centre, posed_centre = rest.mean(axis=0), posed.mean(axis=0)
    a, b = rest - rest_centre, posed - posed_centre
    u, sigma, vt = np.linalg.svd(b.T @ a)
    flip = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))])
    rotation = u @ flip @ vt
    scale = np.trace(np.diag(sigma) @ flip) / (a * a).sum()
    return scale, rotation, posed_centre


def deform_by_blocks(weights: pmvc.Weights, cage: pmvc.Cage, pose: np.ndarray) -> np.ndarray:
    """x' = c' + R (Σ Bᵥ Rᵀ (vᵥ' − c') + s Σ F_f n_f), the blocks read from the
    matrix as docs/coordinates.md lays them out (row-major, vertices first)."""
    vertex_count, triangles = len(cage.vertices), weights.triangles
    blocks = weights.matrix.astype(np.float64).reshape(len(weights.matrix), -1, 3, 3)
    vertex_blocks, face_blocks = blocks[:, :vertex_count], blocks[:, vertex_count:]
    scale, rotation, centre = umeyama(cage.vertices, pose)
    rest = cage.vertices[triangles]
    normals = np.cross(rest[:, 1] - rest[:, 0], rest[:, 2] - rest[:, 0])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    unrotated = (pose - centre) @ rotation  # each row Rᵀ (v' − c')
    inner = np.einsum("pvab,vb->pa", vertex_blocks, unrotated)
    inner += scale * np.einsum("pfab,fb->pa", face_blocks, normals)
    return centre + inner @ rotation.T


def test_blocks_are_nine_columns_per_vertex_and_triangle(test_points, comb_cage):
    points = test_points[::4]
    weights = pmvc.bind(points, comb_cage, method="somigliana", poisson_ratio=0.3, dtype=np.float64)
    vertex_count, triangle_count = len(comb_cage.vertices), len(comb_cage.triangles)
    assert weights.matrix.shape == (len(points), 9 * (vertex_count + triangle_count))
    assert weights.columns_layout == "blocks_per_vertex_then_triangle"
    np.testing.assert_array_equal(weights.triangles, comb_cage.triangles)
    assert weights.columns[:10] == [("vertex_block", k) for k in range(10)]
    assert weights.columns[9 * vertex_count] == ("triangle_block", 0)
    assert len(weights.columns) == weights.matrix.shape[1]
    assert weights.parameters == {"poisson_ratio": 0.3}
    # Inside, the vertex blocks sum to the identity.
    inside = weights.classes == pmvc.INSIDE
    blocks = weights.matrix.reshape(len(points), -1, 3, 3)[:, :vertex_count]
    sums = blocks[inside].sum(axis=1)
    assert inside.sum() > 100
    np.testing.assert_allclose(sums, np.broadcast_to(np.eye(3), sums.shape), atol=1e-9)


@pytest.mark.parametrize("poisson_ratio", [0.0, 0.45, -0.5])
def test_numpy_from_the_documented_formula_deforms_as_pmvc(test_points, comb_cage, poisson_ratio):
    points = test_points[::3]
    weights = pmvc.bind(
        points, comb_cage, method="somigliana", poisson_ratio=poisson_ratio, dtype=np.float64
    )
    # The pulled finger, turned and scaled: the fit's rotation and scale matter.
    angle = 0.4
    turn = np.array(
        [[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0], [0, 0, 1]]
    )
    pose = 1.3 * middle_finger_pose(comb_cage) @ turn.T + np.array([5.0, -2.0, 1.0])
    by_numpy = deform_by_blocks(weights, comb_cage, pose)
    by_pmvc = pmvc.deform(points, comb_cage, pose, weights=weights)
    np.testing.assert_allclose(by_pmvc, by_numpy, rtol=0, atol=1e-9 * comb_cage.diagonal)
    # At rest every inside point is reproduced.
    at_rest = pmvc.deform(points, comb_cage, comb_cage.vertices, weights=weights)
    inside = weights.classes == pmvc.INSIDE
    np.testing.assert_allclose(at_rest[inside], points[inside], atol=1e-8 * comb_cage.diagonal)


def test_the_poisson_ratio_changes_the_weights_and_is_checked(test_points, comb_cage):
    points = test_points[:40]
    soft = pmvc.bind(points, comb_cage, method="somigliana", poisson_ratio=-0.5)
    hard = pmvc.bind(points, comb_cage, method="somigliana", poisson_ratio=0.45)
    assert soft.parameters == {"poisson_ratio": -0.5}
    assert np.abs(soft.matrix - hard.matrix).max() > 1e-3
    family = {f["id"]: f for f in pmvc.families()}["somigliana"]
    (parameter,) = family["parameters"]
    assert (parameter["id"], parameter["default"]) == ("poisson_ratio", 0.0)
    assert (parameter["min"], parameter["max"]) == (-0.999, 0.499)
    assert not family["positive_inside"]
    for refused in (0.5, -1.0, 0.7):
        with pytest.raises(pmvc.ParameterError, match=r"must be -0\.999 to 0\.499"):
            pmvc.bind(points, comb_cage, method="somigliana", poisson_ratio=refused)
