"""pmvc inside Blender: bind a mesh to a cage with any of the package's
families and let the cage deform it, live, in renders and in animation.

In any Blender Python with the package installed::

    import pmvc.blender
    pmvc.blender.register()

adds the operators ``pmvc.bind``, ``unbind``, ``rebind``, ``bake_shape_key``,
``export_weights`` and ``show_coordinate`` and the pmvc panel. The extension
built by ``src/blender/build.py`` calls the same. See docs/blender.md.
"""

_registered = []


def register():
    import bpy

    from . import deform, operators, ui

    if _registered:
        return
    settings = ui.settings_class()
    classes = [settings, *operators.classes(), ui.PMVC_PT_object, ui.PMVC_PT_sidebar]
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.WindowManager.pmvc = bpy.props.PointerProperty(type=settings)
    deform.add_handlers()
    _registered.extend(classes)


def unregister():
    import bpy

    from . import deform, store

    if not _registered:
        return
    deform.remove_handlers()
    del bpy.types.WindowManager.pmvc
    for cls in reversed(_registered):
        bpy.utils.unregister_class(cls)
    _registered.clear()
    store.forget()
