"""The operators: bind (in the background in the UI, with progress and Esc),
unbind, rebind, bake_shape_key, export_weights and show_coordinate."""

import json
import threading

import bpy
import numpy as np
from bpy.props import EnumProperty, FloatProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ExportHelper

import pmvc
from pmvc import _native

from . import binding, deform, store

# ReferenceError: an object deleted while a bind ran in the background.
REFUSED = (pmvc.PmvcError, binding.InputProblem, ValueError, KeyError, TypeError, RuntimeError, ReferenceError)


class Cancelled(Exception):
    """Raised in the progress callback to stop a bind (Esc)."""


def method_items(_self=None, _context=None):
    return [(f["id"].upper(), f["name"], f["summary"]) for f in binding.families()]


def bound_object(context):
    obj = context.active_object
    if obj is None or obj.type != "MESH":
        raise binding.InputProblem("the active object is not a mesh")
    if not store.is_bound(obj):
        raise binding.InputProblem(f"{obj.name!r} is not bound to a cage")
    return obj


class _Binder:
    """Binds in the calling thread (scripts, background mode) or, from the UI,
    in a worker thread while a modal operator shows progress; Esc cancels."""

    _thread = None

    def prepare(self, context):
        """(obj, cage_obj, points, cage, method, parameters); raises InputProblem."""
        raise NotImplementedError

    def execute(self, context):
        try:
            obj, cage_obj, points, cage, method, parameters = self.prepare(context)
            weights = binding.run_bind(points, cage, method, parameters)
            binding.apply(context, obj, cage_obj, points, cage, weights, method, parameters)
        except REFUSED as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, self.done_sentence(obj, cage_obj, weights))
        return {"FINISHED"}

    def invoke(self, context, _event):
        if bpy.app.background:
            return self.execute(context)
        return self.start(context)

    def start(self, context):
        """Start the bind in a worker thread; modal() follows it."""
        try:
            job = self.prepare(context)
        except REFUSED as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self._job, self._done, self._total = job, 0, len(job[2])
        self._cancel, self._result, self._error = False, None, None

        def progress(done, total):
            self._done, self._total = done, total
            if self._cancel:
                raise Cancelled()

        def work():
            try:
                self._result = binding.run_bind(job[2], job[3], job[4], job[5], progress)
            except BaseException as error:  # reported by modal(), in the main thread
                self._error = error

        self._thread = threading.Thread(target=work, daemon=True)
        self._thread.start()
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            self._cancel = True
        if event.type != "TIMER" and not self._cancel:
            return {"PASS_THROUGH"}
        share = 100 * self._done // max(self._total, 1)
        context.window_manager.progress_update(share)
        context.workspace.status_text_set(f"pmvc: binding {self._job[0].name} with {self._job[4]}, {share}% (Esc cancels)")
        if self._thread.is_alive():
            return {"RUNNING_MODAL"}
        self._finish(context)
        if isinstance(self._error, Cancelled) or (self._cancel and self._result is None):
            self.report({"WARNING"}, "pmvc: bind cancelled; nothing changed")
            return {"CANCELLED"}
        if self._error is not None:
            self.report({"ERROR"}, str(self._error))
            return {"CANCELLED"}
        obj, cage_obj, points, cage, method, parameters = self._job
        try:
            binding.apply(context, obj, cage_obj, points, cage, self._result, method, parameters)
        except REFUSED as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, self.done_sentence(obj, cage_obj, self._result))
        return {"FINISHED"}

    def _finish(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)

    @staticmethod
    def done_sentence(obj, cage_obj, weights):
        classes = np.bincount(weights.classes.astype(np.int64), minlength=3)
        sentence = (f"{obj.name}: bound to {cage_obj.name} with {weights.metadata.get('method_name', weights.method)} "
                    f"in {weights.seconds:.2f} s ({len(weights.classes)} vertices, {classes[0]} inside")
        if classes[2]:
            sentence += f", {classes[2]} outside the cage"
        return sentence + ")"


