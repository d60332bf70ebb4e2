"""Files of several objects: which one was read is said, and one is read by name."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import pmvc

# A scene as Blender exports it: a box cage of quads and a triangle inside.
SCENE = """o Cage
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
o Mesh
v 0.2 0.2 0.2
v 0.6 0.2 0.2
v 0.2 0.6 0.2
f -3 -2 -1
"""


@pytest.fixture()
def scene(tmp_path):
    path = tmp_path / "scene.obj"
    path.write_text(SCENE)
    return path


def test_an_object_is_read_by_name_its_vertices_reindexed(scene):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        vertices, faces = pmvc.load_mesh(scene, object="Mesh")
        cage = pmvc.Cage.load(scene, object="Cage")
    np.testing.assert_array_equal(vertices, [[0.2, 0.2, 0.2], [0.6, 0.2, 0.2], [0.2, 0.6, 0.2]])
    np.testing.assert_array_equal(faces, [[0, 1, 2]])
    assert cage.vertices.shape == (8, 3)
    assert cage.faces[0] == [0, 3, 2, 1]


def test_the_cage_object_is_kept_through_pickling_and_recorded_by_bind(scene, tmp_path):
    import pickle

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        vertices, _ = pmvc.load_mesh(scene, object="Mesh")
        cage = pmvc.Cage.load(scene, object="Cage")
    assert cage.object == "Cage"
    assert pickle.loads(pickle.dumps(cage)).object == "Cage"
    weights = pmvc.bind(vertices, cage, method="mvc")
    path = tmp_path / "W.npy"
    pmvc.save_weights(path, weights)
    import json

    record = json.loads(path.with_suffix(".json").read_text())["cage"]
    assert (record["file"], record["object"]) == (str(scene), "Cage")
    # A cage from arrays has no object, and says nothing of one.
    unnamed = pmvc.Cage(cage.vertices, cage.faces)
    assert unnamed.object is None
    pmvc.save_weights(path, pmvc.bind(vertices, unnamed, method="mvc"))
    assert "object" not in json.loads(path.with_suffix(".json").read_text())["cage"]


def test_without_a_name_a_warning_names_the_objects_read_together(scene):
    with pytest.warns(pmvc.PmvcWarning, match="the file has 2 objects: 'Cage', 'Mesh', read together"):
        vertices, _ = pmvc.load_mesh(scene)
    assert len(vertices) == 11


def test_a_wrong_or_empty_name_is_refused_with_the_names(scene):
    with pytest.raises(pmvc.FileError, match="no object is named 'Body'; the file has 2 objects: 'Cage', 'Mesh'"):
        pmvc.load_mesh(scene, object="Body")
    with pytest.raises(pmvc.ParameterError, match="an object name cannot be empty"):
        pmvc.load_mesh(scene, object="")
    with pytest.raises(pmvc.ParameterError, match="object must be a string"):
        pmvc.load_mesh(scene, object=3)
