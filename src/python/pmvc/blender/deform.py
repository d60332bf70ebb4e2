"""The deformation: after each evaluation of the scene, the offsets of every
bound mesh are written into its point attribute ``.pmvc_offset``, which a
geometry nodes modifier (built from Blender's own nodes) adds to the
positions. Blender evaluates the scene a second time, without handlers, when
a handler changed data, so the evaluated mesh holds the deformation when
``view_layer.update()`` or ``scene.frame_set()`` returns."""

import bpy
import numpy as np
from bpy.app.handlers import persistent

import pmvc

from . import store

NODE_GROUP = "pmvc deform"
MODIFIER = "pmvc"

#: Object name -> a sentence saying why its deformation is not current.
status = {}


def node_group():
    """The shared node group: Set Position, offset = the .pmvc_offset attribute."""
    group = bpy.data.node_groups.get(NODE_GROUP)
    if group is not None and group.bl_idname == "GeometryNodeTree":
        return group
    group = bpy.data.node_groups.new(NODE_GROUP, "GeometryNodeTree")
    group.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    group.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes, links = group.nodes, group.links
    source, sink = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    move = nodes.new("GeometryNodeSetPosition")
    offset = nodes.new("GeometryNodeInputNamedAttribute")
    offset.data_type = "FLOAT_VECTOR"
    offset.inputs["Name"].default_value = store.OFFSET
    source.location, offset.location, move.location, sink.location = (-300, 0), (-300, -150), (0, 0), (250, 0)
    links.new(source.outputs[0], move.inputs["Geometry"])
    links.new(offset.outputs["Attribute"], move.inputs["Offset"])
    links.new(move.outputs["Geometry"], sink.inputs[0])
    return group


def modifier_of(obj):
    for modifier in obj.modifiers:
        if modifier.type == "NODES" and modifier.node_group is not None and modifier.node_group.name.startswith(NODE_GROUP):
            return modifier
    return None


def attach(obj):
    """Give ``obj`` the offset attribute (zero) and the modifier, first in its stack."""
    mesh = obj.data
    attribute = mesh.attributes.get(store.OFFSET)
    if attribute is not None:
        mesh.attributes.remove(attribute)
    mesh.attributes.new(store.OFFSET, "FLOAT_VECTOR", "POINT")
    modifier = modifier_of(obj)
    if modifier is None:
        modifier = obj.modifiers.new(MODIFIER, "NODES")
        modifier.node_group = node_group()
        while obj.modifiers[0] != modifier:
            index = list(obj.modifiers).index(modifier)
            obj.modifiers.move(index, index - 1)
    mesh.update_tag()


def detach(obj):
    """Remove the modifier and the attribute: the mesh is its own data again."""
    modifier = modifier_of(obj)
    if modifier is not None:
        obj.modifiers.remove(modifier)
    attribute = obj.data.attributes.get(store.OFFSET)
    if attribute is not None:
        obj.data.attributes.remove(attribute)
    obj.data.update_tag()
    status.pop(obj.name, None)


def to_mesh_space(obj, cage_obj, coordinates):
    """Cage coordinates (its own space) in ``obj``'s space, float64."""
    matrix = np.array(obj.matrix_world.inverted_safe() @ cage_obj.matrix_world, dtype=np.float64)
    if np.array_equal(matrix, np.eye(4)):
        return coordinates
    return coordinates @ matrix[:3, :3].T + matrix[:3, 3]


def evaluated_cage(cage_obj, depsgraph):
    """The cage's evaluated vertices (shape keys, modifiers, armature) and faces."""
    evaluated = cage_obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        coordinates = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", coordinates)
        faces = [tuple(p.vertices) for p in mesh.polygons]
    finally:
        evaluated.to_mesh_clear()
    return coordinates.reshape(-1, 3).astype(np.float64), faces


def posed_cage(obj, cage_obj, depsgraph):
    coordinates, _ = evaluated_cage(cage_obj, depsgraph)
    evaluated_obj = obj.evaluated_get(depsgraph)
    evaluated_cage_obj = cage_obj.evaluated_get(depsgraph)
    return to_mesh_space(evaluated_obj, evaluated_cage_obj, coordinates)


