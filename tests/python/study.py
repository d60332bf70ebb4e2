"""The worked study of docs/python.md: MVC, PMVC, harmonic and Green
coordinates on one scene, deformed to one pose.

    python tests/python/study.py comb --figure study-comb.png
    python tests/python/study.py Beast --figure docs/images/python-study-beast.png

"comb" is the bundled comb (assets/) with its middle finger pulled up by 1.5
times the width of its cage; any other name is a model of ../shared/data/qmvc (NAME.obj,
NAME_Cage.obj and the target pose NAME_Cage_Deformed.obj), and the study
prints "not run" when that folder is missing. It prints a Markdown table of
numbers (tests/python/test_study.py checks that docs/python.md quotes the
comb's table as printed), the bind times, and saves one figure.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import pmvc

ROOT = Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared" / "data" / "qmvc"
# Each family's method and parameters; the first is the MVC of the figure, the
# third the reference every family is compared with (the finest PMVC).
FAMILIES = [
    ("mvc", {}),
    ("pmvc", {"resolution": 32}),
    ("pmvc", {"resolution": 64}),
    ("harmonic", {"grid": 64}),
    ("green", {}),
]
MVC, REFERENCE = 0, 2


def family_label(weights: pmvc.Weights) -> str:
    """What the weights are, as the command line names them: the metadata's
    family name on this cage (QMVC for MVC on a cage's bilinear quads) and the
    parameter, e.g. "PMVC 32²", "HC grid 64"."""
    name = weights.metadata["method_name"]
    parameters = weights.parameters
    if "resolution" in parameters:
        return f"{name} {parameters['resolution']}²"
    if "grid" in parameters:
        return f"{name} grid {parameters['grid']}"
    return name


def middle_finger_tip(cage: pmvc.Cage):
    """The comb cage's middle finger: the indices of the cage vertices at the
    top whose x lies in the middle one of the five fingers' x ranges, and that
    range."""
    vertices = cage.vertices
    top = vertices[:, 1].max()
    tips = np.flatnonzero(vertices[:, 1] > top - 1e-9)
    fingers = np.unique(np.round(vertices[tips, 0], 9)).reshape(-1, 2)
    left, right = fingers[len(fingers) // 2]
    chosen = tips[(vertices[tips, 0] > left - 1e-9) & (vertices[tips, 0] < right + 1e-9)]
    return chosen, (left, right)


def middle_finger_pose(cage: pmvc.Cage, lift: float = 1.5) -> np.ndarray:
    """The comb cage with the tip of its middle finger pulled up (+y) by `lift`
    times the width of that finger's cage (`middle_finger_tip`)."""
    vertices = cage.vertices.copy()
    chosen, (left, right) = middle_finger_tip(cage)
    vertices[chosen, 1] += lift * (right - left)
    return vertices


def load_scene(name: str):
    """(points, faces, cage, pose, description), or None when not available."""
    if name == "comb":
        points, faces = pmvc.load_mesh(ROOT / "assets" / "comb_mesh.obj")
        cage = pmvc.Cage.load(ROOT / "assets" / "comb_cage.obj")
        return points, faces, cage, middle_finger_pose(cage), "middle finger pulled up"
    files = [SHARED / f"{name}.obj", SHARED / f"{name}_Cage.obj", SHARED / f"{name}_Cage_Deformed.obj"]
    if not all(path.exists() for path in files):
        return None
    points, faces = pmvc.load_mesh(files[0])
    cage = pmvc.Cage.load(files[1])
    pose, _ = pmvc.load_mesh(files[2])
    return points, faces, cage, pose, f"{files[2].name}"


def study(name: str, figure: Path | None, backend: str) -> int:
    scene = load_scene(name)
    if scene is None:
        print(f"study {name}: not run ({SHARED} has no {name}.obj, {name}_Cage.obj, {name}_Cage_Deformed.obj)")
        return 0
    points, faces, cage, pose, pose_text = scene
    diagonal = cage.diagonal
    print(
        f"study {name}: {len(points)} points, a cage of {len(cage.vertices)} vertices "
        f"({len(cage.triangles)} triangles), pose: {pose_text}, backend {backend}"
    )
    results = {}
    for method, parameters in FAMILIES:
        weights = pmvc.bind(points, cage, method=method, backend=backend, **parameters)
        moved = pmvc.deform(points, cage, pose, weights=weights)
        results[family_label(weights)] = (weights, moved)
    labels = list(results)
    reference_label = labels[REFERENCE]
    classes = results[reference_label][0].classes
    inside = classes == pmvc.INSIDE
    reference = results[reference_label][1]
    vertices = len(cage.vertices)
    print()
    print(
        "| family | min weight, all rows | min weight inside | inside rows with a weight < 0 "
        f"| max distance to {reference_label} | mean distance to {reference_label} |"
    )
    print("|---|---|---|---|---|---|")
    for label, (weights, moved) in results.items():
        vertex_weights = weights.matrix[inside, :vertices]
        negative = (vertex_weights < 0).any(axis=1).mean() if inside.any() else 0.0
        distance = np.linalg.norm(moved - reference, axis=1) / diagonal
        print(
            f"| {label} | {weights.matrix[:, :vertices].min():.4f} "
            f"| {vertex_weights.min():.4f} | {100 * negative:.1f}% "
            f"| {100 * distance.max():.3f}% | {100 * distance.mean():.4f}% |"
        )
    print()
    print(
        f"rows: {inside.sum()} inside, {(classes == pmvc.ON_CAGE).sum()} on the cage, "
        f"{(classes == pmvc.OUTSIDE).sum()} outside; distances are per point, in % of the cage diagonal "
        f"{diagonal:.4g}"
    )
    print(
        "bind seconds: "
        + ", ".join(f"{label} {weights.seconds:.2f}" for label, (weights, _) in results.items())
        + f" ({results[reference_label][0].device})"
    )
    if figure is not None:
        save_figure(figure, name, points, results, diagonal, cage, pose)
        print(f"figure: {figure}")
    return 0


def save_figure(path: Path, name, points, results, diagonal, cage, pose) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = list(results)
    reference_label, mvc_label = labels[REFERENCE], labels[MVC]
    reference = results[reference_label][1]
    mvc = results[mvc_label][1]
    figure, (left, right) = plt.subplots(1, 2, figsize=(11, 4.6))
    # Left: the deformed points under MVC seen along z, coloured by their
    # distance to the PMVC 64² deformation.
    distance = 100 * np.linalg.norm(mvc - reference, axis=1) / diagonal
    order = np.argsort(distance)
    shown = left.scatter(mvc[order, 0], mvc[order, 1], c=distance[order], s=1.5, cmap="magma")
    edges = cage.triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    for a, b in edges:
        left.plot(pose[[a, b], 0], pose[[a, b], 1], color="0.6", linewidth=0.4)
    left.set_aspect("equal")
    left.set_title(f"{name}: {mvc_label} deformation, distance to {reference_label}")
    figure.colorbar(shown, ax=left, label="% of cage diagonal")
    # Right: for each family, the share of points farther than d from PMVC 64².
    for label, (_, moved) in results.items():
        if label == reference_label:
            continue
        d = np.sort(100 * np.linalg.norm(moved - reference, axis=1) / diagonal)
        share = 1.0 - np.arange(len(d)) / len(d)
        right.step(np.maximum(d, 1e-6), share, where="post", label=label)
    right.set_xscale("log")
    right.set_xlim(1e-4, None)
    right.set_xlabel(f"distance to {reference_label} (% of cage diagonal)")
    right.set_ylabel("share of points at least this far")
    right.set_title("per-point differences")
    right.legend()
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", help='"comb", or a model of ../shared/data/qmvc (e.g. Beast)')
    parser.add_argument("--figure", type=Path, help="save the figure here (PNG)")
    parser.add_argument("--backend", default="cpu", choices=["auto", "cpu", "gpu"])
    arguments = parser.parse_args(argv)
    return study(arguments.scene, arguments.figure, arguments.backend)


if __name__ == "__main__":
    sys.exit(main())
