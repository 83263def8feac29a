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
When the cracks cut the body apart, `remaining_body` keeps one piece (the
cracks that cut it become its boundary) and `cloud_in` its nodes.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np
import shapely
from scipy.spatial import cKDTree
from shapely.geometry import LineString, MultiLineString, Point
from shapely.ops import nearest_points, split

from ..errors import GeometryError
from ..geometry.domain import Domain
from ..geometry.pslg import segment_projection
from ..geometry.nodes import from_points

if TYPE_CHECKING:
    from typing import Literal, Sequence
    from ..geometry.cloud import NodeCloud

__all__ = ["Hit", "tip_direction", "local_spacing", "first_hit", "grown_cloud", "pieces",
           "check_connected", "rebuilt_domain", "describe", "remaining_body", "cloud_in"]


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
    return _cloud(domain, np.concatenate([pts[keep], new_pts[fresh]]),
                  np.concatenate([spacing[keep], new_h[fresh]]))


def _cloud(domain, points, spacing):
    """`from_points` with the nominal spacing of each given point (the median for the
    vertices it appends: it keeps the given points first)."""
    out = from_points(domain, points)
    full = np.concatenate([spacing, np.full(len(out.points) - len(spacing), np.median(spacing))])
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


def describe(parts: Sequence, which: Sequence[int] | None = None) -> str:
    """``"piece k: area ..., bounds (...), around (x, y)"`` for the pieces ``which``
    (default all) of a list of `pieces`."""
    which = range(len(parts)) if which is None else which
    return "; ".join(
        f"piece {k}: area {parts[k].area:.4g}, bounds "
        f"({', '.join(f'{b:.4g}' for b in parts[k].bounds)}), around "
        f"({parts[k].representative_point().x:.4g}, {parts[k].representative_point().y:.4g})"
        for k in which)


def check_connected(domain: Domain, step: int) -> None:
    """Raise `GeometryError` naming the pieces when the cracks cut the body apart."""
    parts = pieces(domain)
    if len(parts) > 1:
        raise GeometryError(
            f"after step {step} the cracks cut the body into {len(parts)} pieces: "
            f"{describe(parts)}; the run stops here (the crack path so far is in the error's "
            "`history`; grow(..., continue_with=\"largest\") goes on with the largest piece)")


def remaining_body(domain: Domain, piece: shapely.Polygon) -> tuple[Domain, list]:
    """The domain of one piece of a body that the cracks cut apart.

    Each region is split along the cracks and keeps its parts in ``piece``; a crack
    that runs along the piece's boundary becomes boundary, a crack of another piece
    is dropped, the others stay.

    Parameters
    ----------
    domain : Domain
        The body cut apart.
    piece : shapely.Polygon
        One of its `pieces`.

    Returns
    -------
    (Domain, list of int)
        The piece as a domain (regions in the same order) and, for every crack of
        ``domain``, its index among the cracks of the piece (-1 if it is gone).

    Raises
    ------
    GeometryError
        The piece holds none or several parts of a material region (the region
        numbers of ``setup``'s materials would change), or a crack lies partly in
        it and partly on its boundary or outside.
    """
    tol = domain.tolerance
    lines = MultiLineString([np.asarray(c) for c in domain.cracks])
    regions = []
    for r, region in enumerate(domain.regions):
        parts = [g for g in split(region, lines).geoms
                 if g.intersection(piece).area > 0.5 * g.area]
        if len(parts) != 1:
            raise GeometryError(
                f"continue_with: the piece kept holds {len(parts)} parts of material region {r}; "
                "expected exactly one (a region dropped or in several parts would renumber the "
                "regions of setup's materials); continue with another piece or stop at the split")
        regions.append(parts[0])
    kept = shapely.union_all(regions)
    edge, inside, interior = kept.boundary.buffer(tol), kept.buffer(tol), kept.buffer(-tol)
    index, cracks = [], []
    for j, c in enumerate(domain.cracks):
        line = LineString(c)
        if edge.contains(line) or not line.intersects(interior):
            index.append(-1)                     # boundary of the piece now, or elsewhere
        elif inside.contains(line):
            index.append(len(cracks))
            cracks.append(np.asarray(c))
        else:
            raise GeometryError(
                f"continue_with: crack {j} lies partly inside the piece kept and partly on its "
                "boundary or outside it; such a piece is not a Domain cnem can represent, stop at "
                "the split instead")
    return Domain(regions, cracks=cracks), index


def cloud_in(cloud: NodeCloud, domain: Domain) -> NodeCloud:
    """The nodes of ``cloud`` in (or on the boundary of) ``domain``, as its cloud."""
    near = shapely.dwithin(shapely.points(cloud.points), domain.polygon, domain.tolerance)
    return _cloud(domain, cloud.points[near], cloud.spacing[near])


def rebuilt_domain(domain: Domain, cracks: Sequence[np.ndarray]) -> Domain:
    """The same regions (their names and named boundaries kept) with new crack polylines."""
    return Domain(list(domain.regions), cracks=[np.asarray(c) for c in cracks],
                  boundaries={name: domain.boundary_segments(name) for name in domain.boundaries},
                  region_names=domain.region_names)
