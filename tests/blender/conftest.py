"""Shared set-up of the Blender tests: bpy from the package index, the
extension installed from its .zip as Blender installs it (into a private user
folder), and scenes built from the bundled comb and a procedural quad cage."""

import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
USER = tempfile.mkdtemp(prefix="pmvc-blender-user-")
# Before bpy is imported: extensions and preferences go to a private folder.
os.environ["BLENDER_USER_RESOURCES"] = USER

import bpy  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import pmvc  # noqa: E402

FAMILIES = [f["id"] for f in pmvc.families()]
TOLERANCE = 1e-6  # of the cage diagonal


def extension_zip():
    path = os.environ.get("PMVC_BLENDER_ZIP") or str(ROOT / "target" / "blender" / f"pmvc-{pmvc.__version__}.zip")
    if not Path(path).is_file():
        pytest.fail(f"{path}: no extension .zip; build it with src/blender/build.py (tests/blender/run does)")
    return path


@pytest.fixture(scope="session", autouse=True)
def extension():
    """Install and enable the extension as Install from Disk does."""
    result = bpy.ops.extensions.package_install_files(
        filepath=extension_zip(), repo="user_default", enable_on_install=True)
    assert result == {"FINISHED"}
    return Path(bpy.utils.user_resource("EXTENSIONS"))


@pytest.fixture(autouse=True)
def empty_file():
    bpy.ops.wm.read_homefile(use_empty=True)
    yield


def link_mesh(name, vertices, faces):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(vertices, dtype=np.float64).tolist(), [], [list(map(int, f)) for f in faces])
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def comb():
    """(mesh object, cage object) of the bundled comb."""
    points, faces = pmvc.load_mesh(str(ROOT / "assets" / "comb_mesh.obj"))
    cage_vertices, cage_faces = pmvc.load_mesh(str(ROOT / "assets" / "comb_cage.obj"))
    return link_mesh("comb", points, faces), link_mesh("comb cage", cage_vertices, cage_faces)


def middle_tip(vertices):
    """The comb cage's vertices at the top of its middle finger, and the finger's
    width (tests/python/study.py's pose)."""
    top = vertices[:, 1].max()
    tips = np.flatnonzero(vertices[:, 1] > top - 1e-9)
    fingers = np.unique(np.round(vertices[tips, 0], 9)).reshape(-1, 2)
    left, right = fingers[len(fingers) // 2]
    return tips[(vertices[tips, 0] > left - 1e-9) & (vertices[tips, 0] < right + 1e-9)], right - left


def box(nx, ny, nz, size=(1.0, 1.0, 1.0), center=(0.0, 0.0, 0.0)):
    """A closed box of quads, nx by ny by nz cells, outward-facing."""
    import bmesh

    bm = bmesh.new()
    bmesh.ops.create_cube(bm, size=1.0)
    bmesh.ops.subdivide_edges(bm, edges=bm.edges[:], cuts=max(nx, ny, nz) - 1, use_grid_fill=True)
    vertices = np.array([v.co[:] for v in bm.verts]) * np.asarray(size) + np.asarray(center)
    faces = [[v.index for v in f.verts] for f in bm.faces]
    bm.free()
    return vertices, faces


def quad_scene():
    """(mesh, cage): an ellipsoid inside a box cage of 96 quads, 4 cells tall."""
    import bmesh

    cage_vertices, cage_faces = box(4, 4, 4, size=(1.0, 1.0, 3.0), center=(0, 0, 1.5))
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=16, v_segments=12, radius=0.5)
    points = np.array([v.co[:] for v in bm.verts]) * [0.7, 0.7, 2.6] + [0, 0, 1.5]
    faces = [[v.index for v in f.verts] for f in bm.faces]
    bm.free()
    return link_mesh("blob", points, faces), link_mesh("box cage", cage_vertices, cage_faces)


def select(mesh_obj, *others):
    for obj in bpy.context.scene.objects:
        obj.select_set(False)
    for obj in (mesh_obj, *others):
        obj.select_set(True)
    bpy.context.view_layer.objects.active = mesh_obj


def coordinates(mesh):
    """float64 (n, 3) of a mesh's vertices or a shape key's points."""
    items = mesh.data if isinstance(mesh, bpy.types.ShapeKey) else mesh.vertices
    out = np.empty(len(items) * 3, dtype=np.float32)
    items.foreach_get("co", out)
    return out.reshape(-1, 3).astype(np.float64)


def evaluated(obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated_obj = obj.evaluated_get(depsgraph)
    mesh = evaluated_obj.to_mesh()
    try:
        return coordinates(mesh)
    finally:
        evaluated_obj.to_mesh_clear()


def evaluated_cage(cage_obj):
    return evaluated(cage_obj)


def cage_faces(cage_obj):
    return [list(p.vertices) for p in cage_obj.data.polygons]


# LBC's bind takes over a minute at its default grid: the tests bind it coarser.
TEST_PARAMETERS = {"lbc": {"grid": 16}, "somigliana": {"poisson_ratio": -0.3}}


def parameters(method):
    family = next(f for f in pmvc.families() if f["id"] == method)
    values = {p["id"]: p["default"] for p in family["parameters"]}
    values.update(TEST_PARAMETERS.get(method, {}))
    return values


def expected(points, rest, faces, posed, method):
    """The package's deformation, bound here from the same points and cage."""
    cage = pmvc.Cage(rest, faces)
    return pmvc.deform(points, cage, posed, method=method, backend="cpu", **parameters(method)), cage.diagonal


def write_obj(path, vertices, faces):
    with open(path, "w") as out:
        for v in vertices:
            out.write("v " + " ".join(repr(float(x)) for x in v) + "\n")
        for f in faces:
            out.write("f " + " ".join(str(i + 1) for i in f) + "\n")


def cli_deform(tmp_path, points, rest, faces, posed, method):
    """`pmvc deform` (the command line, PMVC_BIN) of the same points and poses."""
    binary = os.environ.get("PMVC_BIN") or str(ROOT / "target" / "release" / "pmvc")
    if not Path(binary).is_file():
        pytest.fail(f"{binary}: no pmvc binary (set PMVC_BIN)")
    np.save(tmp_path / "points.npy", points)
    write_obj(tmp_path / "cage.obj", rest, faces)
    write_obj(tmp_path / "posed.obj", posed, faces)
    arguments = [binary, "deform", "--mesh", str(tmp_path / "points.npy"), "--cage", str(tmp_path / "cage.obj"),
                 "--deformed-cage", str(tmp_path / "posed.obj"), "--method", method, "--out", str(tmp_path / "out.npy")]
    for key, value in parameters(method).items():
        arguments += [f"--{key.replace('_', '-')}", str(value)]
    subprocess.run(arguments, check=True, capture_output=True)
    return np.load(tmp_path / "out.npy")


def relative_error(a, b, diagonal):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / diagonal)


def run_python(script, **env):
    """Run ``script`` in a new Python of this environment (a fresh Blender)."""
    environment = dict(os.environ, **env)
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=environment, timeout=300)
