"""Somigliana coordinates from Python: the block layout, the Poisson ratio as a
signed decimal, and the deformation written out in numpy from the documented
formulas (an Umeyama fit of our own, bulging, the local/global blend) against
pmvc.deform."""

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
    settings = [
        (setting["id"], setting["default"], setting["min"], setting["max"])
        for setting in family["deform_parameters"]
    ]
    assert settings == [("bulging", 0.0, 0.0, 10.0), ("local_blend", 0.0, 0.0, 1.0)]
    weights = pmvc.bind(points, comb_cage, method="somigliana")
    for refused in (-0.5, 10.5, "much"):
        with pytest.raises(pmvc.ParameterError):
            pmvc.deform(points, comb_cage, comb_cage.vertices, weights=weights, bulging=refused)
    for refused in (-0.1, 1.01, "half"):
        with pytest.raises(pmvc.ParameterError):
            pmvc.deform(
                points, comb_cage, comb_cage.vertices, weights=weights, local_blend=refused
            )
    # Other families read none.
    assert all(f["deform_parameters"] == [] for f in pmvc.families() if f["id"] != "somigliana")


def rotation_log(rotation: np.ndarray) -> np.ndarray:
    """Axis times angle of a rotation by the trace and the skew part (angles
    well below a half turn here)."""
    angle = np.arccos(np.clip((np.trace(rotation) - 1.0) / 2.0, -1.0, 1.0))
    skew = np.array(
        [rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0], rotation[1, 0] - rotation[0, 1]]
    )
    if angle < 1e-12:
        return skew / 2.0
    return skew * angle / (2.0 * np.sin(angle))


def rotation_exp(vector: np.ndarray) -> np.ndarray:
    """Rodrigues' formula."""
    angle = np.linalg.norm(vector)
    k = np.array([[0.0, -vector[2], vector[1]], [vector[2], 0.0, -vector[0]], [-vector[1], vector[0], 0.0]])
    if angle < 1e-12:
        return np.eye(3) + k
    k /= angle
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * k @ k


def frames(corners: np.ndarray) -> np.ndarray:
    """Per triangle: first edge, normal × edge, normal, as columns."""
    edge = corners[:, 1] - corners[:, 0]
    edge /= np.linalg.norm(edge, axis=1)[:, None]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    return np.stack([edge, np.cross(normal, edge), normal], axis=2)


