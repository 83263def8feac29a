"""One crack increment in the geometry: where a new segment ends, what it meets,
and the node cloud of the grown domain.

A new segment runs from the tip at the kink angle for the tip's increment. It
is cut where it meets the outer boundary, a hole or another crack; when it ends
or passes within ``clearance`` local spacings of the boundary it is carried on
to it, to the boundary point nearest to the segment (no ligament thinner than
the nodes can resolve). Meeting another crack's tip
joins the two cracks into one polyline. The cloud keeps its nodes, but those
closer than ``clearance`` local spacings to a new segment, and gets nodes
along each new segment about one local spacing apart (the new tip among them).
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np
import shapely
from scipy.spatial import cKDTree
from shapely.geometry import LineString, Point
from shapely.ops import nearest_points

from ..errors import GeometryError
from ..geometry.domain import Domain
from ..geometry.pslg import segment_projection
from ..nodes import from_points

if TYPE_CHECKING:
    from typing import Literal, Sequence
    from ..geometry.cloud import NodeCloud

__all__ = ["Hit", "tip_direction", "local_spacing", "first_hit", "grown_cloud", "pieces",
           "check_connected", "rebuilt_domain"]


@dataclasses.dataclass(frozen=True)
class Hit:
    """What a new segment meets first.

    Attributes
    ----------
    kind : {"boundary", "hole", "crack", "joined"} or None
    distance : float
        From the tip, along the segment.
    point : (2,) ndarray
    crack : int
        The crack met (``kind`` "crack" or "joined"), else -1.
    end : int
        ``0`` or ``-1``: the end of that crack that was met ("joined").
    """

    kind: str | None
    distance: float
    point: np.ndarray
    crack: int = -1
    end: int = 0


def tip_direction(crack: np.ndarray, end: Literal[0, -1]) -> np.ndarray:
    """Unit direction of a crack polyline out of its end ``end`` (0 or -1)."""
    d = crack[0] - crack[1] if end == 0 else crack[-1] - crack[-2]
    return d / np.hypot(*d)


def local_spacing(cloud: NodeCloud, point: np.ndarray, k: int = 8) -> float:
    """Median nominal spacing of the ``k`` cloud nodes nearest to a point."""
    _, idx = cKDTree(cloud.points).query(point, k=min(k, len(cloud.points)))
    return float(np.median(cloud.spacing[np.atleast_1d(idx)]))


def _rings(domain):
    """``[(ring LineString, "boundary" or "hole")]`` of the union of the regions."""
    geoms = getattr(domain.polygon, "geoms", [domain.polygon])
    out = []
    for g in geoms:
        out.append((g.exterior, "boundary"))
        out.extend((r, "hole") for r in g.interiors)
    return out


def _points_of(geom):
    if geom.is_empty:
        return np.empty((0, 2))
    parts = getattr(geom, "geoms", [geom])
    return np.concatenate([np.asarray(p.coords, dtype=float)[:, :2] for p in parts])


def first_hit(domain: Domain, cracks: list, crack: int, end: int, start: np.ndarray,
              stop: np.ndarray, reach: float) -> Hit:
    """The first thing the segment ``start -> stop`` (prolonged by ``reach``) meets.

    Parameters
    ----------
    domain : Domain
    cracks : list of (k, 2) ndarray
        All crack polylines (the growing one included, not yet grown).
    crack, end : int
        The growing crack and its growing end.
    start, stop : (2,) ndarray
        The tip and the planned new tip.
    reach : float
        Prolongation: a boundary or crack tip this close beyond ``stop`` is met.

    Returns
    -------
    Hit
    """
    length = float(np.hypot(*(stop - start)))
    e = (stop - start) / length
    probe = LineString([start, start + (length + reach) * e])
    tol = domain.tolerance
    best = Hit(None, np.inf, stop)
    segment = LineString([start, stop])
    for ring, kind in _rings(domain):
        crossings = _points_of(probe.intersection(ring))
        for p in crossings:
            s = float((p - start) @ e)
            if tol < s < best.distance:
                best = Hit(kind, s, p)
        if len(crossings) == 0 and segment.distance(ring) < reach:   # grazes it: a thin ligament
            on_segment, on_ring = (np.asarray(q.coords[0]) for q in nearest_points(segment, ring))
            s = float((on_segment - start) @ e)
            if tol < s < best.distance:
                best = Hit(kind, float(np.hypot(*(on_ring - start))), on_ring)
    for j, c in enumerate(cracks):
        line = c[:-1] if (j == crack and end == -1) else c[1:] if j == crack else c
        if len(line) < 2:
            continue
        for p in _points_of(probe.intersection(LineString(line))):
            s = float((p - start) @ e)
            if tol < s < best.distance:
                best = Hit("crack", s, p, j)
        if j == crack:
            continue
        for other_end in (0, -1):                # a tip ahead, within reach of the segment
            t, dist = segment_projection(c[other_end], start, start + (length + reach) * e)
            s = float(t[0]) * (length + reach)        # along the probe, not the line beyond it
            if dist[0] < reach and tol < s < min(best.distance + reach, length + reach) \
                    and domain.polygon.boundary.distance(Point(c[other_end])) > tol:
                best = Hit("joined", s, c[other_end].copy(), j, other_end)
    if best.kind == "crack" and best.crack != crack:
        c = cracks[best.crack]
        for other_end in (0, -1):
            if np.hypot(*(c[other_end] - best.point)) < reach and \
                    domain.polygon.boundary.distance(Point(c[other_end])) > tol:
                best = Hit("joined", best.distance, c[other_end].copy(), best.crack, other_end)
    return best


def grown_cloud(cloud: NodeCloud, domain: Domain, segments: list, spacings: list,
                clearance: float) -> NodeCloud:
    """The node cloud of the grown domain.

    Parameters
    ----------
    cloud : NodeCloud
        Of the domain before growing.
    domain : Domain
        The grown domain.
    segments : list of ((2,) ndarray, (2,) ndarray)
        The new crack segments ``(start, end)``.
    spacings : list of float
        Local node spacing at each segment.
    clearance : float
        Nodes closer than ``clearance * spacing`` to a new segment are dropped
        (the vertices of the grown domain are kept).

    Returns
    -------
    NodeCloud
    """
    pts, spacing = cloud.points, cloud.spacing
    keep = np.ones(len(pts), dtype=bool)
    vertices = cKDTree(domain.pslg.vertices)
    is_vertex = vertices.query(pts)[0] <= domain.tolerance
    new_pts, new_h = [], []
    for (a, b), h in zip(segments, spacings):
        t, dist = segment_projection(pts, a, b)
        t = np.clip(t, 0.0, 1.0)
        gap = np.hypot(*(pts - (a + t[:, None] * (b - a))).T)
        keep &= (gap >= clearance * h) | is_vertex
        pieces = max(1, int(round(np.hypot(*(b - a)) / h)))
        along = a + (np.arange(1, pieces + 1) / pieces)[:, None] * (b - a)
        new_pts.append(along)
        new_h.append(np.full(pieces, h))
    new_pts, new_h = np.concatenate(new_pts), np.concatenate(new_h)
    fresh = cKDTree(pts[keep]).query(new_pts)[0] > domain.tolerance   # a joined tip is a node
    twice = cKDTree(new_pts).query_pairs(domain.tolerance, output_type="ndarray")
    fresh[twice.max(axis=1)] = False          # two tips that met in this step: one node
    points = np.concatenate([pts[keep], new_pts[fresh]])
    given = np.concatenate([spacing[keep], new_h[fresh]])
    out = from_points(domain, points)
    # from_points keeps the given points first and appends missing vertices
    full = np.concatenate([given, np.full(len(out.points) - len(given), np.median(given))])
    return dataclasses.replace(out, spacing=full)


def pieces(domain: Domain) -> list:
    """The connected pieces of a domain cut along its cracks.

    Returns
    -------
    list of shapely.Polygon
        Largest first.
    """
    if not domain.cracks:
        return [domain.polygon]
    cut = shapely.union_all([LineString(c) for c in domain.cracks]).buffer(10 * domain.tolerance)
    rest = domain.polygon.difference(cut)
    parts = [g for g in getattr(rest, "geoms", [rest]) if g.area > 1e-9 * domain.area]
    return sorted(parts, key=lambda g: -g.area)


def check_connected(domain: Domain, step: int) -> None:
    """Raise `GeometryError` naming the pieces when the cracks cut the body apart."""
    parts = pieces(domain)
    if len(parts) > 1:
        names = "; ".join(
            f"piece {k}: area {g.area:.4g}, bounds ({', '.join(f'{b:.4g}' for b in g.bounds)}), "
            f"around ({g.representative_point().x:.4g}, {g.representative_point().y:.4g})"
            for k, g in enumerate(parts))
        raise GeometryError(
            f"after step {step} the cracks cut the body into {len(parts)} pieces: {names}; the "
            "run stops here (the crack path so far is in the error's `history`)")


def rebuilt_domain(domain: Domain, cracks: Sequence[np.ndarray]) -> Domain:
    """The same regions with new crack polylines."""
    return Domain(list(domain.regions), cracks=[np.asarray(c) for c in cracks])
