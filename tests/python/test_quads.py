"""Cages of quads from Python: PMVC on bilinear patches checked against an
independent numpy ray caster (its own ray-patch intersection, sharing no code
with the library), QMVC named as such, and ``triangulate`` splitting quads."""

from __future__ import annotations

import numpy as np
import pytest

import pmvc

RESOLUTION = 8


def twisted_box(angle: float = 0.6, height: float = 2.0, roof: bool = False):
    """A box [-1, 1]^2 x [0, height] whose top is turned by ``angle``; with
    ``roof`` its top is four triangles up to an apex instead of one quad."""
    square = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    turned = square @ np.array([[c, s], [-s, c]])
    vertices = np.vstack(
        [np.c_[square, np.zeros(4)], np.c_[turned, np.full(4, height)]]
    )
    faces = [[0, 3, 2, 1], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    if roof:
        vertices = np.vstack([vertices, [0.0, 0.0, height + 0.7]])
        faces += [[4, 5, 8], [5, 6, 8], [6, 7, 8], [7, 4, 8]]
    else:
        faces.append([4, 5, 6, 7])
    return vertices, faces


def inside_points(count: int, seed: int = 3) -> np.ndarray:
    """Points well inside both boxes (the turned top only narrows it near z = 2)."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-0.55, 0.55, size=(count, 2))
    z = rng.uniform(0.2, 1.7, size=(count, 1))
    return np.hstack([xy, z])


def cube_map(resolution: int):
    """Texel ray directions (not normalised) and exact solid angles."""
    centres = -1 + (2 * np.arange(resolution) + 1) / resolution
    edges = np.linspace(-1.0, 1.0, resolution + 1)

    def corner(u, v):
        return np.arctan2(u * v, np.sqrt(u * u + v * v + 1))

    u0, v0 = np.meshgrid(edges[:-1], edges[:-1], indexing="ij")
    u1, v1 = np.meshgrid(edges[1:], edges[1:], indexing="ij")
    omega = (corner(u1, v1) - corner(u0, v1) - corner(u1, v0) + corner(u0, v0)).ravel()
    uc, vc = np.meshgrid(centres, centres, indexing="ij")
    uc, vc = uc.ravel(), vc.ravel()
    directions, solid = [], []
    for axis in range(3):
        for sign in (1.0, -1.0):
            d = np.zeros((uc.size, 3))
            d[:, axis] = sign
            others = [k for k in range(3) if k != axis]
            d[:, others[0]] = uc
            d[:, others[1]] = vc
            directions.append(d)
            solid.append(omega)
    return np.vstack(directions), np.concatenate(solid)


def ray_patch(x, d, q):
    """Nearest hit t > 0 of rays x + t d with the bilinear patch q (4 x 3):
    returns t (inf where missed), u, v."""
    a, b, c, e = q[0], q[1] - q[0], q[3] - q[0], q[0] - q[1] + q[2] - q[3]
    # Two planes through each ray: n1, n2 orthogonal to d.
    helper = np.where(np.abs(d[:, [0]]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
    n1 = np.cross(d, helper)
    n2 = np.cross(d, n1)
    best_t = np.full(len(d), np.inf)
    best_u = np.zeros(len(d))
    best_v = np.zeros(len(d))
    ax = a - x
    k = [(n @ ax, n @ b, n @ c, n @ e) for n in (n1, n2)]
    (a1, b1, c1, e1), (a2, b2, c2, e2) = k
    qa = b2 * e1 - e2 * b1
    qb = a2 * e1 + b2 * c1 - c2 * b1 - e2 * a1
    qc = a2 * c1 - c2 * a1
    disc = qb * qb - 4 * qa * qc
    roots = []
    linear = np.abs(qa) < 1e-12 * (np.abs(qb) + np.abs(qc) + 1e-300)
    sq = np.sqrt(np.maximum(disc, 0))
    with np.errstate(divide="ignore", invalid="ignore"):
        r1 = np.where(linear, -qc / qb, (-qb - sq) / (2 * qa))
        r2 = np.where(linear, np.nan, (-qb + sq) / (2 * qa))
    for u in (r1, r2):
        with np.errstate(divide="ignore", invalid="ignore"):
            den1, den2 = c1 + u * e1, c2 + u * e2
            v = np.where(
                np.abs(den1) >= np.abs(den2), -(a1 + u * b1) / den1, -(a2 + u * b2) / den2
            )
        point = a + u[:, None] * b + v[:, None] * c + (u * v)[:, None] * e
        t = ((point - x) * d).sum(1) / (d * d).sum(1)
        ok = (disc >= 0) & (u >= 0) & (u <= 1) & (v >= 0) & (v <= 1) & (t > 0)
        nearer = ok & (t < best_t)
        best_t = np.where(nearer, t, best_t)
        best_u = np.where(nearer, u, best_u)
        best_v = np.where(nearer, v, best_v)
    return best_t, best_u, best_v


def ray_triangle(x, d, tri):
    """Nearest hit t > 0 of rays with a triangle, and its barycentrics."""
    p0, p1, p2 = tri
    e1, e2 = p1 - p0, p2 - p0
    h = np.cross(d, e2)
    det = h @ e1
    with np.errstate(divide="ignore", invalid="ignore"):
        s = x - p0
        u = (h @ s) / det
        qv = np.cross(s, e1)
        v = (d @ qv) / det
        t = (qv @ e2) / det
    ok = (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    return np.where(ok, t, np.inf), u, v


def reference_pmvc(x, vertices, faces, resolution):
    d, omega = cube_map(resolution)
    best = np.full(len(d), np.inf)
    spread = np.zeros((len(d), len(vertices)))
    for face in faces:
        corners = vertices[face]
        if len(face) == 4:
            t, u, v = ray_patch(x, d, corners)
            basis = np.stack([(1 - u) * (1 - v), u * (1 - v), u * v, (1 - u) * v], 1)
        else:
            t, u, v = ray_triangle(x, d, corners)
            basis = np.stack([1 - u - v, u, v], 1)
        nearer = t < best
        best = np.where(nearer, t, best)
        row = np.zeros((len(d), len(vertices)))
        row[:, face] = basis
        spread = np.where(nearer[:, None], row, spread)
    assert np.isfinite(best).all(), "a ray escaped from inside the cage"
    distance = best * np.linalg.norm(d, axis=1)
    weights = (omega / distance) @ spread
    return weights / weights.sum()


@pytest.mark.parametrize("roof", [False, True])
def test_quad_pmvc_matches_an_independent_numpy_ray_caster(roof):
    vertices, faces = twisted_box(roof=roof)
    cage = pmvc.Cage(vertices, faces)
    assert cage.quads.shape == (5 if roof else 6, 4)
    points = inside_points(12)
    bound = pmvc.bind(points, cage, method="pmvc", resolution=RESOLUTION, backend="cpu")
    for row, x in zip(bound.matrix, points):
        expected = reference_pmvc(x, vertices, faces, RESOLUTION)
        np.testing.assert_allclose(row, expected, atol=2e-6)
    assert bound.matrix.min() >= 0.0
    np.testing.assert_allclose(bound.matrix.sum(1), 1.0, atol=1e-5)
    np.testing.assert_allclose(bound.matrix @ vertices, points, atol=2e-5)


def test_splitting_the_quads_changes_the_weights_and_is_recorded():
    vertices, faces = twisted_box()
    cage = pmvc.Cage(vertices, faces)
    points = inside_points(40)
    patches = pmvc.bind(points, cage, method="pmvc", resolution=RESOLUTION, backend="cpu")
    shorter = pmvc.bind(
        points, cage, method="pmvc", resolution=RESOLUTION, backend="cpu", triangulate="shorter"
    )
    assert np.abs(patches.matrix - shorter.matrix).max() > 1e-3
    assert patches.metadata["quad_split"] == "none"
    assert patches.metadata["quads_bound_as"] == "bilinear quads"
    assert shorter.metadata["quad_split"] == "shorter"
    assert "shorter diagonal" in shorter.metadata["quads_bound_as"]
    with pytest.raises(pmvc.ParameterError, match="triangulate"):
        pmvc.bind(points, cage, method="pmvc", triangulate="diagonal")


def test_mvc_on_quads_is_qmvc_and_reproduces_points():
    vertices, faces = twisted_box()
    cage = pmvc.Cage(vertices, faces)
    points = inside_points(30)
    qmvc = pmvc.bind(points, cage, method="mvc", backend="cpu")
    assert qmvc.metadata["method_name"] == "QMVC"
    np.testing.assert_allclose(qmvc.matrix.sum(1), 1.0, atol=1e-5)
    np.testing.assert_allclose(qmvc.matrix @ vertices, points, atol=2e-5)
    split = pmvc.bind(points, cage, method="mvc", backend="cpu", triangulate="longer")
    assert split.metadata["method_name"] == "MVC (longer split)"
    assert np.abs(qmvc.matrix - split.matrix).max() > 1e-4


def test_families_say_which_bind_on_the_gpu_on_a_cage_with_quads():
    families = {family["id"]: family for family in pmvc.families()}
    # QMVC and QGC have no GPU kernel; PMVC has one for patches.
    assert families["mvc"]["gpu_kernel"] and not families["mvc"]["gpu_kernel_quads"]
    assert families["pmvc"]["gpu_kernel"] and families["pmvc"]["gpu_kernel_quads"]
    assert families["green"]["gpu_kernel"] and not families["green"]["gpu_kernel_quads"]
    assert not families["harmonic"]["gpu_kernel_quads"]
