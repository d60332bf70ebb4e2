"""The exceptions pmvc raises. Every one is a :class:`PmvcError`; the message
names the file (and its 1-based line), the element and what is wrong."""

from __future__ import annotations

from typing import Optional

__all__ = [
    "PmvcWarning",
    "BackendWarning",
    "PmvcError",
    "InputError",
    "ParameterError",
    "FileError",
    "CageError",
    "WeightsError",
    "BackendError",
    "BindError",
    "TooLargeError",
]


class PmvcError(Exception):
    """Base class of every pmvc error.

    ``path`` is the file concerned (or None), ``line`` its 1-based line when the
    problem is on one line (or None).
    """

    def __init__(self, message: str, path: Optional[str] = None, line: Optional[int] = None):
        super().__init__(message)
        self.path = path
        self.line = line

    def __reduce__(self):
        # Pickled whole (a Dask worker's error reaches the client so), not
        # only the message that BaseException keeps in ``args``.
        return (type(self), (str(self), self.path, self.line))


class InputError(PmvcError, ValueError):
    """Arrays or arguments that cannot be used: a shape that is not (n, 3), a
    dtype that is not real numbers, NaN or infinity, an index out of range."""


class ParameterError(PmvcError, ValueError):
    """An unknown family or backend, or a parameter outside its family's range."""


class FileError(PmvcError, OSError):
    """A file that cannot be read or written, or that does not parse."""


class CageError(PmvcError, ValueError):
    """Vertices and faces that are not a valid cage (open, non-manifold,
    inconsistently oriented, degenerate, self-intersecting...)."""


class WeightsError(PmvcError, ValueError):
    """Weights that do not fit the points or cage they are used with, or a
    weights file whose arrays or metadata disagree."""


class BackendError(PmvcError):
    """``backend="gpu"`` where no GPU adapter can be opened."""


class BindError(PmvcError):
    """A bind or a cage generation that failed (the reason is in the message)."""


class TooLargeError(PmvcError, MemoryError):
    """Work refused before it started because it would not fit in memory or
    on the disk; the message gives the sizes."""


class PmvcWarning(UserWarning):
    """Base class of the warnings pmvc issues (through :mod:`warnings`)."""


class BackendWarning(PmvcWarning):
    """Work asked for on the GPU ran on the CPU (a family without a GPU kernel,
    such as harmonic coordinates, or QMVC: MVC on a cage's quads), or the GPU
    reported something worth knowing (a pipeline cache it ignored)."""
