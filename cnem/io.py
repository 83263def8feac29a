"""Files: integration cells and nodes of a `Model` through meshio (VTU).

`write` stores one unstructured grid that ParaView opens directly:

* points: the ``n`` nodes first (point ``i`` is node ``i``), then every
  distinct vertex of the integration cells (every cell's own vertices in a
  cracked model, so that the crack faces part), as float64 with ``z = 0`` in 2-D
  (`read` gives back ``(n, 2)`` nodes then, ``(n, 3)`` when a ``z`` is not 0);
* cells: one ``vertex`` cell per node, then the integration cells as
  ``polygon`` cells, grouped by vertex count (meshio keeps one block per
  polygon size);
* cell data ``region``, ``node`` (owner node), ``area`` and ``cell`` (index of
  the integration cell in ``model.cells``; ``-1`` on the vertex cells), plus
  the caller's arrays;
* point data ``node_of_point``, in a cracked 2-D model ``crack_face``
  (`crack_face_ids`), plus the caller's per-node arrays.

Arrays are written in binary, so `read` gives back the cells bit for bit.

>>> import tempfile, pathlib, numpy as np, cnem, cnem.io
>>> from cnem.geometry import rectangle
>>> dom = rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.5, 0.5]]])
>>> model = cnem.discretize(cnem.nodes.regular(dom, 0.1))
>>> path = cnem.io.write(model, pathlib.Path(tempfile.mkdtemp()) / "cells.vtu")
>>> back = cnem.io.read(path)
>>> np.array_equal(back.vertices, model.cells.vertices), np.array_equal(back.node, model.cells.node)
(True, True)

XDMF is not offered: meshio's XDMF writer has no polygon topology. Legacy
``.vtk`` is not offered either: it pads two-component arrays to three, so
point data would not come back as written.
"""

from __future__ import annotations

import logging
import os
import pathlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import meshio
import numpy as np
from numpy.typing import ArrayLike

from .errors import FormatError, check_points
from .geometry.model import Cells
from ._sets import distinct

if TYPE_CHECKING:
    from .geometry.model import Model
    from .geometry.model3d import Model3D

__all__ = ["write", "cell_points", "crack_face_ids", "write_nodes", "write_points", "read", "CellMesh",
           "FormatError", "SUFFIXES"]

log = logging.getLogger(__name__)

#: File suffixes `write` and `read` accept, with the meshio format of each.
SUFFIXES = {".vtu": "vtu"}

#: Cell-data names `write` reserves for itself.
RESERVED = ("region", "node", "area", "cell")


#: Suffixes of geometry files, which `cnem.Domain.from_file` / `cnem.Domain3D.from_file` read.
GEOMETRY_SUFFIXES = (".msh", ".dxf", ".geojson", ".json", ".wkt", ".stl", ".obj", ".ply")


def _format(path):
    path = pathlib.Path(path)
    suffix = path.suffix.lower()
    if suffix in SUFFIXES:
        return path, SUFFIXES[suffix]
    supported = ", ".join(SUFFIXES)
    if suffix == ".vtk":
        raise FormatError(f"cannot use {path.name!r}: legacy VTK pads 2-component arrays to 3, "
                          f"so files would not read back as written; supported suffixes: "
                          f"{supported}")
    if suffix in (".xdmf", ".xmf", ".h5"):
        raise FormatError(f"cannot use {path.name!r}: meshio's XDMF writer has no polygon "
                          f"topology for the integration cells; supported suffixes: "
                          f"{supported} (open .vtu files in ParaView)")
    if suffix in GEOMETRY_SUFFIXES:
        raise FormatError(f"cannot use {path.name!r}: cnem.io reads and writes models and "
                          f"results (supported suffixes: {supported}); read a geometry file with "
                          f"cnem.Domain.from_file({str(path)!r}) (2-D) or "
                          f"cnem.Domain3D.from_file (3-D surfaces)")
    raise FormatError(f"unknown file suffix {suffix or '(none)'!r} in {str(path)!r}; "
                      f"supported suffixes: {supported}")


