"""A 2-D domain from a gmsh ``.msh`` file (any version meshio reads: MSH 2.2, 4.1).

* **Regions**: the surface elements (triangles, quadrangles, first or second order),
  one region per physical surface (in the order of their tags; a group in several
  pieces gives a region per piece), named after it; without physical surfaces all
  surface elements make the regions. Without surface elements the line elements
  must close into outlines (shells and the holes inside them).
* **Outline**: the edges of the surface elements on one side only, with the vertices
  where the boundary runs straight dropped (the mesh's nodes along a straight side
  are not corners) except where a named boundary starts or ends.
* **Named boundaries**: one per physical curve (its name, or its tag as a string
  if it has none): the line elements of the group.
"""

from __future__ import annotations

import os

import numpy as np

from ..errors import FormatError, GeometryError
from .outlines import chain_pieces, drop_straight_vertices, outline_tolerance, polygons_from_rings
from .._sets import distinct, isin

__all__ = ["read_gmsh"]

#: The boundary of each element as a closed polygon through its nodes (gmsh's node
#: order: corners first, then one node per edge).
SURFACE_ORDER = {"triangle": [0, 1, 2], "triangle6": [0, 3, 1, 4, 2, 5], "quad": [0, 1, 2, 3],
                 "quad8": [0, 4, 1, 5, 2, 6, 3, 7], "quad9": [0, 4, 1, 5, 2, 6, 3, 7]}
#: Each line element as a polyline through its nodes.
LINE_ORDER = {"line": [0, 1], "line3": [0, 2, 1]}
#: Cell types of no concern for a 2-D outline.
IGNORED = {"vertex"}


def _group_names(field_data):
    """``{(dim, tag): name}`` of the physical groups that have a name."""
    return {(int(v[1]), int(v[0])): name for name, v in field_data.items()
            if np.size(v) >= 2}


def _cells(mesh, path):
    """Surface element edges and line segments with their physical tags."""
    physical = mesh.cell_data.get("gmsh:physical")
    surface, lines = [], []
    for k, block in enumerate(mesh.cells):
        tags = (np.zeros(len(block.data), dtype=np.int64) if physical is None
                else np.asarray(physical[k], dtype=np.int64))
        if block.type in SURFACE_ORDER:
            order = SURFACE_ORDER[block.type]
            ring = block.data[:, order]
            edges = np.stack([ring, np.roll(ring, -1, axis=1)], axis=2)     # (c, k, 2)
            surface.append((edges.reshape(-1, 2), np.repeat(tags, len(order))))
        elif block.type in LINE_ORDER:
            chain = block.data[:, LINE_ORDER[block.type]]
            segs = np.stack([chain[:, :-1], chain[:, 1:]], axis=2).reshape(-1, 2)
            lines.append((segs, np.repeat(tags, chain.shape[1] - 1)))
        elif block.type not in IGNORED:
            raise FormatError(
                f"{path}: holds {block.type} elements; expected a 2-D mesh of triangles or "
                "quadrangles (or only boundary lines): for a solid use a 3-D domain, for "
                "higher-order elements save the mesh at order 1 or 2")
    return _joined(surface), _joined(lines)


def _joined(parts):
    """``(edges (e, 2), tags (e,))`` of the blocks' parts, concatenated."""
    if not parts:
        return np.empty((0, 2), dtype=np.int64), np.empty(0, dtype=np.int64)
    return (np.concatenate([p[0] for p in parts]).astype(np.int64),
            np.concatenate([p[1] for p in parts]))


def _once(edges):
    """The edges (undirected) that occur exactly once."""
    key = np.sort(edges, axis=1)
    unique, counts = np.unique(key, axis=0, return_counts=True)
    return unique[counts == 1]


def _outlines(edges, points, named_vertices, tol, path):
    """Polygons ``(shell, holes)`` bounded by ``edges`` (vertex pairs)."""
    rings = []
    for ring in chain_pieces(edges, path, points):
        ids = np.array([edges[p, 0] if forward else edges[p, 1] for p, forward in ring])
        rings.append(drop_straight_vertices(points[ids], isin(ids, named_vertices), tol))
    return polygons_from_rings(rings, path)


def read_gmsh(path: str | os.PathLike) -> dict:
    """Regions, named boundaries and region names of a 2-D gmsh mesh (see the module).

    Returns
    -------
    dict
        ``regions`` (list of ``(shell, holes)``), ``boundaries`` (name -> ``(s, 2, 2)``
        segments), ``region_names``.

    Raises
    ------
    FormatError
        A file meshio cannot read, a 3-D mesh, no elements to make an outline of.
    GeometryError
        Outlines that do not close, cross or branch.
    """
    import meshio.gmsh                      # not meshio.read: it exits Python on a bad file
    try:
        mesh = meshio.gmsh.read(str(path))
    except Exception as exc:               # meshio raises ReadError, ValueError, IndexError ...
        raise FormatError(f"{path}: cannot read it as a gmsh mesh ({type(exc).__name__}: "
                          f"{exc}); expected a .msh file saved by gmsh (ASCII or binary, "
                          "version 2.2 or 4.1)") from None
    points = np.asarray(mesh.points, dtype=float)
    if points.shape[1] > 2:
        flat = np.ptp(points[:, 2]) <= outline_tolerance(points[:, :2]) if len(points) else True
        if not flat:
            raise FormatError(f"{path}: the nodes do not lie in a plane z = const (z spans "
                              f"{np.ptp(points[:, 2]):.3g}); expected a 2-D mesh in the x-y plane")
        points = points[:, :2]
    names = _group_names(mesh.field_data)
    (surface, surface_tag), (lines, line_tag) = _cells(mesh, path)
    if len(surface) == 0 and len(lines) == 0:
        raise FormatError(f"{path}: holds no triangles, quadrangles or lines; expected a 2-D "
                          "mesh (in gmsh: Mesh > 2D, then save)")
    tol = outline_tolerance(points)
    boundaries, named_vertices = {}, [np.empty(0, dtype=np.int64)]
    for tag in distinct(line_tag[line_tag > 0]):
        segs = lines[line_tag == tag]
        boundaries[names.get((1, int(tag)), str(tag))] = points[segs]
        # where a group ends (one of its segments there) the outline keeps a corner
        named_vertices.append(np.flatnonzero(np.bincount(segs.ravel(), minlength=len(points))
                                             % 2 == 1))
    named_vertices = np.concatenate(named_vertices)
    regions, region_names = [], []
    if len(surface):
        for tag in distinct(surface_tag):
            polygons = _outlines(_once(surface[surface_tag == tag]), points, named_vertices,
                                 tol, path)
            regions += polygons
            name = names.get((2, int(tag)), str(tag) if tag > 0 else None)
            region_names += [name] * len(polygons)
    else:
        regions = _outlines(lines, points, named_vertices, tol, path)
        region_names = [None] * len(regions)
    if not regions:
        raise GeometryError(f"{path}: no closed outline found; expected surface elements or "
                            "boundary lines that close")
    return {"regions": regions, "boundaries": boundaries, "region_names": region_names}
