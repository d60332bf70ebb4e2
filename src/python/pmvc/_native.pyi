"""Type stubs of the compiled module; import everything from ``pmvc``."""

from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
"""Any array-like of real numbers: a numpy array, a list of lists..."""
Path = Union[str, "PathLike[str]"]
Progress = Callable[[int, int], Any]
"""Called with ``(done, total)``; raising an exception cancels the work."""
Faces = Union[npt.NDArray[np.integer[Any]], Sequence[Sequence[int]]]
"""Faces of 0-based vertex indices: an integer array (m, k), k >= 3 (libigl's
``F``), or a sequence of polygons of any sizes (quads stay quads)."""
CageLike = Union["Cage", Tuple[ArrayLike, Faces], List[Any]]
"""A :class:`Cage`, or libigl's ``(V, F)`` pair, validated as ``Cage(V, F)``."""

__version__: str

class Cage:
    """A validated cage: closed, edge-manifold, consistently oriented, no
    degenerate triangles, not crossing itself (the command line's checks).

    ``vertices`` is an (m, 3) array-like; ``faces`` an integer array (m, k) or a
    sequence of polygons of 0-based vertex indices (quads stay quads; they are
    cut along their shorter diagonal, larger polygons fanned from their first
    corner). An inward-facing
    cage is flipped (see ``flipped``). Raises InputError or CageError.
    Pickles and copies exactly (re-validated when loaded).
    """

    def __init__(self, vertices: ArrayLike, faces: Faces) -> None: ...
    @staticmethod
    def load(path: Path, object: Optional[str] = None) -> "Cage":
        """Read and validate an OBJ, OFF or glTF file (object ``object`` of a
        file with several, as :func:`load_mesh`). Raises FileError (naming the
        file and line) or CageError."""
        ...
    @property
    def vertices(self) -> npt.NDArray[np.float64]:
        """Positions, float64 (m, 3), in file order (the weights' columns)."""
        ...
    @property
    def faces(self) -> List[List[int]]:
        """The polygons as given, reversed if the cage was flipped."""
        ...
    @property
    def triangles(self) -> npt.NDArray[np.int64]:
        """Outward triangles, int64 (t, 3): what Green's ψ columns refer to."""
        ...
    @property
    def quads(self) -> npt.NDArray[np.int64]:
        """The quads as bilinear patches, int64 (q, 4), corners q0..q3, outward."""
        ...
    @property
    def triangle_faces(self) -> npt.NDArray[np.int64]:
        """For each triangle, the face (0-based) it was cut from."""
        ...
    @property
    def flipped(self) -> bool:
        """Whether the faces pointed inward and were reversed."""
        ...
    @property
    def volume(self) -> float:
        """Enclosed volume."""
        ...
    @property
    def diagonal(self) -> float:
        """Length of the bounding-box diagonal."""
        ...
    @property
    def notices(self) -> List[str]:
        """What validation noticed without refusing the cage."""
        ...
    @property
    def path(self) -> Optional[str]:
        """The file it was read from, or None."""
        ...
    @property
    def object(self) -> Optional[str]:
        """The object of that file read as the cage (``Cage.load(path,
        object="Cage")``), or None; ``bind`` records it in the weights'
        metadata."""
        ...

class Weights:
    """The weights of a bind, and what a reader needs to trust them. Pickles
    and copies exactly (the arrays as they are, the metadata checked when
    loaded)."""

    @property
    def matrix(self) -> Union[npt.NDArray[np.float32], npt.NDArray[np.float64]]:
        """float32 (points, columns), bit-for-bit what ``pmvc bind`` writes;
        float64 where ``dtype=numpy.float64`` was asked for (as ``pmvc bind
        --dtype f64``; ``metadata["dtype"]`` says which)."""
        ...
    @property
    def classes(self) -> npt.NDArray[np.int8]:
        """Per row: 0 inside the cage, 1 on it, 2 outside (the family's
        outside policy applies)."""
        ...
    @property
    def method(self) -> str:
        """The family's id: "mvc", "pmvc", "harmonic" or "green"."""
        ...
    @property
    def parameters(self) -> Dict[str, Union[int, float, str]]:
        """The family's own parameters, e.g. ``{"resolution": 32}``,
        ``{"resolution": "exact"}`` or ``{"poisson_ratio": 0.3}``."""
        ...
    @property
    def backend(self) -> str:
        """Where the weights were computed: "cpu" or "gpu"."""
        ...
    @property
    def device(self) -> str:
        """"CPU" or the GPU adapter's name."""
        ...
    @property
    def seconds(self) -> float:
        """How long the bind took."""
        ...
    @property
    def columns(self) -> List[Tuple[str, int]]:
        """What each column is: ``("vertex", j)`` per cage vertex (φ for
        Green), then for Green ``("triangle", k)`` per ``triangles[k]`` (ψ) and
        on quads ``("quad_corner", 4 q + c)``; for Somigliana coordinates
        ``("vertex_block", 9 j + 3 a + b)`` then ``("triangle_block", 9 k + 3 a
        + b)``, entry (a, b) of a 3×3 block."""
        ...
    @property
    def columns_layout(self) -> str:
        """"cage_vertices", "cage_vertices_then_triangles" (Green) or
        "blocks_per_vertex_then_triangle" (Somigliana)."""
        ...
    @property
    def triangles(self) -> Optional[npt.NDArray[np.int64]]:
        """For Green and Somigliana coordinates, the triangles the triangle
        columns refer to (int64 (t, 3), corners in the order used); None
        otherwise."""
        ...
    @property
    def metadata(self) -> Dict[str, Any]:
        """Everything W.json holds (family, parameters, backend, time, column
        layout, class counts, digests of the points and cage)."""
        ...

