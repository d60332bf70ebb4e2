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

    from . import binding, deform, operators, store, ui

    if _registered:
        return
    settings = ui.settings_class()
    classes = [settings, *operators.classes(), ui.PMVC_PT_object, ui.PMVC_PT_sidebar]
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.WindowManager.pmvc = bpy.props.PointerProperty(type=settings)
    # Deformation settings (Somigliana's bulging) belong to the bound object:
    # undoable and animatable as any property; the handlers redeform when one
    # changes.
    for pid, spec in binding.deform_parameter_specs().items():
        setattr(bpy.types.Object, store.deform_property_name(pid), operators.deform_property(spec))
    deform.add_handlers()
    _registered.extend(classes)


def unregister():
    import bpy

    from . import binding, deform, store

    if not _registered:
        return
    deform.remove_handlers()
    del bpy.types.WindowManager.pmvc
    for pid in binding.deform_parameter_specs():
        name = store.deform_property_name(pid)
        if hasattr(bpy.types.Object, name):
            delattr(bpy.types.Object, name)
    for cls in reversed(_registered):
        bpy.utils.unregister_class(cls)
    _registered.clear()
    store.forget()