def cell_topology(cells, *, shared: bool = True):
    """Distinct vertices and polygon connectivity of integration cells.

    Vertices that are bit-for-bit equal become one point, so neighbouring
    cells share their points and the coordinates are never altered.

    Parameters
    ----------
    cells : Cells
        ``model.cells``, ``m`` cells with ``k`` vertices in all.
    shared : bool
        False gives every cell its own copies of its vertices (``q = k``): the
        cells on the two faces of a crack then move apart with their own
        displacements.

    Returns
    -------
    points : (q, 2) float64 ndarray
        Distinct cell vertices.
    offsets : (m + 1,) int64 ndarray
        Cell ``c`` is ``points[connectivity[offsets[c]:offsets[c + 1]]]``.
    connectivity : (k,) int64 ndarray
    """
    vertices = np.ascontiguousarray(cells.vertices, dtype=np.float64)
    if not shared:
        return vertices, np.asarray(cells.offsets, np.int64), np.arange(len(vertices),
                                                                        dtype=np.int64)
    points, connectivity = np.unique(vertices, axis=0, return_inverse=True)
    return points, np.asarray(cells.offsets, np.int64), connectivity.reshape(-1).astype(np.int64)


def cell_points(model: Model | Model3D) -> tuple[np.ndarray, np.ndarray]:
    """The points `write` stores after the nodes, and a cell each of them bounds.

    Parameters
    ----------
    model : Model or Model3D
        ``m`` integration cells.

    Returns
    -------
    points : (q, d) float64 ndarray
        The distinct vertices of the cells (2-D polygons; 3-D facet triangles),
        every cell's own in a cracked model. Point ``n + j`` of the file is
        ``points[j]``.
    cell : (q,) int64 ndarray
        Index in ``model.cells`` of a cell with vertex ``j`` (the lowest).
    """
    if _polyhedral(model.cells):
        points, triangles = polyhedron_topology(model.cells)
        corner_cell = np.repeat(np.asarray(model.cells.facet_cell, np.int64), 3)
        corners = triangles.reshape(-1)
    else:
        points, offsets, corners = cell_topology(model.cells, shared=not _cracked(model))
        corner_cell = np.repeat(np.arange(len(offsets) - 1, dtype=np.int64), np.diff(offsets))
    cell = np.full(len(points), len(model.cells), dtype=np.int64)
    np.minimum.at(cell, corners, corner_cell)
    return points, cell


def _cracked(model):
    """Whether the model's domain has cracks (its file then shares no cell vertices)."""
    return len(getattr(getattr(model, "domain", None), "cracks", ())) > 0


def crack_face_ids(model: Model) -> np.ndarray:
    """Which crack face each node of a cracked 2-D model lies on.

    Parameters
    ----------
    model : Model
        From `cnem.discretize`; its crack-face nodes are the points of the cloud
        with two nodes (``model.node_of_point``).

    Returns
    -------
    (n,) int64 ndarray
        0 off the cracks; ``k + 1`` on the face of crack ``k`` (of
        ``model.domain.cracks``, the nearest polyline) that the crack's normal points
        to, ``-(k + 1)`` on the other. The normal of a crack segment ``a -> b`` is
        ``b - a`` turned counter-clockwise; a node's side is that of its cell
        (`Model.node_sides`).
    """
    nodes = np.asarray(model.nodes, np.float64)
    ids = np.zeros(len(nodes), np.int64)
    copies = np.flatnonzero(np.bincount(model.node_of_point)[model.node_of_point] > 1)
    cracks = model.domain.cracks
    if not len(copies) or not cracks:
        return ids
    a = np.concatenate([c[:-1] for c in cracks])
    b = np.concatenate([c[1:] for c in cracks])
    crack = np.concatenate([np.full(len(c) - 1, k) for k, c in enumerate(cracks)])
    x = nodes[copies][:, None]                                        # (c, 1, 2)
    t = np.clip(np.einsum("csj,sj->cs", x - a, b - a) / np.einsum("sj,sj->s", b - a, b - a), 0, 1)
    nearest = np.argmin(np.linalg.norm(x - (a + t[..., None] * (b - a)), axis=2), axis=1)
    normal = (b - a)[nearest] @ np.array([[0.0, 1.0], [-1.0, 0.0]])   # turned counter-clockwise
    side = np.einsum("cj,cj->c", model.node_sides()[copies] - nodes[copies], normal)
    ids[copies] = np.where(side > 0, 1, -1) * (crack[nearest] + 1)
    return ids


def _polyhedral(cells):
    """Whether ``cells`` are 3-D cells bounded by facet triangles (`cnem.geometry.Cells3D`)."""
    return hasattr(cells, "facet_triangles")


def polyhedron_topology(cells):
    """Distinct vertices ``(q, 3)`` of the 3-D cells' facet triangles and the
    triangles as indices into them ``(t, 3)`` (bit-for-bit equal vertices merged)."""
    corners = np.ascontiguousarray(cells.facet_triangles, dtype=np.float64).reshape(-1, 3)
    points, index = np.unique(corners, axis=0, return_inverse=True)
    return points, index.reshape(-1, 3).astype(np.int64)


