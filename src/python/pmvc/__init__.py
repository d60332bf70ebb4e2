"""Cage-based mesh deformation: positive mean value coordinates (PMVC), mean
value coordinates (MVC), harmonic coordinates and Green coordinates, from numpy.

Bind the points of a mesh to a cage, then move the cage::

    import pmvc
    cage = pmvc.Cage.load("cage.obj")
    points, faces = pmvc.load_mesh("mesh.obj")
    weights = pmvc.bind(points, cage, method="pmvc", resolution=32)
    moved = pmvc.deform(points, cage, posed_cage_vertices, weights=weights)

Every function checks its input as the ``pmvc`` command line does and raises a
:class:`PmvcError` subclass naming what is wrong. See docs/python.md.
"""

from ._errors import (
    BackendError,
    BackendWarning,
    BindError,
    CageError,
    FileError,
    InputError,
    ParameterError,
    PmvcError,
    PmvcWarning,
    TooLargeError,
    WeightsError,
)
from ._native import (
    Cage,
    Weights,
    __version__,
    bind,
    classify,
    deform,
    families,
    generate_cage,
    load_mesh,
    load_weights,
    save_weights,
)

#: Class codes of ``Weights.classes`` and :func:`classify`.
INSIDE = 0
ON_CAGE = 1
OUTSIDE = 2

__all__ = [
    "Cage",
    "Weights",
    "bind",
    "classify",
    "deform",
    "families",
    "generate_cage",
    "load_mesh",
    "load_weights",
    "save_weights",
    "INSIDE",
    "ON_CAGE",
    "OUTSIDE",
    "PmvcError",
    "InputError",
    "ParameterError",
    "FileError",
    "CageError",
    "WeightsError",
    "BackendError",
    "BindError",
    "TooLargeError",
    "PmvcWarning",
    "BackendWarning",
    "__version__",
]
