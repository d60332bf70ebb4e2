"""Bad input is a report (an operator error), never a traceback, and the mesh
stays as it was."""

import bpy
import numpy as np
import pytest

from conftest import box, comb, coordinates, evaluated, link_mesh, quad_scene, select


def refused(operator, match, **arguments):
    with pytest.raises(RuntimeError, match=match) as caught:
        operator(**arguments)
    assert "Traceback" not in str(caught.value)
    return str(caught.value)


def untouched(mesh_obj, rest):
    assert "_pmvc" not in mesh_obj and len(mesh_obj.modifiers) == 0
    bpy.context.view_layer.update()
    assert np.array_equal(coordinates(mesh_obj.data), rest)
    assert np.array_equal(evaluated(mesh_obj), rest)


def test_an_open_cage_is_refused_with_the_command_lines_words():
    mesh_obj, cage_obj = quad_scene()
    rest = coordinates(mesh_obj.data)
    vertices, faces = box(4, 4, 4, size=(1.0, 1.0, 3.0), center=(0, 0, 1.5))
    open_cage = link_mesh("open cage", vertices, faces[1:])
    select(mesh_obj, open_cage)
    message = refused(bpy.ops.pmvc.bind, "cage 'open cage': the cage is not closed", method="PMVC")
    assert "Blender's indices are one less" in message
    untouched(mesh_obj, rest)


def test_a_cage_with_no_volume_is_refused():
    mesh_obj, cage_obj = quad_scene()
    rest = coordinates(mesh_obj.data)
    flat = link_mesh("flat cage", [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [(0, 1, 2, 3), (3, 2, 1, 0)])
    select(mesh_obj, flat)
    refused(bpy.ops.pmvc.bind, "cage 'flat cage': the cage encloses no volume", method="MVC")
    untouched(mesh_obj, rest)


def test_a_non_mesh_selected_is_refused():
    mesh_obj, cage_obj = quad_scene()
    rest = coordinates(mesh_obj.data)
    empty = bpy.data.objects.new("an empty", None)
    bpy.context.scene.collection.objects.link(empty)
    select(mesh_obj, empty)
    refused(bpy.ops.pmvc.bind, "not a mesh", method="PMVC")
    untouched(mesh_obj, rest)
    select(empty, cage_obj)
    refused(bpy.ops.pmvc.bind, "not a mesh", method="PMVC")
    select(mesh_obj)
    refused(bpy.ops.pmvc.bind, "select exactly one cage", method="PMVC")
    refused(bpy.ops.pmvc.unbind, "not bound")
    untouched(mesh_obj, rest)


def test_a_mesh_whose_vertex_count_changed_since_binding():
    mesh_obj, cage_obj = comb()
    select(mesh_obj, cage_obj)
    bpy.ops.pmvc.bind(method="PMVC")
    mesh_obj.data.vertices.add(3)
    mesh_obj.data.update()
    changed = coordinates(mesh_obj.data)
    cage_obj.data.vertices[0].co.z += 0.5
    cage_obj.data.update()
    bpy.context.view_layer.update()  # the update reports nothing and raises nothing
    from pmvc.blender import deform
    assert "7459 vertices, it was bound with 7456" in deform.status["comb"]
    refused(bpy.ops.pmvc.bake_shape_key, "7459 vertices, it was bound with 7456")
    refused(bpy.ops.pmvc.show_coordinate, "7459 vertices", cage_vertex=0)
    assert mesh_obj.data.shape_keys is None
    assert np.array_equal(coordinates(mesh_obj.data), changed)
    assert bpy.ops.pmvc.unbind() == {"FINISHED"}
    assert np.array_equal(evaluated(mesh_obj), changed)


def test_a_cage_vertex_out_of_range_and_a_cage_that_lost_vertices():
    mesh_obj, cage_obj = comb()
    select(mesh_obj, cage_obj)
    bpy.ops.pmvc.bind(method="MVC")
    refused(bpy.ops.pmvc.show_coordinate, "cage vertex 40 does not exist", cage_vertex=40)
    cage_obj.data.vertices.add(1)
    cage_obj.data.update()
    bpy.context.view_layer.update()
    from pmvc.blender import deform
    assert "has 41 vertices, it was bound with 40" in deform.status["comb"]
