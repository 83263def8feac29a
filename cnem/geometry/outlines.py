"""Outlines from the pieces files give: pieces chained into closed rings, rings nested
into polygons (a ring inside a shell is its hole, a ring inside a hole a new shell).

Shared by the gmsh and DXF readers (`cnem.geometry.readers`).

>>> import numpy as np
>>> from cnem.geometry.outlines import chain_pieces, polygons_from_rings
>>> ends = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])       # four sides of a square
>>> [[(p, forward) for p, forward in ring] for ring in chain_pieces(ends, "square")]
[[(0, True), (1, True), (2, True), (3, True)]]
>>> square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
>>> [(len(shell), len(holes)) for shell, holes in polygons_from_rings([square], "square")]
[(4, 0)]
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.validation import explain_validity

from .. import config
from ..errors import GeometryError

__all__ = ["outline_tolerance", "chain_pieces", "polygons_from_rings", "drop_straight_vertices"]


def _fmt(p):
    return f"({p[0]:.6g}, {p[1]:.6g})"


def outline_tolerance(points: np.ndarray) -> float:
    """The distance under which two points of an outline are one, ``(p, 2)`` points given:
    `cnem.config.SNAP_TOL` times their diagonal, or their round-off far from the origin
    (as `cnem.Domain.tolerance`)."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    roundoff = np.finfo(float).eps * float(np.abs(points).max())
    return max(config.SNAP_TOL * float(np.hypot(*(hi - lo))), config.ROUNDOFF_ULPS * roundoff)


def chain_pieces(ends: np.ndarray, what: str, points: np.ndarray | None = None) -> list:
    """The closed rings that pieces (segments, polylines) joined end to end make.

    Parameters
    ----------
    ends : (e, 2) int ndarray
        The end vertices of each piece (the same index where two pieces meet).
    what : str
        The file, named in the errors.
    points : (v, 2) ndarray, optional
        The vertices' coordinates, to say where an outline is open.

    Returns
    -------
    list of list of (int, bool)
        Each ring as its pieces in order, ``True`` where a piece runs from its first
        end to its second.

    Raises
    ------
    GeometryError
        A vertex where one piece ends alone (an open outline) or where more than two
        meet (a branch).
    """
    ends = np.asarray(ends, dtype=np.int64).reshape(-1, 2)
    degree = np.bincount(ends.ravel(), minlength=int(ends.max(initial=-1)) + 1)
    where = (lambda v: f" at {_fmt(points[v])}") if points is not None else (lambda v: "")
    odd = np.flatnonzero(degree % 2 == 1)
    if odd.size:
        raise GeometryError(
            f"{what}: the outline is open: {odd.size} piece ends meet no other piece, first"
            f"{where(odd[0])}; expected closed outlines: join the ends (close the polyline, "
            "snap the lines' end points together) or remove stray lines")
    branch = np.flatnonzero(degree > 2)
    if branch.size:
        raise GeometryError(
            f"{what}: {degree[branch[0]]} outline pieces meet{where(branch[0])}; expected "
            "each outline vertex to join exactly two pieces: split the drawing into separate "
            "closed outlines (for regions sharing a boundary, give each its own closed outline)")
    at_vertex = [[] for _ in range(len(degree))]
    for piece, (a, b) in enumerate(ends):
        at_vertex[a].append(piece)
        at_vertex[b].append(piece)
    used = np.zeros(len(ends), dtype=bool)
    rings = []
    for first in range(len(ends)):
        if used[first]:
            continue
        ring, piece, vertex = [], first, ends[first, 0]
        for _ in range(len(ends)):                # a ring has at most every piece
            used[piece] = True
            forward = bool(ends[piece, 0] == vertex)
            ring.append((piece, forward))
            vertex = ends[piece, 1] if forward else ends[piece, 0]
            following = [p for p in at_vertex[vertex] if not used[p]]
            if not following:
                break
            piece = following[0]
        rings.append(ring)
    return rings


def _ring_polygon(ring, k, what):
    poly = shapely.Polygon(ring)
    if not poly.is_valid or poly.area <= 0:
        raise GeometryError(
            f"{what}: outline {k} (from {_fmt(ring[0])}, {len(ring)} vertices) is not a simple "
            f"closed curve: {explain_validity(poly)}; expected outlines that do not cross or "
            "touch themselves: fix the drawing there")
    return poly


def polygons_from_rings(rings: list, what: str) -> list:
    """Nest closed rings into polygons by containment.

    A ring inside an even number of others is a shell; a ring inside an odd number
    is a hole of the smallest shell around it.

    Parameters
    ----------
    rings : list of (k, 2) ndarray
        Open rings (the first vertex not repeated), in any orientation.
    what : str
        The file, named in the errors.

    Returns
    -------
    list of ((k, 2) ndarray, list of (k, 2) ndarray)
        ``(shell, holes)`` per polygon, in the order of the shells' rings.

    Raises
    ------
    GeometryError
        A ring that crosses itself or another ring.
    """
    polys = [_ring_polygon(r, k, what) for k, r in enumerate(rings)]
    tree = shapely.STRtree(polys)
    inner, outer = tree.query(polys, predicate="within")
    keep = inner != outer
    inner, outer = inner[keep], outer[keep]
    crossing = tree.query(polys, predicate="overlaps")
    if crossing.size:
        a, b = crossing[:, 0]
        spot = polys[a].boundary.intersection(polys[b].boundary).representative_point()
        raise GeometryError(
            f"{what}: outlines {a} and {b} cross near {_fmt(spot.coords[0])}; expected outlines "
            "that are disjoint or nested (holes inside shells): fix the drawing there")
    depth = np.bincount(inner, minlength=len(polys))
    shells = np.flatnonzero(depth % 2 == 0)
    holes = {int(s): [] for s in shells}
    for h in np.flatnonzero(depth % 2 == 1):
        around = outer[(inner == h) & (depth[outer] == depth[h] - 1)]
        holes[int(around[0])].append(rings[h])
    return [(rings[s], holes[int(s)]) for s in shells]


def drop_straight_vertices(ring: np.ndarray, keep: np.ndarray, tol: float) -> np.ndarray:
    """A ring without the vertices that lie on the line through their neighbours.

    Parameters
    ----------
    ring : (k, 2) ndarray
        Open ring (the first vertex not repeated).
    keep : (k,) bool ndarray
        Vertices to keep whatever (where a named boundary starts or ends, say).
    tol : float
        Distance from the line under which a vertex is dropped.

    Returns
    -------
    (j, 2) ndarray
        The corners (at least three vertices stay).
    """
    local = ring - ring.min(axis=0)
    before, after = np.roll(local, 1, axis=0), np.roll(local, -1, axis=0)
    chord = after - before
    cross = chord[:, 0] * (local[:, 1] - before[:, 1]) - chord[:, 1] * (local[:, 0] - before[:, 0])
    off = np.abs(cross) / np.maximum(np.hypot(*chord.T), np.finfo(float).tiny)
    corner = keep | (off > tol)
    if np.count_nonzero(corner) < 3:
        return ring
    return ring[corner]