def _polyhedron_blocks(cells, triangles, shift):
    """meshio ``polyhedron<k>`` blocks (faces of each cell; ``k`` its vertex count, in
    increasing order, which meshio's reader needs to keep the cell data in step) and the
    cell order they use."""
    m = len(cells.node)
    order = np.argsort(cells.facet_cell, kind="stable")
    starts = np.concatenate([[0], np.cumsum(np.bincount(cells.facet_cell, minlength=m))])
    faces = [triangles[order[starts[c]:starts[c + 1]]] + shift for c in range(m)]
    sizes = np.array([len(distinct(f)) for f in faces], dtype=np.int64)
    blocks, ids = [], []
    for size in distinct(sizes):
        members = np.flatnonzero(sizes == size)
        blocks.append(meshio.CellBlock(f"polyhedron{size}", [list(faces[c]) for c in members]))
        ids.append(members)
    return blocks, ids


def _blocks(offsets, connectivity, shift):
    """meshio ``polygon`` blocks (one per vertex count) and the cell order they use."""
    sizes = np.diff(offsets)
    order = np.argsort(sizes, kind="stable")
    blocks, ids = [], []
    for size in distinct(sizes):
        members = order[sizes[order] == size]
        rows = offsets[members][:, None] + np.arange(size)
        blocks.append(meshio.CellBlock("polygon", connectivity[rows] + shift))
        ids.append(members)
    return blocks, ids


def _checked(value, count, name):
    """``value`` as an array of ``count`` rows and its fill value (NaN, or -1 for integers)."""
    arr = np.asarray(value)
    if arr.ndim == 0 or len(arr) != count:
        raise FormatError(f"{name}: expected an array of {count} rows, received shape "
                          f"{np.shape(value)}")
    if arr.dtype.kind in "biu":
        arr = arr.astype(np.int64)
        fill = -1
    elif arr.dtype.kind == "f":
        fill = np.nan
    else:
        raise FormatError(f"{name}: expected a numeric array, received dtype {arr.dtype}")
    return arr, fill


