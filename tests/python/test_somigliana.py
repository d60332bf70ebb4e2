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


def prism_volume(to: np.ndarray, start: np.ndarray) -> float:
    """The signed volume swept by the straight paths from triangle ``start`` to
    triangle ``to`` (corresponding corners), by integrating the Jacobian of
    x(u, v, t) = r(u, v) + t (p(u, v) − r(u, v)) over the triangle and t: a
    polynomial of degree 2, so a 2-point Gauss rule in t and the 3-point
    edge-midpoint rule on the triangle are exact."""
    d = to - start
    gauss_t = [(0.5 - np.sqrt(3) / 6, 0.5), (0.5 + np.sqrt(3) / 6, 0.5)]
    midpoints = [(0.5, 0.5), (0.0, 0.5), (0.5, 0.0)]
    total = 0.0
    for u, v in midpoints:
        for t, wt in gauss_t:
            du = (start[1] - start[0]) + t * (d[1] - d[0])
            dv = (start[2] - start[0]) + t * (d[2] - d[0])
            dt = d[0] + u * (d[1] - d[0]) + v * (d[2] - d[0])
            total += wt * (1.0 / 3.0) * 0.5 * np.linalg.det(np.array([du, dv, dt]))
    return total


def bulged_tractions(cage: pmvc.Cage, triangles, pose, poisson_ratio, gamma):
    """Each triangle's traction factor with bulging γ, as docs/coordinates.md
    defines it: h = s exp(γ² V_f / V), t = (h (1 − ν) + 2 ν s) / (1 + ν), then
    the least-squares projection onto zero net force weighted by area."""
    scale, rotation, centre = umeyama(cage.vertices, pose)
    fitted = scale * (cage.vertices - cage.vertices.mean(axis=0)) @ rotation.T + centre
    rest = cage.vertices[triangles]
    area_normals = 0.5 * np.cross(rest[:, 1] - rest[:, 0], rest[:, 2] - rest[:, 0])
    volume = abs(np.einsum("fi,fi->", area_normals, rest.mean(axis=1)) / 3.0)
    swept = np.array([prism_volume(pose[t], fitted[t]) for t in triangles])
    h = scale * np.exp(gamma**2 * swept / volume)
    tractions = (h * (1 - poisson_ratio) + 2 * poisson_ratio * scale) / (1 + poisson_ratio)
    areas = np.linalg.norm(area_normals, axis=1)
    normals = area_normals / areas[:, None]
    system = np.einsum("f,fi,fj->ij", areas, normals, normals)
    z = np.linalg.solve(system, area_normals.T @ tractions)
    return tractions - normals @ z


@pytest.mark.parametrize("poisson_ratio, gamma", [(0.0, 2.0), (0.3, 4.5)])
def test_bulging_in_numpy_deforms_as_pmvc(test_points, comb_cage, poisson_ratio, gamma):
    points = test_points[::5]
    weights = pmvc.bind(
        points, comb_cage, method="somigliana", poisson_ratio=poisson_ratio, dtype=np.float64
    )
    pose = middle_finger_pose(comb_cage, lift=2.0)
    tractions = bulged_tractions(comb_cage, weights.triangles, pose, poisson_ratio, gamma)
    vertex_count = len(comb_cage.vertices)
    blocks = weights.matrix.reshape(len(points), -1, 3, 3)
    vertex_blocks, face_blocks = blocks[:, :vertex_count], blocks[:, vertex_count:]
    scale, rotation, centre = umeyama(comb_cage.vertices, pose)
    rest = comb_cage.vertices[weights.triangles]
    normals = np.cross(rest[:, 1] - rest[:, 0], rest[:, 2] - rest[:, 0])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    inner = np.einsum("pvab,vb->pa", vertex_blocks, (pose - centre) @ rotation)
    inner += np.einsum("pfab,fb->pa", face_blocks, tractions[:, None] * normals)
    by_numpy = centre + inner @ rotation.T
    by_pmvc = pmvc.deform(points, comb_cage, pose, weights=weights, bulging=gamma)
    inside = weights.classes == pmvc.INSIDE
    np.testing.assert_allclose(
        by_pmvc[inside], by_numpy[inside], rtol=0, atol=1e-9 * comb_cage.diagonal
    )
    # It does bulge: some inside point moves by more than 1e-3 of the diagonal.
    plain = pmvc.deform(points, comb_cage, pose, weights=weights)
    assert np.abs(by_pmvc - plain).max() > 1e-3 * comb_cage.diagonal
    # At rest, nothing moves whatever γ.
    at_rest = pmvc.deform(points, comb_cage, comb_cage.vertices, weights=weights, bulging=gamma)
    np.testing.assert_allclose(at_rest[inside], points[inside], atol=1e-8 * comb_cage.diagonal)


def test_bulging_is_a_deformation_setting_checked_by_its_spec(test_points, comb_cage):
    points = test_points[:20]
    family = {f["id"]: f for f in pmvc.families()}["somigliana"]
    (setting,) = family["deform_parameters"]
    assert (setting["id"], setting["default"], setting["min"], setting["max"]) == (
        "bulging",
        0.0,
        0.0,
        10.0,
    )
    weights = pmvc.bind(points, comb_cage, method="somigliana")
    for refused in (-0.5, 10.5, "much"):
        with pytest.raises(pmvc.ParameterError):
            pmvc.deform(points, comb_cage, comb_cage.vertices, weights=weights, bulging=refused)
    # Other families read none.
    assert all(f["deform_parameters"] == [] for f in pmvc.families() if f["id"] != "somigliana")
