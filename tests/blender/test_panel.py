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


def test_the_deformation_settings_of_a_somigliana_binding_are_properties_of_the_object():
    import numpy as np
    import pmvc
    from conftest import TEST_PARAMETERS, coordinates, evaluated, middle_tip, relative_error
    from pmvc.blender import store

    mesh_obj, cage_obj = comb()
    select(mesh_obj, cage_obj)
    assert bpy.ops.pmvc.bind(method="SOMIGLIANA", **TEST_PARAMETERS["somigliana"]) == {"FINISHED"}
    assert ("prop", "pmvc_bulging") in draw()
    assert ("prop", "pmvc_local_blend") in draw()
    points, rest = coordinates(mesh_obj.data), coordinates(cage_obj.data)
    tip, width = middle_tip(rest)
    for index in tip:
        cage_obj.data.vertices[int(index)].co.y += 1.5 * width
    cage_obj.data.update()
    bpy.context.view_layer.update()
    plain = evaluated(mesh_obj)
    posed = coordinates(cage_obj.data)
    weights = store.load(mesh_obj).weights
    cage = pmvc.Cage(rest, [list(p.vertices) for p in cage_obj.data.polygons])
    diagonal = cage.diagonal
    # Setting it redeforms, as pmvc.deform does with the same weights and γ.
    mesh_obj.pmvc_bulging = 3.0
    bpy.context.view_layer.update()
    bulged = evaluated(mesh_obj)
    expected = pmvc.deform(points, cage, posed, weights=weights, bulging=3.0)
    assert relative_error(bulged, expected, diagonal) < 1e-6
    assert np.abs(bulged - plain).max() > 1e-3 * diagonal
    # So does the local blend, with the bulging.
    mesh_obj.pmvc_local_blend = 0.5
    bpy.context.view_layer.update()
    blended = evaluated(mesh_obj)
    expected = pmvc.deform(points, cage, posed, weights=weights, bulging=3.0, local_blend=0.5)
    assert relative_error(blended, expected, diagonal) < 1e-6
    assert np.abs(blended - bulged).max() > 1e-3 * diagonal
    # A baked shape key keeps both.
    assert bpy.ops.pmvc.bake_shape_key(name="bulged") == {"FINISHED"}
    baked = coordinates(mesh_obj.data.shape_keys.key_blocks["bulged"])
    assert relative_error(baked, expected, diagonal) < 1e-6
    mesh_obj.pmvc_bulging = 0.0
    mesh_obj.pmvc_local_blend = 0.0
    bpy.context.view_layer.update()
    assert relative_error(evaluated(mesh_obj), plain, diagonal) < 1e-6
    # Families that read no deformation setting do not offer it.
    bpy.ops.pmvc.unbind()
    assert bpy.ops.pmvc.bind(method="MVC") == {"FINISHED"}
    assert ("prop", "pmvc_bulging") not in draw()
    assert ("prop", "pmvc_local_blend") not in draw()
