"""The figures docs/coordinates.md gives for the shared models
(../shared/data/qmvc), printed as the docs quote them:

    python tests/python/doc_figures.py

Each line printed is a sentence the docs hold word for word (line breaks aside);
tests/python/test_doc_figures.py runs this whenever the shared data is there and
fails until the docs follow a change that moves a figure. docs/python.md's
figures for Beast are tests/python/study.py's table, checked the same way.
Prints "not run" when the shared data is missing.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import pmvc

ROOT = Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared" / "data" / "qmvc"
MODELS = ["Beast", "Bench", "FireHydrant", "ManHead", "Ogre", "SpikyBox", "WireSphere"]


def load(name: str):
    points, _ = pmvc.load_mesh(SHARED / f"{name}.obj")
    return points, pmvc.Cage.load(SHARED / f"{name}_Cage.obj")


def share(count: int, total: int) -> str:
    return f"{count:,} of {total:,} vertices ({100 * count / total:.2f}%)"


def outside_sentence(name: str) -> str:
    """How many vertices lie outside the model's cage, its quads as bilinear
    patches and split along their shorter diagonal (as --triangulate shorter
    and Green coordinates bind them)."""
    points, cage = load(name)
    patches = int((pmvc.classify(points, cage) == pmvc.OUTSIDE).sum())
    split = int((pmvc.classify(points, cage, triangulate="shorter") == pmvc.OUTSIDE).sum())
    if len(cage.quads) == 0:
        return f"{name}: {share(patches, len(points))} lie outside its cage of triangles."
    if patches == split == 0:
        return (
            f"{name}: all {len(points):,} vertices lie inside its cage, its {len(cage.quads)} quads "
            "bilinear patches or split along the shorter diagonal."
        )
    return (
        f"{name}: {share(patches, len(points))} lie outside its cage, whose {len(cage.quads)} quads are "
        f"bilinear patches; {share(split, len(points))} when they are split along the shorter diagonal."
    )


def between_sentence(name: str) -> str:
    """The vertices between a bent patch and its two triangles, where the
    patches and the shorter split class them differently."""
    points, cage = load(name)
    patches = pmvc.classify(points, cage)
    split = pmvc.classify(points, cage, triangulate="shorter")
    inside_patch = int(((patches == pmvc.INSIDE) & (split == pmvc.OUTSIDE)).sum())
    inside_split = int(((patches == pmvc.OUTSIDE) & (split == pmvc.INSIDE)).sum())
    return (
        f"On the {name}, {inside_patch + inside_split} of the {len(points):,} vertices lie between a "
        f"patch and its triangles: {inside_patch} inside the patches but outside the shorter split's "
        f"triangles, {inside_split} the other way round ({int((split == pmvc.OUTSIDE).sum())} outside "
        f"by the triangles, {int((patches == pmvc.OUTSIDE).sum())} by the patches)."
    )


def main() -> int:
    missing = [name for name in MODELS if not (SHARED / f"{name}_Cage.obj").exists()]
    if missing:
        print(f"doc figures: not run ({SHARED} lacks {', '.join(missing)})")
        return 0
    for name in MODELS:
        print(outside_sentence(name))
    print(between_sentence("Ogre"))
    return 0


if __name__ == "__main__":
    np.seterr(all="raise")
    sys.exit(main())
