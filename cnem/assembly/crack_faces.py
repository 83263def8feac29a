"""Crack faces seen from the integration cells: the side of a cell edge on a face,
and the slits a crack-tip cell wraps around."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import shapely

from ..geometry.pslg import CRACK
from ..geometry.topology import constraint_edges
from ..spatial.rtree import RTree
from .._sets import isin

if TYPE_CHECKING:
    from ..geometry.model import Cells, Model

__all__ = ["crack_faces", "slit_edges", "face_triangles"]


def crack_faces(model: Model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Crack-face edges, each oriented with its own face's triangle on the left.

    Returns
    -------
    p, q : (f, 2) ndarray
        Ends.
    owner : (f,) int64 ndarray
        The triangle of that face.
    """
    crack = model.segments[model.segment_kind == CRACK]
    n = len(model.nodes)
    edges, owner = constraint_edges(model.triangles, model.neighbors())
    is_face = isin(np.sort(edges, axis=1) @ [n, 1], np.sort(crack, axis=1) @ [n, 1])
    edges, owner = edges[is_face], owner[is_face]
    return model.nodes[edges[:, 0]], model.nodes[edges[:, 1]], owner


def slit_edges(model: Model, faces: tuple, cells: Cells
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Crack faces running inside cells (near crack tips a cell can wrap around the
    end of a crack; its polygon then does not show the slit, but the slit's two
    faces are part of the cell's boundary, with different shape functions).

    Returns
    -------
    cell : (s,) int64 ndarray
    a, b : (s, 2) ndarray
        Slit edges, oriented like their face (the face's material on the left).
    hint : (s,) int64 ndarray
        The triangle of the face.
    """
    p, q, owner = faces
    if len(p) == 0:
        return np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0, np.int64)
    frame = model.frame                    # O(1) coordinates at any origin and in any units
    p, q, vertices = (frame.to_local(x) for x in (p, q, cells.vertices))
    area = cells.area / frame.scale ** 2
    # the cell vertices are known only to the domain's tolerance (their global round-off
    # far from the origin): a vertex on the face may stand that far off its line
    tol = model.domain.tolerance / frame.scale
    first = np.repeat(np.arange(len(cells.area)), np.diff(cells.offsets))
    lo = np.full((len(cells.area), 2), np.inf)
    hi = np.full((len(cells.area), 2), -np.inf)
    np.minimum.at(lo, first, vertices)
    np.maximum.at(hi, first, vertices)
    off, idx = RTree(lo, hi).query(np.minimum(p, q), np.maximum(p, q))
    out = []
    for f in range(len(p)):
        face = shapely.LineString([p[f], q[f]])
        for c in idx[off[f]:off[f + 1]]:
            polygon = shapely.Polygon(vertices[cells.offsets[c]:cells.offsets[c + 1]])
            eps = max(1e-6 * np.sqrt(area[c]), tol)
            for piece in _line_parts(face.intersection(polygon)):
                xy = np.asarray(piece.coords)
                d = xy[-1] - xy[0]
                length = np.hypot(*d)
                if length <= eps:
                    continue
                mid = 0.5 * (xy[0] + xy[-1])
                side = eps * np.array([-d[1], d[0]]) / length
                if polygon.contains(shapely.Point(mid + side)) and \
                        polygon.contains(shapely.Point(mid - side)):
                    out.append((c, xy[0], xy[-1], owner[f]))
    if not out:
        return np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0, np.int64)
    cell, a, b, hint = zip(*out)
    return (np.array(cell, np.int64), frame.to_global(np.array(a)), frame.to_global(np.array(b)),
            np.array(hint, np.int64))


def _line_parts(geom):
    """The line pieces of a shapely intersection result."""
    if isinstance(geom, shapely.LineString):
        return [geom] if not geom.is_empty else []
    if hasattr(geom, "geoms"):
        return [g for g in geom.geoms if isinstance(g, shapely.LineString)]
    return []


def face_triangles(model: Model, a: np.ndarray, b: np.ndarray, faces: tuple) -> np.ndarray:
    """For cell edges lying on a crack face, the triangle of that face on the
    cell's side (the shape functions there depend on the side); -1 elsewhere.

    Returns
    -------
    (e,) int64 ndarray
    """
    hint = np.full(len(a), -1, dtype=np.int64)
    p, q, owner = faces
    frame = model.frame                    # O(1) coordinates at any origin and in any units
    p, q, a, b = (frame.to_local(x) for x in (p, q, a, b))
    tol = model.domain.tolerance / frame.scale
    mid = 0.5 * (a + b)
    off, idx = RTree(np.minimum(p, q) - tol, np.maximum(p, q) + tol).query(mid, mid)
    row = np.repeat(np.arange(len(a)), np.diff(off))
    pq, d = q[idx] - p[idx], (b - a)[row]
    length = np.linalg.norm(pq, axis=1)
    rel = mid[row] - p[idx]
    on_line = np.abs(pq[:, 0] * rel[:, 1] - pq[:, 1] * rel[:, 0]) <= tol * length
    along = (rel * pq).sum(axis=1) / length
    inside = (along > -tol) & (along < length + tol)
    same_way = (d * pq).sum(axis=1) > 0.0          # the face's triangle lies on the left too
    hit = on_line & inside & same_way
    hint[row[hit]] = owner[idx[hit]]
    return hint
