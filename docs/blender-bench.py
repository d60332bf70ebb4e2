"""Blender figures of docs/blender.md on a shared model (../shared/data/qmvc,
GPL-3, not in this repository): pmvc's bind and update time in Blender beside
Blender's Mesh Deform modifier (bind time, and its difference from pmvc's
deformation at the model's target pose, in % of the cage diagonal).

    target/blender-venv/bin/python docs/blender-bench.py Ogre --precision 4 5

An update is one cage move and `view_layer.update()`: the handler's product
of the weights, the attribute written, and the mesh evaluated again."""

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp())
import bpy  # noqa: E402
import numpy as np  # noqa: E402

import pmvc  # noqa: E402
import pmvc.blender  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "data" / "qmvc"


def link(name, vertices, faces):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(vertices).tolist(), [], [list(map(int, f)) for f in faces])
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def evaluated(obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated_obj = obj.evaluated_get(depsgraph)
    mesh = evaluated_obj.to_mesh()
    out = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", out)
    evaluated_obj.to_mesh_clear()
    return out.reshape(-1, 3).astype(np.float64)


def set_cage(cage_obj, vertices):
    cage_obj.data.vertices.foreach_set("co", np.asarray(vertices, np.float32).ravel())
    cage_obj.data.update()


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("model", nargs="?", default="Ogre")
    parser.add_argument("--method", default="pmvc")
    parser.add_argument("--precision", type=int, nargs="*", default=[4, 5])
    parser.add_argument("--updates", type=int, default=40)
    args = parser.parse_args()
    files = [SHARED / f"{args.model}{suffix}.obj" for suffix in ("", "_Cage", "_Cage_Deformed")]
    if not all(f.exists() for f in files):
        print(f"{args.model}: not run ({SHARED} missing)")
        return
    points, faces = pmvc.load_mesh(str(files[0]))
    rest, cage_faces = pmvc.load_mesh(str(files[1]))
    target, _ = pmvc.load_mesh(str(files[2]))
    pmvc.blender.register()
    bpy.ops.wm.read_homefile(use_empty=True)
    mesh_obj, cage_obj = link(args.model, points, faces), link("cage", rest, cage_faces)
    rest32 = np.empty(len(rest) * 3, np.float32)
    cage_obj.data.vertices.foreach_get("co", rest32)
    rest32 = rest32.reshape(-1, 3).astype(np.float64)
    diagonal = float(np.linalg.norm(rest32.max(0) - rest32.min(0)))
    for obj in (mesh_obj, cage_obj):
        obj.select_set(True)
    bpy.context.view_layer.objects.active = mesh_obj
    started = time.perf_counter()
    bpy.ops.pmvc.bind(method=args.method.upper())
    bind_seconds = time.perf_counter() - started
    # Updates: the cage moving from rest to its target pose.
    times = []
    for step in range(1, args.updates + 1):
        set_cage(cage_obj, rest32 + (target - rest32) * step / args.updates)
        started = time.perf_counter()
        bpy.context.view_layer.update()
        times.append(time.perf_counter() - started)
    pmvc_posed = evaluated(mesh_obj)
    binding = pmvc.blender.store.load(mesh_obj)
    reference = pmvc.deform(binding.points, binding.cage, target, weights=binding.weights)
    agreement = np.abs(pmvc_posed - reference).max() / diagonal
    # A drag: one cage vertex moving, the others at rest.
    set_cage(cage_obj, rest32)
    bpy.context.view_layer.update()
    drags = []
    for step in range(1, args.updates + 1):
        cage_obj.data.vertices[0].co.z += 0.001 * diagonal
        cage_obj.data.update()
        started = time.perf_counter()
        bpy.context.view_layer.update()
        drags.append(time.perf_counter() - started)
    set_cage(cage_obj, target)
    bpy.context.view_layer.update()
    binding = pmvc.blender.store.load(mesh_obj)
    posed = pmvc.blender.deform.posed_cage(mesh_obj, cage_obj, bpy.context.evaluated_depsgraph_get())
    started = time.perf_counter()
    for _ in range(10):
        binding.offsets(posed)
    product = (time.perf_counter() - started) / 10
    set_cage(cage_obj, rest32)
    bpy.context.view_layer.update()
    started = time.perf_counter()
    bpy.context.view_layer.update()  # nothing moved: the handler only compares
    idle = time.perf_counter() - started
    print(f"{args.model}: {len(points)} vertices, cage of {len(rest)} vertices, {os.cpu_count()} cores")
    print(f"pmvc bind in Blender ({args.method}): {bind_seconds:.2f} s")
    print(f"pmvc update, one cage vertex dragged: median {1000 * np.median(drags):.1f} ms, max {1000 * max(drags):.1f} ms")
    print(f"pmvc update, every cage vertex moving: median {1000 * np.median(times):.1f} ms, "
          f"max {1000 * max(times):.1f} ms over {len(times)} updates; an update with nothing moved {1000 * idle:.1f} ms")
    print(f"evaluated mesh at the target pose against pmvc.deform: {agreement:.1e} of the cage diagonal")
    print(f"of which the product of the weights (numpy, float32): {1000 * product:.1f} ms")
    bpy.ops.pmvc.unbind()
    at_rest = evaluated(mesh_obj)
    for precision in args.precision:
        modifier = mesh_obj.modifiers.new("MeshDeform", "MESH_DEFORM")
        modifier.object = cage_obj
        modifier.precision = precision
        with bpy.context.temp_override(object=mesh_obj, active_object=mesh_obj):
            started = time.perf_counter()
            bpy.ops.object.meshdeform_bind(modifier=modifier.name)
            bpy.context.view_layer.update()  # Mesh Deform binds when it is next evaluated
            bind = time.perf_counter() - started
        set_cage(cage_obj, target)
        bpy.context.view_layer.update()
        moved = evaluated(mesh_obj)
        distance = np.linalg.norm(moved - pmvc_posed, axis=1) / diagonal * 100
        still = int(np.sum(np.all(moved == at_rest, axis=1)))
        print(f"Mesh Deform precision {precision}: bind {bind:.1f} s; distance to pmvc ({args.method}) at the target pose: "
              f"max {distance.max():.2f}%, mean {distance.mean():.3f}% of the cage diagonal; {still} vertices did not move")
        set_cage(cage_obj, rest32)
        mesh_obj.modifiers.remove(modifier)
        bpy.context.view_layer.update()
    sys.stdout.flush()
    os._exit(0)


if __name__ == "__main__":
    main()