def blended_by_numpy(weights, cage, pose, poisson_ratio, gamma, blend):
    """The local/global blend as docs/coordinates.md defines it: each
    triangle's rotation R exp(b log(Rᵀ r_f)), each vertex's R exp of the
    area-weighted mean of its triangles' log(Rᵀ R_f), stretches b σ̄_f + (1 − b)
    s, tractions along R_f n_f projected onto zero net force, and each point
    x' = c' + A⁻¹ (Σ Rᵥ Bᵥ Rᵥᵀ (vᵥ' − c') + Σ t_f R_f F_f n_f), A = Σ Rᵥ Bᵥ Rᵥᵀ."""
    triangles = weights.triangles
    scale, rotation, centre = umeyama(cage.vertices, pose)
    fitted = scale * (cage.vertices - cage.vertices.mean(axis=0)) @ rotation.T + centre
    rest, posed = cage.vertices[triangles], pose[triangles]
    rest_frames, posed_frames = frames(rest), frames(posed)
    area_normals = 0.5 * np.cross(rest[:, 1] - rest[:, 0], rest[:, 2] - rest[:, 0])
    areas = np.linalg.norm(area_normals, axis=1)
    normals = area_normals / areas[:, None]
    posed_areas = 0.5 * np.linalg.norm(np.cross(posed[:, 1] - posed[:, 0], posed[:, 2] - posed[:, 0]), axis=1)
    volume = abs(np.einsum("fi,fi->", area_normals, rest.mean(axis=1)) / 3.0)
    face_rotations, tractions = [], []
    for f in range(len(triangles)):
        own = posed_frames[f] @ rest_frames[f].T
        turned = rotation @ rotation_exp(blend * rotation_log(rotation.T @ own))
        tangent = rest_frames[f][:, :2]
        before = tangent.T @ np.stack([rest[f, 1] - rest[f, 0], rest[f, 2] - rest[f, 0]], axis=1)
        after = tangent.T @ turned.T @ np.stack([posed[f, 1] - posed[f, 0], posed[f, 2] - posed[f, 0]], axis=1)
        stretch_map = after @ np.linalg.inv(before)
        mean_singular = 0.5 * np.sqrt(np.sum(stretch_map**2) + 2.0 * posed_areas[f] / areas[f])
        stretch = blend * mean_singular + (1.0 - blend) * scale
        h = stretch * np.exp(gamma**2 * prism_volume(posed[f], fitted[triangles[f]]) / volume)
        tractions.append((h * (1 - poisson_ratio) + 2 * poisson_ratio * stretch) / (1 + poisson_ratio))
        face_rotations.append(turned)
    face_rotations, tractions = np.array(face_rotations), np.array(tractions)
    directions = np.einsum("fij,fj->fi", face_rotations, normals)
    system = np.einsum("f,fi,fj->ij", areas, directions, directions)
    z = np.linalg.solve(system, (areas * tractions) @ directions)
    tractions = tractions - directions @ z
    vertex_count = len(cage.vertices)
    logs, totals = np.zeros((vertex_count, 3)), np.zeros(vertex_count)
    for f, corners in enumerate(triangles):
        for v in corners:
            logs[v] += areas[f] * rotation_log(rotation.T @ face_rotations[f])
            totals[v] += areas[f]
    vertex_rotations = np.array([rotation @ rotation_exp(logs[v] / totals[v]) for v in range(vertex_count)])
    blocks = weights.matrix.astype(np.float64).reshape(len(weights.matrix), -1, 3, 3)
    vertex_blocks, face_blocks = blocks[:, :vertex_count], blocks[:, vertex_count:]
    turned_blocks = np.einsum("vij,pvjk,vlk->pvil", vertex_rotations, vertex_blocks, vertex_rotations)
    matrix = turned_blocks.sum(axis=1)
    vector = np.einsum("pvij,vj->pi", turned_blocks, pose - centre)
    vector += np.einsum("fij,pfjk,fk->pi", face_rotations, face_blocks, tractions[:, None] * normals)
    return centre + np.linalg.solve(matrix, vector[:, :, None])[:, :, 0]


@pytest.mark.parametrize("poisson_ratio, gamma, blend", [(0.0, 0.0, 1.0), (0.3, 2.0, 0.5)])
def test_the_local_blend_in_numpy_deforms_as_pmvc(test_points, comb_cage, poisson_ratio, gamma, blend):
    points = test_points[::5]
    weights = pmvc.bind(
        points, comb_cage, method="somigliana", poisson_ratio=poisson_ratio, dtype=np.float64
    )
    angle = 0.5
    turn = np.array(
        [[np.cos(angle), 0.0, np.sin(angle)], [0.0, 1.0, 0.0], [-np.sin(angle), 0.0, np.cos(angle)]]
    )
    pose = 1.2 * middle_finger_pose(comb_cage, lift=2.0) @ turn.T + np.array([1e3, -2.0, 4.0])
    by_numpy = blended_by_numpy(weights, comb_cage, pose, poisson_ratio, gamma, blend)
    by_pmvc = pmvc.deform(
        points, comb_cage, pose, weights=weights, bulging=gamma, local_blend=blend
    )
    inside = weights.classes == pmvc.INSIDE
    np.testing.assert_allclose(
        by_pmvc[inside], by_numpy[inside], rtol=0, atol=1e-8 * comb_cage.diagonal
    )
    # It differs from the global variant, and at rest nothing moves.
    plain = pmvc.deform(points, comb_cage, pose, weights=weights, bulging=gamma)
    assert np.abs(by_pmvc - plain).max() > 1e-3 * comb_cage.diagonal
    at_rest = pmvc.deform(
        points, comb_cage, comb_cage.vertices, weights=weights, local_blend=blend
    )
    np.testing.assert_allclose(at_rest[inside], points[inside], atol=1e-8 * comb_cage.diagonal)
