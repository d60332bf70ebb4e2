"""Unbind, rebind, bake, export, show a coordinate, revert (what undo restores),
save and reload, and a .blend opened without the add-on."""

import json
import textwrap

import bpy
import numpy as np
import pytest

import pmvc
from conftest import (TOLERANCE, cage_faces, comb, coordinates, evaluated, expected, quad_scene,
                      relative_error, run_python, select)


def bound_comb(method="pmvc"):
    mesh_obj, cage_obj = comb()
    select(mesh_obj, cage_obj)
    assert bpy.ops.pmvc.bind(method=method.upper()) == {"FINISHED"}
    return mesh_obj, cage_obj


def pull(cage_obj, index=0, amount=(0.0, 0.0, 0.6)):
    vertex = cage_obj.data.vertices[index]
    vertex.co = (vertex.co.x + amount[0], vertex.co.y + amount[1], vertex.co.z + amount[2])
    cage_obj.data.update()
    bpy.context.view_layer.update()


def test_unbind_restores_the_rest_positions_exactly():
    mesh_obj, cage_obj = bound_comb()
    rest = coordinates(mesh_obj.data)
    pull(cage_obj)
    assert np.abs(evaluated(mesh_obj) - rest).max() > 1e-3
    assert bpy.ops.pmvc.unbind() == {"FINISHED"}
    bpy.context.view_layer.update()
    assert np.array_equal(evaluated(mesh_obj), rest)
    assert np.array_equal(coordinates(mesh_obj.data), rest)
    assert len(mesh_obj.modifiers) == 0 and ".pmvc_offset" not in mesh_obj.data.attributes
    assert "_pmvc" not in mesh_obj and not [t for t in bpy.data.texts if t.name.startswith(".pmvc")]
    pull(cage_obj)  # the cage no longer moves it
    assert np.array_equal(evaluated(mesh_obj), rest)


def test_rebind_takes_the_cage_as_it_is_as_rest():
    mesh_obj, cage_obj = bound_comb()
    points = coordinates(mesh_obj.data)
    pull(cage_obj)
    assert bpy.ops.pmvc.rebind() == {"FINISHED"}
    assert len([t for t in bpy.data.texts if t.name.startswith(".pmvc")]) == 1  # the old one went
    bpy.context.view_layer.update()
    assert np.array_equal(evaluated(mesh_obj), points)  # the new rest: unmoved
    rest = coordinates(cage_obj.data)
    pull(cage_obj, 5, (0.3, 0.0, 0.0))
    want, diagonal = expected(points, rest, cage_faces(cage_obj), coordinates(cage_obj.data), "pmvc")
    assert relative_error(evaluated(mesh_obj), want, diagonal) < TOLERANCE


def test_bake_shape_key_holds_the_current_deformation():
    mesh_obj, cage_obj = bound_comb()
    pull(cage_obj)
    posed = evaluated(mesh_obj)
    assert bpy.ops.pmvc.bake_shape_key(name="pose") == {"FINISHED"}
    key = mesh_obj.data.shape_keys.key_blocks["pose"]
    assert key.value == 0.0
    assert np.abs(coordinates(key) - posed).max() < TOLERANCE * 8.6
    bpy.context.view_layer.update()
    assert np.abs(evaluated(mesh_obj) - posed).max() < TOLERANCE * 8.6  # not applied twice
    rest = coordinates(mesh_obj.data)
    assert bpy.ops.pmvc.unbind() == {"FINISHED"}
    key.value = 1.0
    bpy.context.view_layer.update()
    assert np.abs(evaluated(mesh_obj) - posed).max() < TOLERANCE * 8.6
    assert np.array_equal(coordinates(mesh_obj.data), rest)


def test_export_weights_writes_what_pmvc_bind_writes(tmp_path):
    mesh_obj, cage_obj = bound_comb("harmonic")
    path = tmp_path / "W.npy"
    assert bpy.ops.pmvc.export_weights(filepath=str(path)) == {"FINISHED"}
    for name in ("W.npy", "W.classes.npy", "W.json"):
        assert (tmp_path / name).is_file(), name
    loaded = pmvc.load_weights(str(path))
    points, rest = coordinates(mesh_obj.data), coordinates(cage_obj.data)
    bound = pmvc.bind(points, pmvc.Cage(rest, cage_faces(cage_obj)), method="harmonic", grid=64, backend="cpu")
    assert np.array_equal(loaded.matrix, bound.matrix)
    written = json.loads((tmp_path / "W.json").read_text())
    assert written["method"] == "harmonic"
    # The objects bound, by their Blender names, where `pmvc bind` names files.
    assert (written["mesh"]["object"], written["cage"]["object"]) == (mesh_obj.name, cage_obj.name)
    assert written["mesh"]["file"] == bpy.data.filepath


