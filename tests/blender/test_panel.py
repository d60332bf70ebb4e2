"""The panel's drawing, run against a layout that records what it is given
(background mode draws no interface)."""

import bpy

from conftest import comb, select


class Layout:
    """Records labels, properties and operators as Blender's UILayout takes them."""

    def __init__(self, record=None):
        self.record = record if record is not None else []

    def label(self, text="", icon="NONE"):
        self.record.append(("label", text))

    def prop(self, data, name, **_):
        assert hasattr(data, name), name
        self.record.append(("prop", name))

    def operator(self, idname, **_):
        category, name = idname.split(".")
        assert hasattr(getattr(bpy.ops, category), name), idname
        self.record.append(("operator", idname))
        properties = bpy.ops.pmvc.bind.get_rna_type().properties if name == "bind" else None

        class Properties:
            def __setattr__(self, key, value):
                if properties is not None:
                    assert key in properties.keys(), key
        return Properties()

    def row(self, **_):
        return Layout(self.record)


def draw():
    from pmvc.blender import ui

    layout = Layout()
    ui.draw(layout, bpy.context)
    return layout.record


def test_the_panel_offers_bind_then_the_bound_operators():
    mesh_obj, cage_obj = comb()
    select(mesh_obj, cage_obj)
    before = draw()
    assert ("operator", "pmvc.bind") in before and ("prop", "method") in before
    assert ("label", "Cage: comb cage") in before
    assert bpy.context.window_manager.pmvc.method == "PMVC"
    bpy.ops.pmvc.bind(method="MVC")
    after = draw()
    for name in ("rebind", "unbind", "bake_shape_key", "show_coordinate", "export_weights"):
        assert ("operator", f"pmvc.{name}") in after, name
    assert any(kind == "label" and text.startswith("Bound to comb cage with MVC") for kind, text in after)
    mesh_obj.modifiers.clear()
    assert ("label", "The pmvc modifier was removed: rebind") in draw()