def _parameter_annotations():
    items = method_items()
    default = "PMVC" if any(item[0] == "PMVC" for item in items) else items[0][0]
    annotations = {"method": EnumProperty(name="Method", items=items, default=default)}
    for pid, spec in binding.parameter_specs().items():
        annotations[pid] = parameter_property(spec)
    return annotations


def parameter_property(spec):
    """A family's setting as a Blender property: whole numbers as an integer,
    a decimal (the Poisson ratio) as a float shown to the thousandth."""
    name = spec.get("label", spec["id"])
    if binding.is_decimal(spec):
        return FloatProperty(name=name, default=spec["default"], min=spec["min"], max=spec["max"],
                             step=1, precision=3)
    return IntProperty(name=name, default=spec["default"], min=spec["min"], max=spec["max"])


def deform_property(spec):
    """A deformation setting (Somigliana's bulging γ) as a property of the
    bound object, a float shown to the hundredth the package holds."""
    return FloatProperty(name=spec.get("label", spec["id"]), default=spec["default"], min=spec["min"],
                         max=spec["max"], step=10, precision=2, update=_redeform,
                         description="Read when the weights deform the cage's pose: changing it binds nothing again")


def _redeform(obj, _context):
    """A deformation setting changed: the next depsgraph update redeforms
    ``obj`` (its handler compares the settings with the last ones used)."""
    obj.update_tag()


class PMVC_OT_unbind(bpy.types.Operator):
    """Remove the binding: the mesh is back at its rest positions"""
    bl_idname = "pmvc.unbind"
    bl_label = "Unbind"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        try:
            obj = bound_object(context)
        except REFUSED as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        binding.release(obj)
        self.report({"INFO"}, f"{obj.name}: unbound, at rest")
        return {"FINISHED"}


class PMVC_OT_rebind(_Binder, bpy.types.Operator):
    """Bind again with the cage's current shape as its rest shape"""
    bl_idname = "pmvc.rebind"
    bl_label = "Rebind"
    bl_options = {"REGISTER", "UNDO"}

    def prepare(self, context):
        obj = bound_object(context)
        method, parameters, cage_obj = store.summary(obj)
        if cage_obj is None:
            raise binding.InputProblem(f"{obj.name!r}: its cage object was deleted; bind it to another")
        points, cage = binding.inputs(obj, cage_obj, context.evaluated_depsgraph_get())
        return obj, cage_obj, points, cage, method, parameters


class PMVC_OT_bake_shape_key(bpy.types.Operator):
    """Store the current deformation as a shape key (value 0 while bound)"""
    bl_idname = "pmvc.bake_shape_key"
    bl_label = "Bake Shape Key"
    bl_options = {"REGISTER", "UNDO"}

    name: StringProperty(name="Name", default="pose")

    def execute(self, context):
        try:
            obj = bound_object(context)
            current, posed = deform.current_pose(obj, context.evaluated_depsgraph_get())
            moves = current.offsets(posed, store.deform_settings(obj))
        except REFUSED as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        mesh = obj.data
        if mesh.shape_keys is None:
            obj.shape_key_add(name="Basis", from_mix=False)
        key = obj.shape_key_add(name=self.name, from_mix=False)
        rest = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", rest)
        key.data.foreach_set("co", (rest.reshape(-1, 3) + moves).astype(np.float32).ravel())
        key.value = 0.0
        mesh.update_tag()
        self.report({"INFO"}, f"{obj.name}: shape key {key.name!r} holds the pose (value 0 while bound; "
                              "unbind, then set it to 1)")
        return {"FINISHED"}


