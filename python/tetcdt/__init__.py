"""Constrained Delaunay tetrahedralizations of piecewise linear complexes.

numpy arrays in, a mesh out::

    import numpy as np, tetcdt
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    faces = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])
    mesh = tetcdt.tetrahedralize(points, faces, switches="pq1.414a0.01")
    print(mesh.points.shape, mesh.tets.shape, mesh.stats["max_radius_edge_ratio"])

The switches are the command line's (``tetcdt --help``), with or without the dash.
Every mesh returned has passed the library's certifier: with ``p`` it is a constrained
Delaunay tetrahedralization of the input, and without it the Delaunay
tetrahedralization of the points.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from typing import Any, Optional, Union

import numpy as np

from . import _tetcdt
from ._tetcdt import InvalidInputError, MeshingError

__all__ = [
    "tetrahedralize",
    "read",
    "Mesh",
    "PLC",
    "InvalidInputError",
    "MeshingError",
]

ArrayLike = Any
Faces = Union[ArrayLike, Sequence[Sequence[int]], Sequence[Sequence[Sequence[int]]]]


def _read_only(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


class Mesh:
    """A finished mesh: numpy arrays, numbered from 0, and the run's figures.

    Attributes:
        points: (n, 3) float64, the input points that the mesh uses, in input order,
            then the Steiner points.
        tets: (k, 4) int32, four point indices per tet, positively oriented.
        faces: (f, 3) int32, the faces on facets (the domain's boundary and interior
            facets), with ``face_markers`` (int32) the facets' markers.
        edges: (e, 2) int32, the edges on input segments and facet boundaries, with
            ``edge_markers``.
        tet_regions: (k,) float64, each tet's region attribute with switch ``A``, else
            None.
        stats: the ``-V`` figures (``tetcdt --stats-json`` writes the same fields), with
            the quality figures (``max_radius_edge_ratio``, ``min_dihedral``, ...) when
            ``q`` or ``a`` is given.

    The arrays are read-only: they are the mesh that ``write`` writes.
    """

    points: np.ndarray
    tets: np.ndarray
    faces: np.ndarray
    face_markers: np.ndarray
    edges: np.ndarray
    edge_markers: np.ndarray
    tet_regions: Optional[np.ndarray]
    stats: dict[str, Any]

    def __init__(self, native: dict[str, Any]) -> None:
        for name in ("points", "tets", "faces", "face_markers", "edges", "edge_markers"):
            setattr(self, name, _read_only(native[name]))
        regions = native["tet_regions"]
        self.tet_regions = None if regions is None else _read_only(regions)
        self.stats = native["stats"]
        self._files = native["files"]

    def __repr__(self) -> str:
        return (
            f"<tetcdt.Mesh: {len(self.points)} points, {len(self.tets)} tets, "
            f"{len(self.faces)} faces>"
        )

    def write(self, prefix: Union[str, os.PathLike[str]]) -> list[str]:
        """Writes TetGen's files (``prefix.node``, ``.ele``, ``.face``, ``.edge``, and
        what the switches ``e n f k g z`` add) and returns their paths.

        The files are written whole or not at all, as the command line writes them.
        """
        paths = self._files.write(os.fspath(prefix), self.points, self.tets)
        return [os.fspath(p) for p in paths]

    def to_meshio(self) -> Any:
        """The mesh as a ``meshio.Mesh`` (tets, and the faces on facets with their markers
        as cell data ``facet_marker``; ``region`` too with switch ``A``)."""
        try:
            import meshio  # type: ignore[import-untyped,import-not-found,unused-ignore]
        except ImportError as e:
            raise ImportError("Mesh.to_meshio needs meshio: pip install meshio") from e
        cells = [("tetra", np.asarray(self.tets)), ("triangle", np.asarray(self.faces))]
        cell_data = {
            "facet_marker": [
                np.zeros(len(self.tets), dtype=np.int32),
                np.asarray(self.face_markers),
            ]
        }
        if self.tet_regions is not None:
            cell_data["region"] = [
                np.asarray(self.tet_regions),
                np.zeros(len(self.faces)),
            ]
        return meshio.Mesh(np.asarray(self.points), cells, cell_data=cell_data)

    def to_pyvista(self) -> Any:
        """The tets as a ``pyvista.UnstructuredGrid`` (with cell data ``region`` under
        switch ``A``)."""
        try:
            import pyvista  # type: ignore[import-untyped,import-not-found,unused-ignore]
        except ImportError as e:
            raise ImportError("Mesh.to_pyvista needs pyvista: pip install pyvista") from e
        k = len(self.tets)
        cells = np.empty((k, 5), dtype=np.int64)
        cells[:, 0] = 4
        cells[:, 1:] = self.tets
        celltypes = np.full(k, pyvista.CellType.TETRA, dtype=np.uint8)
        grid = pyvista.UnstructuredGrid(cells.ravel(), celltypes, np.asarray(self.points))
        if self.tet_regions is not None:
            grid.cell_data["region"] = np.asarray(self.tet_regions)
        return grid


class PLC:
    """A piecewise linear complex read from a file (``tetcdt.read``).

    Attributes:
        points: (n, 3) float64.
        facets: one list of polygons (int64 arrays of point indices, from 0) per facet.
        facet_markers: (m,) int64.
        facet_holes: per facet, the hole points inside it.
        holes: (h, 3) float64, the volume holes.
        regions: (r, 5) float64: a point inside, the attribute, the volume bound
            (negative when none).
        source: the file read; ``first_index`` is the number of its first point.
    """

    def __init__(self, native: Any) -> None:
        self._native = native
        self.points: np.ndarray = native.points
        indices, polygon_ends, facet_ends = native.facet_arrays
        polygons = np.split(indices, polygon_ends[1:-1]) if len(polygon_ends) > 1 else []
        self.facets: list[list[np.ndarray]] = [
            polygons[facet_ends[i] : facet_ends[i + 1]] for i in range(len(facet_ends) - 1)
        ]
        self.facet_markers: np.ndarray = native.facet_markers
        self.facet_holes: list[list[tuple[float, float, float]]] = native.facet_holes
        self.holes: np.ndarray = native.holes
        self.regions: np.ndarray = native.regions
        self.source: str = os.fspath(native.source)
        self.first_index: int = native.first_index
        self.warnings: list[str] = native.warnings

    def __repr__(self) -> str:
        return (
            f"<tetcdt.PLC {self.source!r}: {len(self.points)} points, "
            f"{len(self.facets)} facets>"
        )

    @property
    def faces(self) -> Faces:
        """The facets in ``tetrahedralize``'s form: an (m, 3) array when every facet is
        one triangle, else the list of facets."""
        if all(len(f) == 1 and len(f[0]) == 3 for f in self.facets):
            return np.array([f[0] for f in self.facets], dtype=np.int64).reshape(-1, 3)
        return self.facets

    def tetrahedralize(self, switches: str = "pq1.414") -> Mesh:
        """Meshes the PLC exactly as the command line meshes its file (facet holes
        included)."""
        return _finish(self._native.tetrahedralize(switches))


def _finish(native: dict[str, Any]) -> Mesh:
    for w in native["warnings"]:
        warnings.warn(w, stacklevel=3)
    return Mesh(native)


def _flat_facets(faces: Faces) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The facets as flat arrays: the point indices, where each polygon ends, and where
    each facet's polygons end (both offsets starting with 0)."""
    if isinstance(faces, np.ndarray) or (
        len(faces) > 0 and all(np.isscalar(v) for v in faces[0])
    ):
        try:
            a = np.asarray(faces)
        except ValueError:
            a = None  # polygons of different lengths
        if a is not None and a.dtype != object and a.ndim == 2:
            if a.size and not np.issubdtype(a.dtype, np.integer):
                raise ValueError(f"faces must hold integer point indices, not {a.dtype}")
            m, k = a.shape
            indices = np.ascontiguousarray(a, dtype=np.int64).ravel()
            return indices, np.arange(0, m * k + 1, k, dtype=np.int64), np.arange(m + 1)
        facets: Any = [[p] for p in faces]
    else:
        facets = faces
    indices_list: list[np.ndarray] = []
    polygon_ends = [0]
    facet_ends = [0]
    total = 0
    for fi, facet in enumerate(facets):
        for polygon in facet:
            p = np.asarray(polygon)
            if p.ndim != 1 or (p.size and not np.issubdtype(p.dtype, np.integer)):
                raise ValueError(
                    f"facet {fi}: a polygon must be a list of integer point indices"
                )
            indices_list.append(p.astype(np.int64, copy=False))
            total += p.size
            polygon_ends.append(total)
        facet_ends.append(len(polygon_ends) - 1)
    indices = np.concatenate(indices_list) if indices_list else np.zeros(0, np.int64)
    return indices, np.asarray(polygon_ends, np.int64), np.asarray(facet_ends, np.int64)