def test_green_weights_are_exported_as_npz_as_pmvc_bind_writes_them(tmp_path, capfd):
    mesh_obj, cage_obj = bound_comb("green")
    assert bpy.ops.pmvc.export_weights(filepath=str(tmp_path / "W.npy")) == {"FINISHED"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["W.classes.npy", "W.json", "W.npz"]
    assert "W.npz" in capfd.readouterr().out
    loaded = pmvc.load_weights(str(tmp_path / "W.npz"))
    assert loaded.matrix.shape == (7456, 40 + 76)


def test_show_coordinate_makes_a_vertex_group_and_reports_the_minimum(capfd):
    mesh_obj, cage_obj = bound_comb("mvc")
    capfd.readouterr()
    assert bpy.ops.pmvc.show_coordinate(cage_vertex=3) == {"FINISHED"}
    group = mesh_obj.vertex_groups["pmvc mvc 3"]
    column = pmvc.bind(coordinates(mesh_obj.data), pmvc.Cage(coordinates(cage_obj.data), cage_faces(cage_obj)),
                       method="mvc").matrix[:, 3].astype(np.float64)
    weights = np.zeros(len(column))
    for vertex in mesh_obj.data.vertices:
        for element in vertex.groups:
            if element.group == group.index:
                weights[vertex.index] = element.weight
    assert np.allclose(weights, np.clip(column, 0, 1), atol=1e-6)
    assert column.min() < 0
    assert f"minimum {column.min():.4g}" in capfd.readouterr().out


def test_reverting_to_the_state_before_bind_unbinds(tmp_path):
    """Undo cannot be driven in background mode (ed.undo's poll needs a
    window); a binding is ID data only (an ID property, an attribute, a
    modifier), which global undo restores like a revert of the file."""
    mesh_obj, cage_obj = comb()
    rest = coordinates(mesh_obj.data)
    before = str(tmp_path / "before.blend")
    bpy.ops.wm.save_as_mainfile(filepath=before)
    select(mesh_obj, cage_obj)
    bpy.ops.pmvc.bind(method="PMVC")
    pull(cage_obj)
    bpy.ops.wm.open_mainfile(filepath=before)
    mesh_obj, cage_obj = bpy.data.objects["comb"], bpy.data.objects["comb cage"]
    assert "_pmvc" not in mesh_obj and len(mesh_obj.modifiers) == 0
    pull(cage_obj)
    assert np.array_equal(evaluated(mesh_obj), rest)


def test_reverting_to_the_state_before_a_bake_keeps_the_binding(tmp_path):
    mesh_obj, cage_obj = bound_comb()
    pull(cage_obj)
    posed = evaluated(mesh_obj)
    before = str(tmp_path / "before.blend")
    bpy.ops.wm.save_as_mainfile(filepath=before)
    bpy.ops.pmvc.bake_shape_key(name="pose")
    bpy.ops.wm.open_mainfile(filepath=before)
    mesh_obj, cage_obj = bpy.data.objects["comb"], bpy.data.objects["comb cage"]
    assert mesh_obj.data.shape_keys is None and "_pmvc" in mesh_obj
    bpy.context.view_layer.update()
    assert np.array_equal(evaluated(mesh_obj), posed)
    pull(cage_obj, 3)  # still bound: it follows
    assert np.abs(evaluated(mesh_obj) - posed).max() > 1e-3


def test_save_reload_and_deform_again(tmp_path):
    mesh_obj, cage_obj = quad_scene()
    points, rest = coordinates(mesh_obj.data), coordinates(cage_obj.data)
    select(mesh_obj, cage_obj)
    bpy.ops.pmvc.bind(method="GREEN")
    pull(cage_obj, 0, (0.2, 0.1, 0.0))
    path = str(tmp_path / "bound.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=path)
    mesh_obj, cage_obj = bpy.data.objects["blob"], bpy.data.objects["box cage"]
    pull(cage_obj, 7, (0.0, -0.3, 0.1))
    want, diagonal = expected(points, rest, cage_faces(cage_obj), coordinates(cage_obj.data), "green")
    assert relative_error(evaluated(mesh_obj), want, diagonal) < TOLERANCE


def test_a_blend_opens_without_the_add_on(tmp_path):
    mesh_obj, cage_obj = bound_comb()
    rest = coordinates(mesh_obj.data)
    pull(cage_obj)
    posed = evaluated(mesh_obj)
    path = tmp_path / "bound.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    np.save(tmp_path / "rest.npy", rest)
    np.save(tmp_path / "posed.npy", posed)
    script = textwrap.dedent(f"""
        import bpy, numpy as np
        assert "bl_ext.user_default.pmvc" not in {{a.module for a in bpy.context.preferences.addons}}
        bpy.ops.wm.open_mainfile(filepath={str(path)!r})
        obj = bpy.data.objects["comb"]
        def read(mesh):
            out = np.empty(len(mesh.vertices) * 3, np.float32); mesh.vertices.foreach_get("co", out)
            return out.reshape(-1, 3).astype(np.float64)
        assert np.array_equal(read(obj.data), np.load({str(tmp_path / 'rest.npy')!r})), "mesh data not at rest"
        shown = read(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh())
        assert np.abs(shown - np.load({str(tmp_path / 'posed.npy')!r})).max() < 1e-5, "pose as saved"
        print("opened fine")
    """)
    import tempfile
    result = run_python(script, BLENDER_USER_RESOURCES=tempfile.mkdtemp())
    assert result.returncode == 0, result.stdout + result.stderr
    assert "opened fine" in result.stdout
    assert "Traceback" not in result.stderr and "Error" not in result.stdout, result.stdout + result.stderr


def test_a_bind_cancelled_from_its_progress_changes_nothing():
    """Esc in the interface sets a flag the progress callback raises on; the
    modal operator itself needs a window, so its worker's path is run here."""
    from pmvc.blender import binding, operators

    mesh_obj, cage_obj = comb()
    rest = coordinates(mesh_obj.data)
    points, cage = binding.inputs(mesh_obj, cage_obj, bpy.context.evaluated_depsgraph_get())
    calls = []

    def progress(done, total):
        calls.append(done)
        raise operators.Cancelled()

    with pytest.raises(operators.Cancelled):
        binding.run_bind(points, cage, "pmvc", {"resolution": 256}, progress)
    assert calls and "_pmvc" not in mesh_obj and len(mesh_obj.modifiers) == 0
    assert np.array_equal(evaluated(mesh_obj), rest)
