# The pmvc extension for Blender: everything lives in the pmvc package
# (pmvc.blender), installed by Blender from the wheel this extension bundles.


def register():
    from pmvc import blender

    blender.register()


def unregister():
    from pmvc import blender

    blender.unregister()