class PMVC_OT_export_weights(bpy.types.Operator, ExportHelper):
    """Write the weights as `pmvc bind` writes them (W.npy, W.classes.npy, W.json)"""
    bl_idname = "pmvc.export_weights"
    bl_label = "Export Weights"
    bl_options = {"REGISTER"}

    filename_ext = ".npy"
    filter_glob: StringProperty(default="*.npy;*.npz", options={"HIDDEN"})  # Green: .npz

    def execute(self, context):
        try:
            obj = bound_object(context)
            weights = with_objects_named(store.load(obj).weights, obj)
            path = self.filepath
            if weights.triangles is not None and path.lower().endswith(".npy"):
                path = path[:-4] + ".npz"  # Green's φ and ψ, as `pmvc bind` writes them
            pmvc.save_weights(path, weights)
        except REFUSED as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, f"{obj.name}: weights written to {path} (with .classes.npy and .json)")
        return {"FINISHED"}


def with_objects_named(weights, obj):
    """``weights`` whose metadata names the .blend file and the mesh and cage
    objects, where ``pmvc bind`` names its input files and objects."""
    metadata = json.loads(weights.__reduce__()[1][2])
    blend = bpy.data.filepath  # "" for a file never saved, as for arrays
    _, _, cage_obj = store.summary(obj)
    for record, named in (("mesh", obj), ("cage", cage_obj)):
        metadata[record]["file"] = blend
        if named is not None:
            metadata[record]["object"] = named.name
    return _native._restore_weights(weights.matrix, weights.classes, json.dumps(metadata), None)


class PMVC_OT_show_coordinate(bpy.types.Operator):
    """One cage vertex's coordinate function as a vertex group (see it in Weight Paint)"""
    bl_idname = "pmvc.show_coordinate"
    bl_label = "Show Coordinate"
    bl_options = {"REGISTER", "UNDO"}

    cage_vertex: IntProperty(name="Cage vertex", default=0, min=0)

    def execute(self, context):
        try:
            obj = bound_object(context)
            current = store.load(obj)
            count = len(current.rest)
            if self.cage_vertex >= count:
                raise binding.InputProblem(f"cage vertex {self.cage_vertex} does not exist (the cage has {count}: 0 to {count - 1})")
            if len(obj.data.vertices) != len(current.points):
                raise binding.InputProblem(f"{obj.name!r} has {len(obj.data.vertices)} vertices, it was bound with {len(current.points)}")
        except REFUSED as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        column = current.weights.matrix[:, self.cage_vertex].astype(np.float64)
        name = f"pmvc {current.method} {self.cage_vertex}"
        group = obj.vertex_groups.get(name) or obj.vertex_groups.new(name=name)
        clamped = np.clip(column, 0.0, 1.0)
        for value in np.unique(clamped):
            group.add(np.flatnonzero(clamped == value).tolist(), float(value), "REPLACE")
        obj.vertex_groups.active_index = group.index
        low, high = float(column.min()), float(column.max())
        note = f"; values below 0 shown as 0 (minimum {low:.4g})" if low < 0 else ""
        self.report({"INFO"}, f"{obj.name}: vertex group {name!r}, from {low:.4g} to {high:.4g}{note}")
        return {"FINISHED"}


def bind_class():
    """PMVC_OT_bind, its method enum and parameters read from the package."""

    def prepare(self, context):
        obj, cage_obj = binding.mesh_and_cage(context)
        method = self.method.lower()
        binding.family(method)
        parameters = binding.parameters_for(method, {pid: getattr(self, pid) for pid in binding.parameter_specs()})
        points, cage = binding.inputs(obj, cage_obj, context.evaluated_depsgraph_get())
        return obj, cage_obj, points, cage, method, parameters

    return type("PMVC_OT_bind", (_Binder, bpy.types.Operator), {
        "__doc__": "Bind the active mesh to the other selected object (the cage)",
        "bl_idname": "pmvc.bind",
        "bl_label": "Bind",
        "bl_options": {"REGISTER", "UNDO"},
        "__annotations__": _parameter_annotations(),
        "prepare": prepare,
    })


def classes():
    return [bind_class(), PMVC_OT_unbind, PMVC_OT_rebind, PMVC_OT_bake_shape_key,
            PMVC_OT_export_weights, PMVC_OT_show_coordinate]