def load_mesh(
    path: Path,
    object: Optional[str] = None,
) -> Tuple[npt.NDArray[np.float64], Union[npt.NDArray[np.int64], List[List[int]]]]:
    """Read an OBJ, OFF or glTF file, or a .npy point set: ``(vertices,
    faces)``, vertices float64 (n, 3) in file order; faces an int64 array (m, 3)
    of 0-based indices when every face is a triangle ((0, 3) for a point set),
    else a list of polygons (lists of indices). ``object`` names one object of
    a file with several (an OBJ's ``o`` name, a glTF node's or mesh's name);
    without it a PmvcWarning names them where there are several."""
    ...

def bind(
    points: ArrayLike,
    cage: CageLike,
    method: str = "pmvc",
    resolution: Union[int, str] = 32,
    grid: int | None = None,
    poisson_ratio: float = 0.0,
    backend: str = "auto",
    progress: Optional[Progress] = None,
    triangulate: Optional[str] = None,
    pmvc_kernel: str = "auto",
    strict: bool = False,
    dtype: npt.DTypeLike = "float32",
) -> Weights:
    """Bind ``points`` (n, 3) to ``cage`` with one family (see ``families()``).

    ``resolution`` is PMVC's cube-map resolution (or ``"exact"``), ``grid`` the
    grid of harmonic coordinates, BBW and LBC (``None``: the family's default,
    64, 32 and 32), ``poisson_ratio`` Somigliana coordinates' Poisson ratio
    (-0.999 to 0.499); each is read only by its family and checked against its
    range. Quads are bilinear patches (MVC on them is QMVC) unless
    ``triangulate`` is "shorter" or "longer", which splits them along that
    diagonal first; Green coordinates always bind on triangles. ``backend``: "auto" (the CPU, or a hardware GPU where it is
    predicted faster for this bind), "cpu" or "gpu". ``pmvc_kernel``: PMVC's GPU
    kernel, "auto", "tiles" or "bands" (as ``pmvc bind --pmvc-kernel``; "bands"
    reproduces GPU weights bound before the tile kernel). ``strict=True``
    raises InputError before binding when points lie outside the cage.
    ``dtype=numpy.float64`` keeps every row as computed, without rounding it to
    float32 (bound on the CPU; not for harmonic coordinates). ``cage``
    is a Cage or a ``(V, F)`` pair. The GIL is released; Ctrl-C cancels within
    about a second."""
    ...

def deform(
    points: ArrayLike,
    cage: CageLike,
    deformed_vertices: ArrayLike,
    weights: Optional[Weights] = None,
    method: str = "pmvc",
    **parameters: Any,
) -> npt.NDArray[np.float64]:
    """The points moved by the cage's move to ``deformed_vertices``, float64
    (n, 3), as ``pmvc deform`` computes them. Without ``weights``, ``method`` is
    bound first with ``parameters`` (resolution, grid, poisson_ratio, backend,
    progress, triangulate, pmvc_kernel, strict, dtype); with ``weights``,
    ``strict=True`` refuses weights with rows outside the cage. ``bulging``
    (Somigliana coordinates' γ, 0 to 10, default 0) and ``local_blend`` (their
    local/global blend, 0 to 1, default 0) are read when deforming, so they may
    be given with ``weights``."""
    ...

def classify(
    points: ArrayLike,
    cage: CageLike,
    method: Optional[str] = None,
    triangulate: Optional[str] = None,
) -> npt.NDArray[np.int8]:
    """Per point: 0 inside the cage, 1 on it, 2 outside, as ``bind`` with the
    same ``method`` and ``triangulate`` classes its rows: against the cage it
    binds (quads split along a diagonal with ``triangulate``, and for Green
    coordinates, which bind on triangles)."""
    ...

def generate_cage(
    vertices: ArrayLike,
    faces: Faces,
    target: int,
    clearance: Optional[float] = None,
    cell_size: Optional[float] = None,
    progress: Optional[Progress] = None,
    quads: bool = False,
) -> Tuple[Cage, Dict[str, Any]]:
    """A cage of about ``target`` vertices around a triangle mesh, and a dict
    of what ``pmvc cage`` prints; ``quads=True`` pairs triangles into quads
    where they fit."""
    ...

def families() -> List[Dict[str, Any]]:
    """Every family: id, name, summary, parameters, deform_parameters (read
    by deform, not bind: Somigliana's bulging and local_blend), positive_inside,
    outside_policy, columns_layout, gpu_kernel, gpu_kernel_quads."""
    ...

def save_weights(path: Path, weights: Weights) -> None:
    """Write ``weights`` as ``pmvc bind`` does: the matrix (.npy, or .npz with
    phi and psi for Green), the classes (W.classes.npy) and the metadata
    (W.json), all or nothing."""
    ...

def load_weights(path: Path) -> Weights:
    """Read a .npy/.npz written by ``pmvc bind`` or :func:`save_weights`, with
    its metadata and classes when they are beside it."""
    ...