def write(model: Model | Model3D, path: str | os.PathLike, *,
          point_data: Mapping[str, ArrayLike] | None = None,
          cell_data: Mapping[str, ArrayLike] | None = None) -> pathlib.Path:
    """Write the nodes and integration cells of a model to a ``.vtu`` file.

    A 2-D model's cells are ``polygon`` cells after one ``vertex`` cell per node;
    a 3-D model's cells are ``polyhedron`` cells (VTK polyhedra whose faces are the
    cells' facet triangles; ParaView and pyvista clip, slice and measure them), with
    no vertex cells (meshio cannot mix them with polyhedra) and a cell-data
    ``volume`` instead of ``area``.

    Parameters
    ----------
    model : Model or Model3D
        From `cnem.discretize`: ``n`` nodes, ``m`` integration cells.
    path : str or os.PathLike
        Suffix ``.vtu``.
    point_data : dict of str -> (n,) or (n, c), or (n + q,) or (n + q, c) array_like, optional
        Values at the nodes (displacements, say), or at every point of the file
        (the nodes, then the ``q`` cell vertices of `cell_points`). With ``n`` rows
        the cell vertices get NaN (``-1`` for integer arrays). The names
        ``node_of_point`` and ``crack_face`` (written for a cracked 2-D model,
        `crack_face_ids`) are reserved.
    cell_data : dict of str -> (m,) or (m, c) array_like, optional
        Values on the integration cells (stresses, say); the node vertex
        cells get NaN (``-1``). The names ``region``, ``node``, ``area``
        (``volume``) and ``cell`` are reserved.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    FormatError
        Unsupported suffix, arrays of the wrong length, reserved names.
    """
    path, fmt = _format(path)
    cells, nodes = model.cells, np.asarray(model.nodes, np.float64)
    n, m = len(nodes), len(cells)
    if _polyhedral(model.cells):
        vpoints, triangles = polyhedron_topology(cells)
        blocks, ids = _polyhedron_blocks(cells, triangles, n)
        head, measure = [], ("volume", np.asarray(cells.volume, np.float64))
    else:
        vpoints, offsets, connectivity = cell_topology(cells, shared=not _cracked(model))
        blocks, ids = _blocks(offsets, connectivity, n)
        head = [meshio.CellBlock("vertex", np.arange(n, dtype=np.int64)[:, None])]
        measure = ("area", np.asarray(cells.area, np.float64))
    points = np.zeros((n + len(vpoints), 3))
    points[:n, :nodes.shape[1]] = nodes
    points[n:, :vpoints.shape[1]] = vpoints

    def per_block(values, fill, nodes_value=None):
        """Split ``values`` (m rows) over the blocks; the vertex block gets ``fill``."""
        first = [] if not head else [
            np.full((n,) + values.shape[1:], fill, dtype=values.dtype) if nodes_value is None
            else nodes_value]
        return first + [values[i] for i in ids]

    cdata = {
        "region": per_block(np.asarray(cells.region, np.int64), -1),
        "node": per_block(np.asarray(cells.node, np.int64), -1, np.arange(n, dtype=np.int64)),
        measure[0]: per_block(measure[1], np.nan),
        "cell": per_block(np.arange(m, dtype=np.int64), -1),
    }
    for name, value in (cell_data or {}).items():
        if name in RESERVED + (measure[0],):
            raise FormatError(f"cell_data name {name!r} is reserved by cnem.io "
                              f"({', '.join(cdata)}); rename it")
        arr, fill = _checked(value, m, f"cell_data[{name!r}]")
        cdata[name] = per_block(arr, fill)

    pdata = {"node_of_point": np.concatenate(
        [np.asarray(model.node_of_point, np.int64), np.full(len(vpoints), -1, np.int64)])}
    if _cracked(model) and not _polyhedral(cells):
        pdata["crack_face"] = np.concatenate([crack_face_ids(model),
                                              np.zeros(len(vpoints), np.int64)])
    for name, value in (point_data or {}).items():
        if name in ("node_of_point", "crack_face"):
            raise FormatError(f"point_data name {name!r} is reserved by cnem.io; rename it")
        rows = len(points) if np.ndim(value) and len(value) == len(points) else n
        arr, fill = _checked(value, rows, f"point_data[{name!r}]")
        full = np.full((len(points),) + arr.shape[1:], fill, dtype=arr.dtype)
        full[:rows] = arr
        pdata[name] = full

    mesh = meshio.Mesh(points, head + blocks, point_data=pdata, cell_data=cdata)
    meshio.write(path, mesh, file_format=fmt, binary=True)
    log.info("cnem.io.write: %d nodes, %d cells, %d cell sizes -> %s", n, m, len(blocks), path)
    return path


def write_nodes(model: Model, path: str | os.PathLike, *,
                point_data: Mapping[str, ArrayLike] | None = None) -> pathlib.Path:
    """Write the nodes, the constrained Delaunay triangles and the constraint segments.

    Parameters
    ----------
    model : Model
        ``n`` nodes, ``t`` triangles, ``s`` constraint segments.
    path : str or os.PathLike
        Suffix ``.vtu``.
    point_data : dict of str -> (n,) or (n, c) array_like, optional
        Values at the nodes.

    Returns
    -------
    pathlib.Path

    Notes
    -----
    Cell data ``region`` holds the region of each triangle (``-1`` on the
    segments) and ``kind`` the kind of each segment (0 boundary, 1 interface,
    2 crack face; ``-1`` on the triangles). Point data ``node_of_point`` maps
    each node to ``model.cloud.points``.
    """
    path, fmt = _format(path)
    nodes = np.asarray(model.nodes, np.float64)
    n = len(nodes)
    points = np.zeros((n, 3))
    points[:, :nodes.shape[1]] = nodes
    tri = np.asarray(model.triangles, np.int64)
    seg = np.asarray(model.segments, np.int64)
    pdata = {"node_of_point": np.asarray(model.node_of_point, np.int64)}
    for name, value in (point_data or {}).items():
        arr, _ = _checked(value, n, f"point_data[{name!r}]")
        pdata[name] = arr
    cells = [meshio.CellBlock("triangle", tri), meshio.CellBlock("line", seg)]
    cdata = {
        "region": [np.asarray(model.triangle_region, np.int64), np.full(len(seg), -1, np.int64)],
        "kind": [np.full(len(tri), -1, np.int64), np.asarray(model.segment_kind, np.int64)],
    }
    meshio.write(path, meshio.Mesh(points, cells, point_data=pdata, cell_data=cdata),
                 file_format=fmt, binary=True)
    return path


