"""save_weights and load_weights: the files `pmvc bind` writes beside weights."""

from __future__ import annotations

import json

import numpy as np
import pytest

import pmvc
from conftest import ASSETS, middle_finger_pose, run_pmvc, write_cage_obj, write_points_obj


@pytest.mark.parametrize("method,name", [("pmvc", "W.npy"), ("green", "W.npz")])
def test_saved_weights_come_back_with_their_classes_and_metadata(
    tmp_path, test_points, comb_cage, method, name
):
    weights = pmvc.bind(test_points, comb_cage, method=method, resolution=8, backend="cpu")
    path = tmp_path / name
    pmvc.save_weights(path, weights)
    metadata = json.loads((tmp_path / "W.json").read_text())
    assert metadata["method"] == method and metadata["rows"] == len(test_points)
    assert metadata["classes"]["file"] == "W.classes.npy"
    assert metadata["parameters"] == ({"resolution": 8} if method == "pmvc" else {})
    assert metadata["cage"]["file"] == str(ASSETS / "comb_cage.obj")
    assert metadata == {**weights.metadata, "classes": metadata["classes"]}
    np.testing.assert_array_equal(np.load(tmp_path / "W.classes.npy"), weights.classes)
    if method == "green":
        with np.load(path) as arrays:
            stored = np.hstack([arrays["phi"], arrays["psi"]])
        assert metadata["triangles"] == comb_cage.triangles.tolist()
    else:
        stored = np.load(path)
    assert stored.tobytes() == weights.matrix.tobytes()
    loaded = pmvc.load_weights(path)
    assert loaded.matrix.tobytes() == weights.matrix.tobytes()
    np.testing.assert_array_equal(loaded.classes, weights.classes)
    assert (loaded.method, loaded.parameters, loaded.backend) == (
        weights.method, weights.parameters, weights.backend,
    )  # fmt: skip
    assert loaded.columns == weights.columns and loaded.seconds == weights.seconds
    pose = middle_finger_pose(comb_cage)
    np.testing.assert_array_equal(
        pmvc.deform(test_points, comb_cage, pose, weights=loaded),
        pmvc.deform(test_points, comb_cage, pose, weights=weights),
    )


def test_pmvc_deform_reads_what_save_weights_writes(pmvc_bin, tmp_path, test_points, comb_cage):
    weights = pmvc.bind(test_points, comb_cage, method="harmonic", grid=16, backend="cpu")
    pmvc.save_weights(tmp_path / "W.npy", weights)
    pose = middle_finger_pose(comb_cage)
    run_pmvc(
        pmvc_bin, "deform", "--mesh", str(write_points_obj(tmp_path / "p.obj", test_points)),
        "--cage", str(ASSETS / "comb_cage.obj"),
        "--deformed-cage", str(write_cage_obj(tmp_path / "posed.obj", pose, comb_cage.faces)),
        "--weights", str(tmp_path / "W.npy"), "--out", str(tmp_path / "out.npy"),
    )  # fmt: skip
    np.testing.assert_array_equal(
        np.load(tmp_path / "out.npy"),
        pmvc.deform(test_points, comb_cage, pose, weights=weights),
    )


def test_load_weights_reads_what_pmvc_bind_writes(pmvc_bin, tmp_path, test_points, comb_cage):
    mesh = write_points_obj(tmp_path / "p.obj", test_points)
    run_pmvc(
        pmvc_bin, "bind", "--mesh", str(mesh), "--cage", str(ASSETS / "comb_cage.obj"),
        "--method", "pmvc", "--resolution", "8", "--backend", "cpu", "--out", str(tmp_path / "W.npy"),
    )  # fmt: skip
    if not (tmp_path / "W.json").exists():
        pytest.skip("not run: this pmvc bind writes no metadata beside its weights")
    loaded = pmvc.load_weights(tmp_path / "W.npy")
    bound = pmvc.bind(test_points, comb_cage, method="pmvc", resolution=8, backend="cpu")
    assert loaded.matrix.tobytes() == bound.matrix.tobytes()
    np.testing.assert_array_equal(loaded.classes, bound.classes)
    assert loaded.metadata["mesh"]["digest"] == bound.metadata["mesh"]["digest"]
    assert loaded.metadata["cage"]["digest"] == bound.metadata["cage"]["digest"]


def test_weights_files_that_do_not_fit_are_refused_by_name(tmp_path, test_points, comb_cage):
    weights = pmvc.bind(test_points[:20], comb_cage, method="mvc", backend="cpu")
    with pytest.raises(pmvc.FileError, match=r"W.npz: MVC weights are written as .npy; use .*W.npy"):
        pmvc.save_weights(tmp_path / "W.npz", weights)
    with pytest.raises(pmvc.FileError, match="no metadata beside"):
        pmvc.load_weights(tmp_path / "W.npy")
    pmvc.save_weights(tmp_path / "W.npy", weights)
    loaded = pmvc.load_weights(tmp_path / "W.npy")
    with pytest.raises(pmvc.WeightsError, match=r"W.npy: the weights were bound for other inputs: rows is 20 there, 21 here"):
        pmvc.deform(test_points[:21], comb_cage, comb_cage.vertices, weights=loaded)
    text = (tmp_path / "W.json").read_text()
    (tmp_path / "W.json").write_text(text.replace('"method": "mvc"', '"method": "nope"'))
    with pytest.raises(pmvc.WeightsError, match=r"W.json: field method: \"nope\" is not a family"):
        pmvc.load_weights(tmp_path / "W.npy")
    (tmp_path / "W.json").write_text(text[:40])
    with pytest.raises(pmvc.FileError) as raised:
        pmvc.load_weights(tmp_path / "W.npy")
    assert raised.value.line is not None and "not weights metadata" in str(raised.value)