class NotInDepsgraph(ValueError):
    """The cage is not evaluated in this depsgraph (disabled in renders, say)."""


def current_pose(obj, depsgraph, changed_only=False, settings=None):
    """(binding, posed cage in the mesh's space) as ``depsgraph`` has it
    (posed None when ``changed_only`` and neither the cage nor the deformation
    ``settings`` changed since the last update); raises with a sentence when it
    cannot be read."""
    binding = store.load(obj)
    cage_obj = store.cage_of(obj)
    if cage_obj is None:
        raise ValueError("its cage object was deleted")
    if len(obj.data.vertices) != len(binding.points):
        raise ValueError(f"it has {len(obj.data.vertices)} vertices, it was bound with {len(binding.points)}: unbind and bind again")
    if not cage_obj.evaluated_get(depsgraph).is_evaluated:
        raise NotInDepsgraph(f"its cage {cage_obj.name} is not in this view layer or render")
    posed = posed_cage(obj, cage_obj, depsgraph)
    if posed.shape != binding.rest.shape:
        raise ValueError(f"its cage {cage_obj.name} has {len(posed)} vertices, it was bound with {len(binding.rest)} "
                         "(a modifier on the cage that adds vertices, or an edit): rebind")
    last = binding.last_posed.get(obj.name_full)
    if changed_only and last is not None and np.array_equal(posed, last[0]) and last[1] == settings:
        return binding, None
    return binding, posed


def update_object(obj, depsgraph):
    """Rewrite ``obj``'s offsets if its cage moved; a sentence if it cannot."""
    if obj.mode == "EDIT":
        return
    try:
        settings = store.deform_settings(obj)
        binding, posed = current_pose(obj, depsgraph, changed_only=True, settings=settings)
        if posed is None:
            return
        offsets = binding.offsets(posed, settings)
    except NotInDepsgraph:
        return  # keep the offsets of the depsgraph that has it
    except (pmvc.PmvcError, ValueError, KeyError, TypeError, RuntimeError) as error:
        status[obj.name] = str(error)
        return
    except Exception as error:  # a handler's traceback would repeat at every update
        status[obj.name] = f"pmvc could not update it: {type(error).__name__}: {error}"
        return
    attribute = obj.data.attributes.get(store.OFFSET)
    if attribute is None or attribute.domain != "POINT" or attribute.data_type != "FLOAT_VECTOR":
        status[obj.name] = "its offset attribute is missing: bind again"
        return
    attribute.data.foreach_set("vector", offsets.astype(np.float32).ravel())
    obj.data.update_tag()
    binding.last_posed[obj.name_full] = (posed, settings)
    status.pop(obj.name, None)


def bound_objects():
    return [obj for obj in bpy.data.objects if store.is_bound(obj)]


def update_all(depsgraph):
    for obj in bound_objects():
        update_object(obj, depsgraph)


@persistent
def on_depsgraph_update(scene, depsgraph):
    update_all(depsgraph)


@persistent
def on_frame_change(scene, depsgraph):
    update_all(depsgraph)


@persistent
def on_undo(*_args):
    store.forget_poses()


@persistent
def on_load(*_args):
    store.forget()
    status.clear()


HANDLERS = (
    (bpy.app.handlers.depsgraph_update_post, on_depsgraph_update),
    (bpy.app.handlers.frame_change_post, on_frame_change),
    (bpy.app.handlers.undo_post, on_undo),
    (bpy.app.handlers.redo_post, on_undo),
    (bpy.app.handlers.load_post, on_load),
)


def add_handlers():
    remove_handlers()
    for handlers, function in HANDLERS:
        handlers.append(function)


def remove_handlers():
    for handlers, function in HANDLERS:
        for existing in [h for h in handlers if getattr(h, "__name__", None) == function.__name__ and getattr(h, "__module__", None) == function.__module__]:
            handlers.remove(existing)