def write_points(points: ArrayLike, path: str | os.PathLike, *, cells: ArrayLike | None = None,
                 point_data: Mapping[str, ArrayLike] | None = None,
                 cell_data: Mapping[str, ArrayLike] | None = None) -> pathlib.Path:
    """Write points (2-D or 3-D), as ``vertex`` cells or with triangles or tetrahedra on them.

    Parameters
    ----------
    points : (n, 2) or (n, 3) array_like
        Written with ``z = 0`` in 2-D.
    path : str or os.PathLike
        Suffix ``.vtu``.
    cells : (t, 3) or (t, 4) int array_like, optional
        Triangles (3 columns) or, on 3-D points, tetrahedra (4 columns), as indices into
        ``points``; without them every point is a ``vertex`` cell.
    point_data : dict of str -> (n,) or (n, c) array_like, optional
    cell_data : dict of str -> (t,) or (t, c) array_like, optional
        Values on the cells (or on the vertex cells: one per point).

    Returns
    -------
    pathlib.Path

    Raises
    ------
    FormatError
        Unsupported suffix, cells that are not triangles or tetrahedra of the points, or
        arrays of the wrong length.
    """
    path, fmt = _format(path)
    pts = check_points("points", points, error=FormatError)
    full = np.zeros((len(pts), 3))
    full[:, :pts.shape[1]] = pts
    if cells is None:
        block = meshio.CellBlock("vertex", np.arange(len(pts), dtype=np.int64)[:, None])
    else:
        cell = np.asarray(cells)
        corners = (3, 4) if pts.shape[1] == 3 else (3,)
        if cell.ndim != 2 or cell.shape[1] not in corners or cell.dtype.kind not in "iu" or \
                (cell.size and (cell.min() < 0 or cell.max() >= len(pts))):
            kinds = " or (t, 4) tetrahedra" if pts.shape[1] == 3 else ""
            raise FormatError(f"cells: expected a (t, 3) array of triangles{kinds}, as point "
                              f"indices in [0, {len(pts)}), received shape {cell.shape}, "
                              f"dtype {cell.dtype}"
                              + (f", indices {cell.min()}..{cell.max()}" if cell.size else "")
                              + "; index the points given")
        kind = "triangle" if cell.shape[1] == 3 else "tetra"
        block = meshio.CellBlock(kind, cell.astype(np.int64))
    pdata = {name: _checked(value, len(pts), f"point_data[{name!r}]")[0]
             for name, value in (point_data or {}).items()}
    cdata = {name: [_checked(value, len(block.data), f"cell_data[{name!r}]")[0]]
             for name, value in (cell_data or {}).items()}
    meshio.write(path, meshio.Mesh(full, [block], point_data=pdata, cell_data=cdata),
                 file_format=fmt, binary=True)
    return path


@dataclass(frozen=True, repr=False)
class CellMesh:
    """Nodes and integration cells read back from a file written by `write`.

    Attributes
    ----------
    nodes : (n, d) float64 ndarray
        d = 2 unless the file holds a point off the plane z = 0.
    node_of_point : (n,) int64 ndarray
    offsets : (m + 1,) int64 ndarray
    vertices : (k, d) float64 ndarray
        Cell ``c`` is ``vertices[offsets[c]:offsets[c + 1]]``, in the order
        and orientation of ``model.cells``.
    node : (m,) int64 ndarray
        Owner node of each cell.
    region : (m,) int64 ndarray
    area : (m,) float64 ndarray
    point_data : dict of str -> (n, ...) ndarray
        The caller's per-node arrays.
    cell_data : dict of str -> (m, ...) ndarray
        The caller's per-cell arrays.
    """

    nodes: np.ndarray
    node_of_point: np.ndarray
    offsets: np.ndarray
    vertices: np.ndarray
    node: np.ndarray
    region: np.ndarray
    area: np.ndarray
    point_data: dict = field(default_factory=dict)
    cell_data: dict = field(default_factory=dict)

    def __len__(self):
        return len(self.node)

    def polygon(self, i: int) -> np.ndarray:
        """Vertices of cell ``i``, ``(k, 2)``, counter-clockwise."""
        return self.vertices[self.offsets[i]:self.offsets[i + 1]]

    @property
    def cells(self) -> Cells:
        """The cells as a `cnem.geometry.Cells` (areas recomputed from the vertices)."""
        return Cells(self.node, self.region, self.offsets, self.vertices)

    def __repr__(self):
        extra = list(self.point_data) + list(self.cell_data)
        return (f"<CellMesh {len(self.nodes)} nodes, {len(self.node)} cells, "
                f"{len(distinct(self.region))} regions"
                + (f", data: {', '.join(extra)}" if extra else "") + ">")


