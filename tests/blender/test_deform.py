"""The evaluated mesh equals `pmvc deform` for the cage's evaluated pose: after
an edit, at a keyframed frame, under an armature, for every family."""

import bpy
import numpy as np
import pytest

from conftest import (FAMILIES, TEST_PARAMETERS, TOLERANCE, cage_faces, cli_deform, comb, coordinates, evaluated,
                      evaluated_cage, expected, middle_tip, quad_scene, relative_error, select)


def bind(mesh_obj, cage_obj, method):
    select(mesh_obj, cage_obj)
    assert bpy.ops.pmvc.bind(method=method.upper(), **TEST_PARAMETERS.get(method, {})) == {"FINISHED"}


@pytest.mark.parametrize("method", FAMILIES)
def test_a_cage_edit_deforms_the_comb_as_pmvc_deform_does(method, tmp_path):
    mesh_obj, cage_obj = comb()
    points, rest = coordinates(mesh_obj.data), coordinates(cage_obj.data)
    bind(mesh_obj, cage_obj, method)
    assert np.array_equal(evaluated(mesh_obj), points)  # bound at rest: unmoved
    tip, width = middle_tip(rest)  # pull the middle finger's tip up
    assert len(tip) == 4
    for index in tip:
        cage_obj.data.vertices[int(index)].co.y += 1.5 * width
    cage_obj.data.update()
    bpy.context.view_layer.update()
    posed = coordinates(cage_obj.data)
    cli = cli_deform(tmp_path, points, rest, cage_faces(cage_obj), posed, method)
    diagonal = float(np.linalg.norm(rest.max(0) - rest.min(0)))
    moved = evaluated(mesh_obj)
    assert np.abs(moved - points).max() > 0.5 * width  # it did move
    assert relative_error(moved, cli, diagonal) < TOLERANCE


@pytest.mark.parametrize("method", FAMILIES)
def test_frame_set_on_a_keyframed_cage_shape_key(method):
    mesh_obj, cage_obj = quad_scene()
    points, rest = coordinates(mesh_obj.data), coordinates(cage_obj.data)
    bind(mesh_obj, cage_obj, method)
    cage_obj.shape_key_add(name="Basis", from_mix=False)
    key = cage_obj.shape_key_add(name="bend", from_mix=False)
    for vertex in key.data:
        x, y, z = vertex.co
        vertex.co = (x + 0.4 * (z / 3.0) ** 2, y, z * (1.0 + 0.1 * x))
    key.value = 0.0
    key.keyframe_insert("value", frame=1)
    key.value = 1.0
    key.keyframe_insert("value", frame=11)
    scene = bpy.context.scene
    for frame in (7, 11, 1):
        scene.frame_set(frame)
        posed = evaluated_cage(cage_obj)
        if frame == 1:
            assert np.array_equal(posed, rest) and np.allclose(evaluated(mesh_obj), points, atol=1e-6)
            continue
        assert np.abs(posed - rest).max() > 0.1
        want, diagonal = expected(points, rest, cage_faces(cage_obj), posed, method)
        assert relative_error(evaluated(mesh_obj), want, diagonal) < TOLERANCE, frame


def armature_cage(cage_obj):
    """An armature of two bones bending the cage's upper half; returns it."""
    armature = bpy.data.armatures.new("rig")
    rig = bpy.data.objects.new("rig", armature)
    bpy.context.scene.collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    lower = armature.edit_bones.new("lower")
    lower.head, lower.tail = (0, 0, 0), (0, 0, 1.5)
    upper = armature.edit_bones.new("upper")
    upper.head, upper.tail, upper.parent = (0, 0, 1.5), (0, 0, 3.0), lower
    bpy.ops.object.mode_set(mode="OBJECT")
    groups = {name: cage_obj.vertex_groups.new(name=name) for name in ("lower", "upper")}
    for vertex in cage_obj.data.vertices:
        share = float(np.clip((vertex.co.z - 1.0) / 1.0, 0.0, 1.0))
        groups["upper"].add([vertex.index], share, "REPLACE")
        groups["lower"].add([vertex.index], 1.0 - share, "REPLACE")
    modifier = cage_obj.modifiers.new("Armature", "ARMATURE")
    modifier.object = rig
    return rig


