"""The interface's bind: a worker thread, progress in the status bar, Esc.
A modal operator needs a window, which background mode lacks; here the
operator's own start() and modal() run against a recording window manager, with
the timer and Esc events it would get."""

import inspect
import time

import bpy
import numpy as np

import pmvc

from conftest import comb, coordinates, evaluated, select


class WindowManager:
    def __init__(self):
        self.progress, self.handlers, self.timers = [], [], 0

    def event_timer_add(self, step, window=None):
        self.timers += 1
        return "timer"

    def event_timer_remove(self, timer):
        self.timers -= 1

    def progress_begin(self, low, high):
        self.progress.append(("begin", low, high))

    def progress_update(self, value):
        self.progress.append(value)

    def progress_end(self):
        self.progress.append("end")

    def modal_handler_add(self, operator):
        self.handlers.append(operator)


class Workspace:
    def __init__(self):
        self.texts = []

    def status_text_set(self, text):
        self.texts.append(text)


class Context:
    def __init__(self):
        self.window_manager, self.workspace, self.window = WindowManager(), Workspace(), None

    def __getattr__(self, name):
        return getattr(bpy.context, name)


class Event:
    def __init__(self, kind):
        self.type = kind


def operator(method, **parameters):
    """An object with the bind operator's methods and properties (Blender makes
    operator instances itself)."""
    cls = bpy.types.PMVC_OT_bind
    names = ("start", "modal", "_finish", "done_sentence", "prepare")
    probe = type("Probe", (), {name: inspect.getattr_static(cls, name) for name in names})()
    probe.reports = []
    probe.report = lambda kind, text: probe.reports.append((set(kind), text))
    probe.method = method
    # Every family's setting at its default, as the operator's properties are.
    defaults = {spec["id"]: spec["default"] for family in pmvc.families() for spec in family["parameters"]}
    for key, value in {**defaults, "resolution": 32, "grid": 64, **parameters}.items():
        setattr(probe, key, value)
    return probe


def follow(probe, context, escape_after=None):
    started = time.perf_counter()
    while True:
        if escape_after is not None and time.perf_counter() - started > escape_after:
            result = probe.modal(context, Event("ESC"))
            escape_after = None
        else:
            result = probe.modal(context, Event("TIMER"))
        if result != {"RUNNING_MODAL"}:
            return result
        assert time.perf_counter() - started < 120
        time.sleep(0.05)


def test_the_interface_bind_runs_in_a_thread_with_progress():
    mesh_obj, cage_obj = comb()
    select(mesh_obj, cage_obj)
    context, probe = Context(), operator("PMVC", resolution=64)
    assert probe.start(context) == {"RUNNING_MODAL"}
    assert context.window_manager.handlers == [probe]
    assert probe.modal(context, Event("MOUSEMOVE")) == {"PASS_THROUGH"}  # the interface stays live
    assert follow(probe, context) == {"FINISHED"}
    assert "_pmvc" in mesh_obj and context.window_manager.timers == 0
    assert context.window_manager.progress[-1] == "end" and context.workspace.texts[-1] is None
    assert any(text and "(Esc cancels)" in text for text in context.workspace.texts)
    assert probe.reports[-1][0] == {"INFO"} and "bound to comb cage with PMVC" in probe.reports[-1][1]
    cage_obj.data.vertices[0].co.z += 0.5
    cage_obj.data.update()
    bpy.context.view_layer.update()
    assert np.abs(evaluated(mesh_obj) - coordinates(mesh_obj.data)).max() > 1e-3


def test_esc_cancels_the_interface_bind_and_changes_nothing():
    mesh_obj, cage_obj = comb()
    rest = coordinates(mesh_obj.data)
    select(mesh_obj, cage_obj)
    context, probe = Context(), operator("PMVC", resolution=512)  # about 30 s to finish
    assert probe.start(context) == {"RUNNING_MODAL"}
    started = time.perf_counter()
    assert follow(probe, context, escape_after=0.3) == {"CANCELLED"}
    assert time.perf_counter() - started < 10
    assert probe.reports[-1] == ({"WARNING"}, "pmvc: bind cancelled; nothing changed")
    assert "_pmvc" not in mesh_obj and len(mesh_obj.modifiers) == 0
    assert np.array_equal(evaluated(mesh_obj), rest)
    assert context.window_manager.timers == 0 and context.workspace.texts[-1] is None


def test_bad_input_in_the_interface_is_a_report_before_any_thread():
    mesh_obj, _ = comb()
    select(mesh_obj)
    context, probe = Context(), operator("PMVC")
    assert probe.start(context) == {"CANCELLED"}
    assert probe.reports[-1][0] == {"ERROR"} and "select exactly one cage" in probe.reports[-1][1]
    assert context.window_manager.handlers == []
