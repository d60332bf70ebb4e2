"""Classes against an independent inside test, and Green coordinates' columns."""

from __future__ import annotations

import numpy as np
import pytest

import pmvc
from conftest import middle_finger_pose


def winding_numbers(vertices: np.ndarray, triangles: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Generalised winding number (Van Oosterom and Strackee's solid angle of
    each triangle, summed over 4π); written here, sharing nothing with pmvc."""
    total = np.zeros(len(points))
    for a, b, c in vertices[triangles]:
        ra, rb, rc = a - points, b - points, c - points
        la, lb, lc = (np.linalg.norm(r, axis=1) for r in (ra, rb, rc))
        numerator = np.einsum("ij,ij->i", ra, np.cross(rb, rc))
        denominator = (
            la * lb * lc
            + np.einsum("ij,ij->i", ra, rb) * lc
            + np.einsum("ij,ij->i", rb, rc) * la
            + np.einsum("ij,ij->i", rc, ra) * lb
        )
        total += 2 * np.arctan2(numerator, denominator)
    return total / (4 * np.pi)


def test_classes_agree_with_an_independent_winding_number(test_points, comb_cage):
    classes = pmvc.classify(test_points, comb_cage)
    assert classes.dtype == np.int8
    vertices, triangles = comb_cage.vertices, comb_cage.triangles
    on_cage_points = len(vertices) + len(triangles[::3])
    on_cage = np.zeros(len(test_points), dtype=bool)
    first = len(test_points) - 4 - on_cage_points
    on_cage[first : first + on_cage_points] = True
    assert (classes[on_cage] == pmvc.ON_CAGE).all()
    winding = winding_numbers(vertices, triangles, test_points[~on_cage])
    expected = np.where(winding > 0.5, pmvc.INSIDE, pmvc.OUTSIDE)
    np.testing.assert_array_equal(classes[~on_cage], expected)
    assert (expected == pmvc.INSIDE).sum() > 100 and (expected == pmvc.OUTSIDE).sum() == 4
    # bind classes its rows the same way.
    weights = pmvc.bind(test_points, comb_cage, method="mvc", backend="cpu")
    np.testing.assert_array_equal(weights.classes, classes)


def test_green_columns_are_phi_per_vertex_then_psi_per_listed_triangle(test_points, comb_cage):
    weights = pmvc.bind(test_points, comb_cage, method="green", backend="cpu")
    m, t = len(comb_cage.vertices), len(comb_cage.triangles)
    assert weights.matrix.shape == (len(test_points), m + t)
    assert weights.columns == [("vertex", j) for j in range(m)] + [("triangle", k) for k in range(t)]
    assert weights.columns_layout == "cage_vertices_then_triangles"
    np.testing.assert_array_equal(weights.triangles, comb_cage.triangles)
    # The deformation from the documented layout, in numpy: each point moves by
    # Σ φ_j (v'_j − v_j) + Σ ψ_k (s_k n'_k − n_k), with n the unit normal of
    # triangles[k] by the right-hand rule and s_k Green's stretch factor.
    pose = middle_finger_pose(comb_cage)
    rest = comb_cage.vertices
    corners = weights.triangles
    u, v = rest[corners[:, 1]] - rest[corners[:, 0]], rest[corners[:, 2]] - rest[corners[:, 0]]
    u1, v1 = pose[corners[:, 1]] - pose[corners[:, 0]], pose[corners[:, 2]] - pose[corners[:, 0]]
    normal = np.cross(u, v)
    area = 0.5 * np.linalg.norm(normal, axis=1)
    dot = lambda x, y: np.einsum("ij,ij->i", x, y)  # noqa: E731
    stretch = np.sqrt(
        dot(u1, u1) * dot(v, v) - 2 * dot(u1, v1) * dot(u, v) + dot(v1, v1) * dot(u, u)
    ) / (np.sqrt(8) * area)
    posed_normal = np.cross(u1, v1)
    moves = np.vstack(
        [
            pose - rest,
            stretch[:, None] * posed_normal / np.linalg.norm(posed_normal, axis=1)[:, None]
            - normal / np.linalg.norm(normal, axis=1)[:, None],
        ]
    )
    by_numpy = test_points + weights.matrix.astype(np.float64) @ moves
    by_pmvc = pmvc.deform(test_points, comb_cage, pose, weights=weights)
    np.testing.assert_allclose(by_pmvc, by_numpy, rtol=0, atol=1e-12 * comb_cage.diagonal)
    # The pose moves the points by much more than the tolerance.
    assert np.abs(by_pmvc - test_points).max() > 0.1


def test_other_families_list_cage_vertices_only(test_points, comb_cage):
    weights = pmvc.bind(test_points[:50], comb_cage, method="mvc", backend="cpu")
    assert weights.columns == [("vertex", j) for j in range(len(comb_cage.vertices))]
    assert weights.triangles is None
    assert weights.columns_layout == "cage_vertices"


def test_quads_stay_quads_and_are_cut_along_their_shorter_diagonal(tmp_path):
    # A box stretched along x: each side quad has one diagonal shorter than the other.
    box = np.array(
        [[0, 0, 0], [4, 0, 0], [4, 1, 0], [0, 1, 0], [0, 0, 1], [4, 0, 1], [4, 1, 1], [0, 1, 1]],
        dtype=float,
    )
    faces = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    cage = pmvc.Cage(box, faces)
    assert cage.faces == faces and not cage.flipped
    assert len(cage.triangles) == 12
    np.testing.assert_array_equal(cage.triangle_faces, np.repeat(np.arange(6), 2))
    with open(tmp_path / "box.obj", "w") as out:
        out.writelines(f"v {x} {y} {z}\n" for x, y, z in box)
        out.writelines("f " + " ".join(str(i + 1) for i in f) + "\n" for f in faces)
    loaded = pmvc.Cage.load(tmp_path / "box.obj")
    assert loaded.faces == faces
    np.testing.assert_array_equal(loaded.triangles, cage.triangles)
    vertices, mesh_faces = pmvc.load_mesh(tmp_path / "box.obj")
    assert mesh_faces == faces
    np.testing.assert_array_equal(vertices, box)
    # Inward faces are flipped, and the faces reported reversed with them.
    inward = pmvc.Cage(box, [f[::-1] for f in faces])
    assert inward.flipped and inward.faces == faces
    assert any("flipped" in notice for notice in inward.notices)


def test_a_npy_point_set_loads_as_points_without_faces(tmp_path, test_points):
    np.save(tmp_path / "points.npy", test_points)
    points, faces = pmvc.load_mesh(tmp_path / "points.npy")
    # No faces: an empty triangle array, as libigl gives a point cloud.
    assert faces.shape == (0, 3) and faces.dtype == np.int64
    assert points.tobytes() == test_points.tobytes()
    np.save(tmp_path / "flat.npy", test_points[:, :2])
    with pytest.raises(pmvc.FileError, match="flat.npy"):
        pmvc.load_mesh(tmp_path / "flat.npy")


def test_families_lists_every_family_with_its_parameters_and_promise():
    families = {family["id"]: family for family in pmvc.families()}
    assert list(families) == [
        "mvc", "pmvc", "harmonic", "green", "mec", "mlc", "bbw", "lbc", "somigliana"
    ]
    assert families["pmvc"]["positive_inside"] and not families["mvc"]["positive_inside"]
    for positive_on_the_cpu in ("mec", "mlc"):
        family = families[positive_on_the_cpu]
        assert family["positive_inside"] and not family["gpu_kernel"]
    assert [p["id"] for p in families["pmvc"]["parameters"]] == ["resolution"]
    assert families["harmonic"]["parameters"][0]["default"] == 64
    assert families["bbw"]["parameters"][0]["default"] == 32
    assert families["bbw"]["parameters"][0]["id"] == "grid"
    assert families["green"]["columns_layout"] == "cage_vertices_then_triangles"
    assert "Green's exterior extension" in families["green"]["outside_policy"]


def test_generate_cage_encloses_the_mesh_and_reports_what_pmvc_cage_prints(comb_points):
    _, faces = pmvc.load_mesh(pmvc_assets() / "comb_mesh.obj")
    calls = []
    cage, report = pmvc.generate_cage(
        comb_points, faces, target=80, progress=lambda done, total: calls.append(done)
    )
    assert isinstance(cage, pmvc.Cage)
    assert report["vertices"] == len(cage.vertices) and report["outside_vertices"] == 0
    assert report["target_vertices"] == 80
    # Second starts (a box, prisms) run up to 64 vertices, and above only where
    # the cage from the voxels bridges gaps; at 80 it keeps the comb's open.
    assert report["start"] == "voxels" and report["start_reason"] is None
    # From the voxels, a distance below which parts may merge (infinite only
    # for a box or prism, which begins around every part).
    assert 0 < report["merge_distance"] < float("inf")
    # The gap report's keys, as pmvc cage's "gaps between parts" line has them
    # (their meaning is tested in tests/cagegen/autocage_shapes.rs).
    assert isinstance(report["gap_points"], int) and isinstance(report["gap_points_open"], int)
    for key in ("narrowest_open_gap", "widest_closed_gap"):
        assert report[key] is None or report[key] > 0
    assert (pmvc.classify(comb_points, cage) == pmvc.INSIDE).all()
    assert calls[0] == 0 and calls[-1] == 1000 and calls == sorted(calls)


def test_generate_cage_says_why_a_prism_replaced_the_voxels_cage(comb_points):
    _, faces = pmvc.load_mesh(pmvc_assets() / "comb_mesh.obj")
    # At the hand-made cage's 40 vertices, a prism over the comb's outline
    # keeps the slots between its fingers.
    cage, report = pmvc.generate_cage(comb_points, faces, target=40)
    assert report["start"] == "prism along z"
    assert report["start_reason"] in ("smaller", "more gaps open", "smaller and more gaps open")
    assert report["gap_points_open"] == report["gap_points"] > 0
    assert report["merge_distance"] == float("inf")
    assert len(cage.vertices) == 40


def test_generate_cage_reports_where_it_bridges_gaps(comb_points):
    _, faces = pmvc.load_mesh(pmvc_assets() / "comb_mesh.obj")
    # Few vertices: the comb's prongs share one part of the cage.
    cage, report = pmvc.generate_cage(comb_points, faces, target=16)
    bridged = report["bridged_gap_points"]
    closed = report["gap_points"] - report["gap_points_open"]
    assert closed > 0
    # The summary never claims to keep apart what the cage joined.
    assert report["merge_distance"] >= report["widest_closed_gap"]
    assert bridged.dtype == np.float64 and bridged.shape == (closed, 3)
    assert (pmvc.classify(bridged, cage) != pmvc.OUTSIDE).all()


def test_generate_cage_with_quads_keeps_them_in_the_cage(comb_points):
    _, faces = pmvc.load_mesh(pmvc_assets() / "comb_mesh.obj")
    cage, report = pmvc.generate_cage(comb_points, faces, target=60, quads=True)
    assert report["quads"] > 0 and report["quads"] == len(cage.quads)
    assert report["outside_vertices"] == 0
    assert (pmvc.classify(comb_points, cage) == pmvc.INSIDE).all()
    _, triangles = pmvc.generate_cage(comb_points, faces, target=60)
    assert triangles["quads"] == 0


def pmvc_assets():
    from conftest import ASSETS

    return ASSETS