@pytest.mark.parametrize("method", FAMILIES)
def test_an_armature_on_the_cage_drives_the_mesh(method):
    mesh_obj, cage_obj = quad_scene()
    points, rest = coordinates(mesh_obj.data), coordinates(cage_obj.data)
    rig = armature_cage(cage_obj)
    bpy.context.view_layer.update()
    bind(mesh_obj, cage_obj, method)
    rig.pose.bones["upper"].rotation_mode = "XYZ"
    rig.pose.bones["upper"].rotation_euler = (0.0, 0.6, 0.0)
    bpy.context.view_layer.update()
    posed = evaluated_cage(cage_obj)
    assert np.abs(posed - rest).max() > 0.3
    want, diagonal = expected(points, rest, cage_faces(cage_obj), posed, method)
    assert relative_error(evaluated(mesh_obj), want, diagonal) < TOLERANCE


def test_several_meshes_follow_one_cage_and_objects_may_be_moved_apart():
    mesh_obj, cage_obj = comb()
    twin = mesh_obj.copy()
    twin.data = mesh_obj.data.copy()
    bpy.context.scene.collection.objects.link(twin)
    # The cage and the twin elsewhere: each binds in its own mesh's space.
    cage_obj.location = (0.5, -0.25, 0.0)
    twin.location = (0.5, -0.25, 0.0)
    bpy.context.view_layer.update()
    bind(mesh_obj, cage_obj, "mvc")
    bind(twin, cage_obj, "pmvc")
    rest = coordinates(cage_obj.data)
    cage_obj.data.vertices[0].co.x -= 0.5
    cage_obj.data.update()
    bpy.context.view_layer.update()
    posed = coordinates(cage_obj.data)
    faces = cage_faces(cage_obj)
    points = coordinates(mesh_obj.data)
    shift = np.array([0.5, -0.25, 0.0])
    want, diagonal = expected(points, rest + shift, faces, posed + shift, "mvc")
    assert relative_error(evaluated(mesh_obj), want, diagonal) < TOLERANCE
    want, diagonal = expected(points, rest, faces, posed, "pmvc")
    assert relative_error(evaluated(twin), want, diagonal) < TOLERANCE
    assert np.abs(evaluated(twin) - points).max() > 0.01
    # Moving the cage object moves the meshes bound to it.
    before = evaluated(mesh_obj)
    cage_obj.location.z += 0.75
    bpy.context.view_layer.update()
    assert np.abs(evaluated(mesh_obj) - (before + [0, 0, 0.75])).max() < TOLERANCE * diagonal


def test_float64_weights_are_kept_and_applied_as_float64():
    """Where the package binds float64 weights (`dtype=numpy.float64`), a
    binding stored with them deforms with them, saved and reloaded."""
    import pmvc
    from pmvc.blender import binding, store

    mesh_obj, cage_obj = comb()
    points, cage = binding.inputs(mesh_obj, cage_obj, bpy.context.evaluated_depsgraph_get())
    try:
        weights = pmvc.bind(points, cage, method="mvc", dtype=np.float64)
    except TypeError:
        pytest.skip("this pmvc-cage has no float64 weights")
    binding.apply(bpy.context, mesh_obj, cage_obj, points, cage, weights, "mvc", {})
    store.forget()  # rebuilt from the stored arrays
    assert store.load(mesh_obj).weights.matrix.dtype == np.float64
    rest = coordinates(cage_obj.data)
    cage_obj.data.vertices[0].co.z += 0.5
    cage_obj.data.update()
    bpy.context.view_layer.update()
    want = pmvc.deform(points, cage, coordinates(cage_obj.data), weights=weights)
    assert relative_error(evaluated(mesh_obj), want, cage.diagonal) < TOLERANCE
    assert np.abs(evaluated(mesh_obj) - points).max() > 1e-3 and not np.array_equal(rest, coordinates(cage_obj.data))
