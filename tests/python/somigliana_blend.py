"""The figures docs/coordinates.md quotes for Somigliana coordinates' local
blend: the bundled comb bound once, its middle finger's tip turned by 30° and
60° about the finger's base (past 81° the finger's sides fold over), deformed at blends 0, 0.5 and 1; the tip's width
(across the turned finger) and depth (z) against their rest values.

    python tests/python/somigliana_blend.py [--pose-out bend60.obj]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import pmvc
from study import middle_finger_tip

ROOT = Path(__file__).resolve().parents[2]


def turned_tip(cage: pmvc.Cage, degrees: float):
    """The cage with the top face of its middle finger turned by `degrees`
    about the finger's base centre (in the xy plane), that rotation, and the
    finger's x range."""
    vertices = cage.vertices.copy()
    tip, (left, right) = middle_finger_tip(cage)
    top = vertices[:, 1].max()
    prong = (vertices[:, 0] > left - 1e-9) & (vertices[:, 0] < right + 1e-9)
    base = vertices[prong & (vertices[:, 1] < top - 1e-9), 1].max()
    pivot = np.array([(left + right) / 2, base, 0.0])
    angle = np.radians(degrees)
    turn = np.array(
        [[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0], [0, 0, 1]]
    )
    vertices[tip] = (vertices[tip] - pivot) @ turn.T + pivot
    return vertices, turn, (left, right)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pose-out", type=Path, help="write the 60° pose as an OBJ cage")
    args = parser.parse_args()
    mesh = pmvc.load_mesh(ROOT / "assets" / "comb_mesh.obj")
    cage = pmvc.Cage.load(ROOT / "assets" / "comb_cage.obj")
    points = np.asarray(mesh[0], dtype=np.float64)
    weights = pmvc.bind(points, cage, method="somigliana")
    # The middle finger's tip: mesh vertices within the finger, in its top 0.6.
    _, _, (left, right) = turned_tip(cage, 0.0)
    top = points[:, 1].max()
    tip = (points[:, 0] > left) & (points[:, 0] < right) & (points[:, 1] > top - 0.6)
    rest_width, rest_depth = np.ptp(points[tip, 0]), np.ptp(points[tip, 2])
    print(f"tip: {tip.sum()} vertices, {rest_width:.3f} wide and {rest_depth:.3f} deep at rest")
    print("| turn | blend | tip width | tip depth | largest move against blend 0 |")
    print("|---|---|---:|---:|---:|")
    for degrees in (30.0, 60.0):
        pose, turn, _ = turned_tip(cage, degrees)
        across = turn @ np.array([1.0, 0.0, 0.0])
        plain = pmvc.deform(points, cage, pose, weights=weights)
        for blend in (0.0, 0.5, 1.0):
            moved = pmvc.deform(points, cage, pose, weights=weights, local_blend=blend)
            change = np.linalg.norm(moved - plain, axis=1).max() / cage.diagonal
            print(
                f"| {degrees:.0f}° | {blend} | {np.ptp(moved[tip] @ across):.3f} "
                f"| {np.ptp(moved[tip, 2]):.3f} | {change:.2e} |"
            )
        if args.pose_out and degrees == 60.0:
            text = (ROOT / "assets" / "comb_cage.obj").read_text()
            faces = [line for line in text.splitlines() if line.startswith("f ")]
            lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in pose] + faces
            args.pose_out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
