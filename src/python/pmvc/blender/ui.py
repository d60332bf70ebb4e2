"""The pmvc panel, in the object properties of a mesh and in the 3D view's sidebar."""

import bpy
from bpy.props import EnumProperty, IntProperty

from . import binding, deform, operators, store


def settings_class():
    items = operators.method_items()
    default = "PMVC" if any(item[0] == "PMVC" for item in items) else items[0][0]
    annotations = {"method": EnumProperty(name="Method", items=items, default=default)}
    for pid, spec in binding.parameter_specs().items():
        annotations[pid] = operators.parameter_property(spec)
    annotations["cage_vertex"] = IntProperty(name="Cage vertex", default=0, min=0)
    return type("PMVC_Settings", (bpy.types.PropertyGroup,), {"__annotations__": annotations})


def draw(layout, context):
    obj = context.active_object
    settings = context.window_manager.pmvc
    if obj is None or obj.type != "MESH":
        layout.label(text="Select a cage, then the mesh to bind (active)")
        return
    if not store.is_bound(obj):
        layout.prop(settings, "method")
        entry = next((f for f in binding.families() if f["id"].upper() == settings.method), None)
        for parameter in entry["parameters"] if entry else []:
            layout.prop(settings, parameter["id"])
        others = [o for o in context.selected_objects if o != obj]
        layout.label(text=f"Cage: {others[0].name}" if len(others) == 1 else "Select the cage too (the mesh active)")
        op = layout.operator("pmvc.bind")
        op.method = settings.method
        for pid in binding.parameter_specs():
            setattr(op, pid, getattr(settings, pid))
        return
    method, parameters, cage_obj = store.summary(obj)
    detail = ", ".join(f"{k} {v}" for k, v in parameters.items())
    layout.label(text=f"Bound to {cage_obj.name if cage_obj else '(deleted cage)'} with {method.upper()}" + (f" ({detail})" if detail else ""))
    problem = deform.status.get(obj.name)
    if problem:
        layout.label(text=problem, icon="ERROR")
    if deform.modifier_of(obj) is None:
        layout.label(text="The pmvc modifier was removed: rebind", icon="ERROR")
    entry = next((f for f in binding.families() if f["id"] == method), None)
    for setting in entry.get("deform_parameters", []) if entry else []:
        layout.prop(obj, store.deform_property_name(setting["id"]))
    row = layout.row(align=True)
    row.operator("pmvc.rebind")
    row.operator("pmvc.unbind")
    layout.operator("pmvc.bake_shape_key")
    row = layout.row(align=True)
    row.prop(settings, "cage_vertex")
    row.operator("pmvc.show_coordinate").cage_vertex = settings.cage_vertex
    layout.operator("pmvc.export_weights")


class PMVC_PT_object(bpy.types.Panel):
    bl_label = "pmvc"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type == "MESH"

    def draw(self, context):
        draw(self.layout, context)


class PMVC_PT_sidebar(bpy.types.Panel):
    bl_label = "pmvc"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "pmvc"

    def draw(self, context):
        draw(self.layout, context)