def _float_rows(name: str, a: Optional[ArrayLike], width: Sequence[int]) -> Optional[np.ndarray]:
    if a is None:
        return None
    arr = np.ascontiguousarray(a, dtype=np.float64)
    if arr.size == 0:
        arr = arr.reshape(0, width[0])
    if arr.ndim != 2 or arr.shape[1] not in width:
        shape = " or ".join(f"(n, {w})" for w in width)
        raise ValueError(f"{name} must have shape {shape}, not {arr.shape}")
    return arr


def tetrahedralize(
    points: ArrayLike,
    faces: Optional[Faces] = None,
    switches: str = "pq1.414",
    holes: Optional[ArrayLike] = None,
    regions: Optional[ArrayLike] = None,
    facet_markers: Optional[ArrayLike] = None,
) -> Mesh:
    """Meshes a PLC given as arrays and returns the ``Mesh``.

    Args:
        points: (n, 3) coordinates.
        faces: the facets, as an (m, 3) (or (m, k)) integer array of polygons, a list of
            polygons (lists of point indices), or a list of facets (each a list of
            polygons in one plane). Indices count from 0. None meshes the points alone
            (the Delaunay tetrahedralization; leave ``p`` out of the switches).
        switches: the command line's switches, such as ``"pq1.414a0.1"`` or ``"pA"``.
        holes: (h, 3) points inside volume holes.
        regions: (r, 4) or (r, 5): a point inside each region, its attribute, and its
            volume bound (used with ``a`` alone).
        facet_markers: one integer marker per facet.

    Raises:
        InvalidInputError: the input is not a valid PLC (intersecting facets, a point
            index out of range, ...), with the command line's message.
        MeshingError: meshing failed on a valid input (the command line's exit code 1).
        ValueError: bad switches, or arrays of the wrong shape.
    """
    pts = np.ascontiguousarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must have shape (n, 3), not {pts.shape}")
    if faces is None:
        faces = np.zeros((0, 3), dtype=np.int64)
    indices, polygon_ends, facet_ends = _flat_facets(faces)
    markers = None
    if facet_markers is not None:
        markers = np.ascontiguousarray(facet_markers, dtype=np.int64).ravel()
    native = _tetcdt.tetrahedralize(
        pts,
        indices,
        polygon_ends,
        facet_ends,
        markers,
        _float_rows("holes", holes, (3,)),
        _float_rows("regions", regions, (4, 5)),
        switches,
    )
    return _finish(native)


def read(path: Union[str, os.PathLike[str]]) -> PLC:
    """Reads a model in any format the command line reads (``.poly``, ``.smesh``,
    ``.off``, ``.obj``, ``.stl``, ``.ply``, Medit ``.mesh``, ``.node``).

    Raises:
        InvalidInputError: the file is malformed (the message names file, line and
            element).
        FileNotFoundError, OSError: it cannot be read.
    """
    return PLC(_tetcdt.read(os.fspath(path)))