def _meshio_read(path: str, fmt: str) -> meshio.Mesh:
    """``meshio.read``, with its failures as `FormatError`: on a file it cannot parse
    meshio raises ``SystemExit`` (which would end the interpreter) or its own errors."""
    try:
        return meshio.read(path, file_format=fmt)
    except FileNotFoundError:
        raise
    except (SystemExit, Exception) as err:          # meshio's ReadError, XML, struct errors
        raise FormatError(f"{str(path)!r} could not be read as {fmt} ({type(err).__name__}: "
                          f"{err}); is it a file that cnem.io.write produced, complete?") from None


def read(path: str | os.PathLike) -> CellMesh:
    """Read nodes and integration cells from a file written by `write`.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.vtu`` file from `write`.

    Returns
    -------
    CellMesh
        ``read(write(model, p))`` holds exactly ``model.cells.vertices``,
        ``offsets``, ``node``, ``region`` and ``area`` (float64, bit for bit)
        and ``model.nodes``.

    Raises
    ------
    FormatError
        Unsupported suffix, or a file that `write` did not produce.
    """
    path, fmt = _format(path)
    mesh = _meshio_read(path, fmt)
    if any(block.type.startswith("polyhedron") for block in mesh.cells):
        raise FormatError(f"{str(path)!r} holds the polyhedra of a 3-D model; cnem.io.read "
                          f"reads the polygon cells of 2-D models only: open it with "
                          f"meshio.read or pyvista.read")
    missing = [k for k in RESERVED if k not in mesh.cell_data]
    if missing:
        raise FormatError(f"{str(path)!r} lacks the cell data {missing} that cnem.io.write "
                          f"stores; it was not written by cnem.io.write")
    points = np.asarray(mesh.points, np.float64)
    dim = 3 if points.shape[1] == 3 and np.any(points[:, 2] != 0.0) else 2
    points = points[:, :dim]
    node_ids, polys = [], []
    for k, block in enumerate(mesh.cells):
        data = {name: np.asarray(mesh.cell_data[name][k]) for name in mesh.cell_data}
        if block.type == "vertex":
            node_ids.append(np.asarray(block.data, np.int64)[:, 0])
        elif block.type in ("polygon", "triangle", "quad"):
            polys.append((np.asarray(block.data, np.int64), data))
        else:
            raise FormatError(f"{str(path)!r}: unexpected cell type {block.type!r}; "
                              f"expected vertex and polygon cells from cnem.io.write")
    if not node_ids or not polys:
        raise FormatError(f"{str(path)!r}: expected vertex cells (nodes) and polygon cells "
                          f"(integration cells) as written by cnem.io.write")
    nodes_idx = np.concatenate(node_ids)
    nodes = points[nodes_idx]
    cell_ids = np.concatenate([d["cell"].astype(np.int64) for _, d in polys])
    m = len(cell_ids)
    if not np.array_equal(np.sort(cell_ids), np.arange(m)):
        raise FormatError(f"{str(path)!r}: cell indices are not a permutation of 0..{m - 1}")
    sizes = np.zeros(m, dtype=np.int64)
    for conn, d in polys:
        sizes[d["cell"].astype(np.int64)] = conn.shape[1]
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    vertices = np.empty((offsets[-1], dim))
    for conn, d in polys:
        rows = offsets[d["cell"].astype(np.int64)][:, None] + np.arange(conn.shape[1])
        vertices[rows] = points[conn]

    def gather(name, dtype=None):
        first = np.asarray(polys[0][1][name])
        out = np.empty((m,) + first.shape[1:], dtype=dtype or first.dtype.newbyteorder("="))
        for _, d in polys:
            out[d["cell"].astype(np.int64)] = d[name]
        return out

    user_cells = {name: gather(name) for name in mesh.cell_data if name not in RESERVED}
    user_points = {name: np.asarray(v)[nodes_idx].astype(np.asarray(v).dtype.newbyteorder("="))
                   for name, v in mesh.point_data.items() if name != "node_of_point"}
    nop = mesh.point_data.get("node_of_point")
    nop = (np.asarray(nop, np.int64)[nodes_idx] if nop is not None
           else np.arange(len(nodes), dtype=np.int64))
    return CellMesh(nodes=np.ascontiguousarray(nodes), node_of_point=nop, offsets=offsets,
                    vertices=vertices, node=gather("node", np.int64),
                    region=gather("region", np.int64), area=gather("area", np.float64),
                    point_data=user_points, cell_data=user_cells)
