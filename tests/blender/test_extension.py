"""The extension installs from its .zip as Blender's Install from Disk does."""

from pathlib import Path

import bpy

import pmvc
from conftest import FAMILIES


def test_the_extension_is_installed_enabled_and_brings_its_wheel(extension):
    assert "bl_ext.user_default.pmvc" in {a.module for a in bpy.context.preferences.addons}
    assert (extension / "user_default" / "pmvc" / "blender_manifest.toml").is_file()
    # Blender unpacked the bundled wheel into the extensions' site-packages.
    unpacked = list(Path(extension).glob(".local/lib/python*/site-packages/pmvc/blender/__init__.py"))
    assert unpacked, "the bundled pmvc-cage wheel was not installed"


def test_the_method_enum_lists_every_family_of_the_package():
    items = bpy.ops.pmvc.bind.get_rna_type().properties["method"].enum_items.keys()
    assert list(items) == [f.upper() for f in FAMILIES]
    assert {"MVC", "PMVC", "HARMONIC", "GREEN"} <= set(items)


def test_operators_are_registered_and_undoable():
    for name in ("bind", "unbind", "rebind", "bake_shape_key", "show_coordinate", "export_weights"):
        cls = getattr(bpy.types, getattr(bpy.ops.pmvc, name).idname())
        wanted = {"REGISTER"} if name == "export_weights" else {"REGISTER", "UNDO"}
        assert wanted <= set(cls.bl_options), name


def test_the_panels_are_registered():
    assert hasattr(bpy.types, "PMVC_PT_object") and hasattr(bpy.types, "PMVC_PT_sidebar")
    assert bpy.types.PMVC_PT_object.bl_context == "object"
    assert bpy.types.PMVC_PT_sidebar.bl_space_type == "VIEW_3D"
    assert pmvc.blender is not None


def test_blenders_own_validator_accepts_the_zip():
    """Blender's extension command line (`blender --command extension validate`)
    checks the manifest more strictly than installing does (a tagline of 78
    characters installed, and fails here)."""
    import subprocess
    import sys

    from conftest import extension_zip

    script = Path(bpy.utils.system_resource("SCRIPTS")) / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"
    assert script.is_file(), script
    result = subprocess.run([sys.executable, str(script), "validate", extension_zip()],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and "Success" in result.stdout, result.stdout + result.stderr
