"""The pictures of docs/blender.md, rendered by Blender (Workbench, in
background mode) with the add-on, on the bundled comb:

    target/blender-venv/bin/python docs/blender-images.py docs/images

blender-posed-ogre.png: the shared Ogre (../shared/data/qmvc, GPL-3; skipped
where it is missing) bound with PMVC, its artist cage at its target pose, and
the Ogre at rest beside it.
blender-posed-comb.png: the comb bound with PMVC, its cage (wireframe) with the
middle finger's tip pulled up, as the evaluated mesh shows it.
blender-coordinate-pmvc.png, blender-coordinate-mvc.png: the coordinate of one
cage vertex (the one whose MVC coordinate is the most negative) as `pmvc.show_coordinate` gives
it, coloured as Weight Paint colours it (blue 0, red 1), with the vertices where
MVC's weight is negative in magenta (Weight Paint shows them as 0)."""

import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp())
import bpy  # noqa: E402
import numpy as np  # noqa: E402

import pmvc  # noqa: E402
import pmvc.blender  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def link(name, vertices, faces):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(vertices).tolist(), [], [list(map(int, f)) for f in faces])
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def scene(method):
    bpy.ops.wm.read_homefile(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = "BLENDER_WORKBENCH"
    sc.render.resolution_x, sc.render.resolution_y = 400, 400
    sc.render.image_settings.color_mode = "RGB"
    sc.display.shading.light = "STUDIO"
    sc.world = bpy.data.worlds.new("w")
    sc.world.color = (1, 1, 1)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 8.2
    camera.location = (3.3, 3.3, 30.0)
    sc.collection.objects.link(camera)
    sc.camera = camera
    points, faces = pmvc.load_mesh(str(ROOT / "assets" / "comb_mesh.obj"))
    cage_vertices, cage_faces = pmvc.load_mesh(str(ROOT / "assets" / "comb_cage.obj"))
    mesh_obj, cage_obj = link("comb", points, faces), link("comb cage", cage_vertices, cage_faces)
    for obj in sc.objects:
        obj.select_set(obj in (mesh_obj, cage_obj))
    bpy.context.view_layer.objects.active = mesh_obj
    bpy.ops.pmvc.bind(method=method)
    return mesh_obj, cage_obj, middle_tip(cage_vertices)


def middle_tip(vertices):
    """The cage vertices at the top of the middle finger (tests/python/study.py's pose)."""
    top = vertices[:, 1].max()
    tips = np.flatnonzero(vertices[:, 1] > top - 1e-9)
    fingers = np.unique(np.round(vertices[tips, 0], 9)).reshape(-1, 2)
    left, right = fingers[len(fingers) // 2]
    return tips[(vertices[tips, 0] > left - 1e-9) & (vertices[tips, 0] < right + 1e-9)], right - left


def show_wire(cage_obj, thickness):
    """The cage as thin bars in the render: a twin sharing its mesh, with a
    Wireframe modifier (on the cage itself it would change the vertices the
    binding reads); the cage is kept out of the render."""
    twin = bpy.data.objects.new("cage wire", cage_obj.data)
    bpy.context.scene.collection.objects.link(twin)
    twin.modifiers.new("wire", "WIREFRAME").thickness = thickness
    cage_obj.hide_render = True
    return twin


def render(path):
    bpy.context.scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)


def posed(out):
    mesh_obj, cage_obj, (tip, width) = scene("PMVC")
    for index in tip:
        cage_obj.data.vertices[int(index)].co.y += 1.5 * width
    cage_obj.data.update()
    show_wire(cage_obj, 0.04).color = (0.1, 0.1, 0.1, 1)
    mesh_obj.color = (0.85, 0.7, 0.45, 1)
    bpy.context.scene.display.shading.color_type = "OBJECT"
    bpy.context.view_layer.update()
    render(out / "blender-posed-comb.png")


def weight_colour(w):
    """Weight Paint's ramp: blue 0, cyan, green 0.5, yellow, red 1."""
    stops = np.array([[0, 0, 1], [0, 1, 1], [0, 1, 0], [1, 1, 0], [1, 0, 0]], dtype=np.float64)
    x = np.clip(w, 0, 1) * 4
    i = np.minimum(x.astype(int), 3)
    t = (x - i)[:, None]
    return stops[i] * (1 - t) + stops[i + 1] * t


def coordinate(out, method, vertex):
    mesh_obj, cage_obj, _ = scene(method)
    bpy.ops.pmvc.show_coordinate(cage_vertex=vertex)
    group = mesh_obj.vertex_groups.active
    weights = pmvc.blender.store.load(mesh_obj).weights.matrix[:, vertex].astype(np.float64)
    colours = weight_colour(weights)
    colours[weights < 0] = (1.0, 0.0, 1.0)
    attribute = mesh_obj.data.color_attributes.new("weights", "FLOAT_COLOR", "POINT")
    attribute.data.foreach_set("color", np.hstack([colours, np.ones((len(colours), 1))]).astype(np.float32).ravel())
    mesh_obj.data.color_attributes.active_color = attribute
    sc = bpy.context.scene
    sc.display.shading.color_type = "VERTEX"
    sc.display.shading.light = "FLAT"
    show_wire(cage_obj, 0.03)
    print(f"{method}: cage vertex {vertex} ({group.name}), weights from {weights.min():.4f} to {weights.max():.4f}, "
          f"{int((weights < 0).sum())} vertices below 0")
    render(out / f"blender-coordinate-{method.lower()}.png")


def ogre(out):
    """The shared Ogre (../shared/data/qmvc, GPL-3) bound with PMVC to its artist
    cage, at the cage's target pose, beside it at rest."""
    shared = ROOT.parent / "shared" / "data" / "qmvc"
    files = [shared / f"Ogre{suffix}.obj" for suffix in ("", "_Cage", "_Cage_Deformed")]
    if not all(f.exists() for f in files):
        print(f"Ogre: not rendered ({shared} missing)")
        return
    points, faces = pmvc.load_mesh(str(files[0]))
    rest, cage_faces = pmvc.load_mesh(str(files[1]))
    target, _ = pmvc.load_mesh(str(files[2]))
    bpy.ops.wm.read_homefile(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = "BLENDER_WORKBENCH"
    sc.render.resolution_x, sc.render.resolution_y = 640, 400
    sc.render.image_settings.color_mode = "RGB"
    sc.display.shading.light = "STUDIO"
    sc.display.shading.color_type = "OBJECT"
    sc.world = bpy.data.worlds.new("w")
    sc.world.color = (1, 1, 1)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 92.0
    camera.location = (22.0, 17.5, 100.0)
    sc.collection.objects.link(camera)
    sc.camera = camera
    posed_obj, cage_obj = link("Ogre", points, faces), link("Ogre cage", rest, cage_faces)
    for obj in sc.objects:
        obj.select_set(obj in (posed_obj, cage_obj))
    bpy.context.view_layer.objects.active = posed_obj
    bpy.ops.pmvc.bind(method="PMVC")
    cage_obj.data.vertices.foreach_set("co", np.asarray(target, np.float32).ravel())
    cage_obj.data.update()
    show_wire(cage_obj, 0.12).color = (0.1, 0.1, 0.1, 1)
    at_rest = link("Ogre at rest", points, faces)
    at_rest.location.x = 44.0
    for obj, colour in ((posed_obj, (0.55, 0.7, 0.45, 1)), (at_rest, (0.7, 0.7, 0.7, 1))):
        obj.color = colour
    bpy.context.view_layer.update()
    render(out / "blender-posed-ogre.png")


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "docs/images")
    pmvc.blender.register()
    posed(out)
    ogre(out)
    # The cage vertex whose MVC coordinate is the most negative somewhere.
    points, _ = pmvc.load_mesh(str(ROOT / "assets" / "comb_mesh.obj"))
    mvc = pmvc.bind(points, pmvc.Cage.load(str(ROOT / "assets" / "comb_cage.obj")), method="mvc").matrix
    vertex = int(np.unravel_index(np.argmin(mvc), mvc.shape)[1])
    coordinate(out, "PMVC", vertex)
    coordinate(out, "MVC", vertex)
    sys.stdout.flush()
    os._exit(0)  # skip bpy's slow teardown


if __name__ == "__main__":
    main()
