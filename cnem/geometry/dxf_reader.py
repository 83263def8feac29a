"""A 2-D domain from a DXF drawing (read with ezdxf).

* **Outlines** from the model space: closed LWPOLYLINE / 2-D POLYLINE (bulges
  included) and CIRCLE entities are rings as they are; LINE, ARC, open polylines,
  ELLIPSE and SPLINE pieces are joined end to end into rings (ends closer than
  `cnem.config.SNAP_TOL` times the drawing's diagonal meet). A ring inside a shell
  is its hole, a ring inside a hole a new region.
* **Arcs** (ARC, CIRCLE, bulges) become equal chords with their vertices on the arc,
  as many as keep every chord within ``chord_tolerance`` times the drawing's diagonal
  of the arc (default `cnem.config.CHORD_TOLERANCE`) and at least
  `cnem.config.ARC_MIN_PIECES` per full turn: a circle of radius ``r`` about ``c``
  gives ``cnem.geometry.arc(c, r, 0, 2 pi, pieces=n)`` less its repeated end.
* **Named boundaries**: each layer with outline pieces, named after the layer
  (``"0"``, the default layer, included).

Text, dimensions, hatches, points and block references carry no outline and are
left out (logged).
"""

from __future__ import annotations

import logging
import os

import numpy as np

from .. import config
from ..errors import FormatError, GeometryError
from .outlines import chain_pieces, outline_tolerance, polygons_from_rings
from .pslg import _merge_vertices

__all__ = ["read_dxf", "arc_pieces"]

log = logging.getLogger(__name__)

#: The entity types that make outlines.
OUTLINE_TYPES = ("LINE", "ARC", "CIRCLE", "LWPOLYLINE", "POLYLINE", "ELLIPSE", "SPLINE")


def arc_pieces(radius: float, sweep: float, sagitta: float) -> int:
    """The number of equal chords of an arc: each within ``sagitta`` of the arc, and at
    least `cnem.config.ARC_MIN_PIECES` per full turn.

    Parameters
    ----------
    radius, sweep, sagitta : float
        The arc's radius, its angle in radians (either sign), the largest distance.
    """
    step = 2 * np.arccos(max(1.0 - sagitta / radius, -1.0))
    turn = abs(sweep) / (2 * np.pi)
    return max(1, int(np.ceil(turn * config.ARC_MIN_PIECES - 1e-9)),
               int(np.ceil(abs(sweep) / step - 1e-9)))


def _arc(center, radius, start, sweep, sagitta):
    """Vertices of an arc from angle ``start`` over ``sweep`` (radians), ends included."""
    t = np.linspace(start, start + sweep, arc_pieces(radius, sweep, sagitta) + 1)
    return np.asarray(center, dtype=float) + radius * np.column_stack([np.cos(t), np.sin(t)])


def _bulge(p, q, bulge, sagitta):
    """Vertices from ``p`` to ``q`` (ends excluded) of a polyline segment with a bulge."""
    if bulge == 0:
        return np.empty((0, 2))
    theta = 4 * np.arctan(bulge)                 # the included angle, > 0 counter-clockwise
    chord = q - p
    length = np.hypot(*chord)
    left = np.array([-chord[1], chord[0]]) / length
    center = 0.5 * (p + q) + left * (0.5 * length / np.tan(0.5 * theta))
    start = np.arctan2(*(p - center)[::-1])
    return _arc(center, np.hypot(*(p - center)), start, theta, sagitta)[1:-1]


def _to_wcs(entity, xy):
    """OCS points ``(k, 2)`` of a planar entity in world x-y (mirrored drawings have the
    extrusion (0, 0, -1))."""
    extrusion = tuple(entity.dxf.get("extrusion", (0.0, 0.0, 1.0)))
    if extrusion == (0.0, 0.0, 1.0):
        return xy
    # the elevation moves points along z only, which the plane drops
    return np.array([(v.x, v.y) for v in entity.ocs().points_to_wcs([(x, y, 0.0) for x, y in xy])])


def _polyline(entity, vertices, closed, sagitta):
    """``(x, y, bulge)`` vertices of a polyline as points, arcs flattened."""
    vertices = np.asarray(vertices, dtype=float).reshape(-1, 3)
    count = len(vertices) if closed else len(vertices) - 1
    out = []
    for k in range(count):
        p, q = vertices[k, :2], vertices[(k + 1) % len(vertices), :2]
        out += [p[None], _bulge(p, q, vertices[k, 2], sagitta)]
    if not closed:
        out.append(vertices[-1:, :2])
    return _to_wcs(entity, np.concatenate(out)), closed


def _piece(entity, sagitta):
    """``(points (k, 2), closed)`` of one outline entity."""
    kind, dxf = entity.dxftype(), entity.dxf
    if kind == "LINE":
        return np.array([(dxf.start.x, dxf.start.y), (dxf.end.x, dxf.end.y)]), False
    if kind in ("ARC", "CIRCLE"):
        start = np.radians(dxf.start_angle) if kind == "ARC" else 0.0
        sweep = (np.radians(dxf.end_angle) - start) % (2 * np.pi) if kind == "ARC" else 2 * np.pi
        pts = _arc((dxf.center.x, dxf.center.y), dxf.radius, start, sweep or 2 * np.pi, sagitta)
        return _to_wcs(entity, pts[:-1] if kind == "CIRCLE" else pts), kind == "CIRCLE"
    if kind == "LWPOLYLINE":
        return _polyline(entity, list(entity.get_points("xyb")), entity.closed, sagitta)
    if kind == "POLYLINE":
        if not entity.is_2d_polyline:
            raise FormatError(f"a 3-D POLYLINE or mesh on layer {dxf.layer!r}; expected 2-D "
                              "outlines: draw it as an LWPOLYLINE in the x-y plane")
        vertices = [(v.dxf.location[0], v.dxf.location[1], v.dxf.bulge) for v in entity.vertices]
        return _polyline(entity, vertices, entity.is_closed, sagitta)
    pts = np.array([(v.x, v.y) for v in entity.flattening(sagitta)], dtype=float)   # curves
    closed = len(pts) > 2 and np.array_equal(pts[0], pts[-1])
    return (pts[:-1] if closed else pts), closed


def _read(path):
    import ezdxf
    try:
        return ezdxf.readfile(path)
    except OSError as exc:
        raise FormatError(f"{path}: cannot open it ({exc}); expected a readable DXF file") \
            from None
    except ezdxf.DXFError as exc:
        raise FormatError(f"{path}: not a DXF drawing ezdxf can read ({exc}); save it again "
                          "as DXF (ASCII, R12 or later)") from None


def _pieces(doc, path, chord_tolerance):
    """``(points, closed, layer)`` of every outline entity of the model space."""
    from ezdxf import bbox
    msp = doc.modelspace()
    entities = [e for e in msp if e.dxftype() in OUTLINE_TYPES]
    ignored = sorted({e.dxftype() for e in msp} - set(OUTLINE_TYPES))
    if ignored:
        log.info("%s: left out the entities without an outline: %s", path, ", ".join(ignored))
    if not entities:
        raise FormatError(f"{path}: the model space holds no outline (LINE, ARC, CIRCLE, "
                          f"LWPOLYLINE, POLYLINE, ELLIPSE, SPLINE); received only "
                          f"{', '.join(ignored) or 'nothing'}")
    box = bbox.extents(entities, fast=True)
    diagonal = float(np.hypot(*(np.asarray(box.extmax) - np.asarray(box.extmin))[:2]))
    sagitta = chord_tolerance * diagonal
    pieces = []
    for e in entities:
        try:
            pts, closed = _piece(e, sagitta)
        except FormatError as exc:
            raise FormatError(f"{path}: {exc}") from None
        pieces.append((pts, closed, e.dxf.layer))
    return pieces


def read_dxf(path: str | os.PathLike, *, chord_tolerance: float | None = None) -> dict:
    """Regions and named boundaries (layers) of a DXF drawing (see the module).

    Parameters
    ----------
    path : str or os.PathLike
    chord_tolerance : float, optional
        The largest distance of an arc's chords from it, relative to the drawing's
        diagonal (default `cnem.config.CHORD_TOLERANCE`).

    Returns
    -------
    dict
        ``regions`` (list of ``(shell, holes)``), ``boundaries`` (layer -> ``(s, 2, 2)``
        segments), ``region_names`` (None).

    Raises
    ------
    FormatError
        A file ezdxf cannot read, or a drawing with no outline.
    GeometryError
        Open, branching, crossing or self-intersecting outlines.
    """
    tolerance = config.CHORD_TOLERANCE if chord_tolerance is None else float(chord_tolerance)
    if not 0 < tolerance < 1:
        raise FormatError(f"chord_tolerance: expected a fraction of the drawing's diagonal in "
                          f"(0, 1), received {chord_tolerance!r}")
    pieces = _pieces(_read(path), path, tolerance)
    tol = outline_tolerance(np.concatenate([p for p, _, _ in pieces]))
    rings = [p for p, closed, _ in pieces if closed]
    open_pieces = [p for p, closed, _ in pieces if not closed]
    if open_pieces:
        pool = np.concatenate([p[[0, -1]] for p in open_pieces])
        vertices, ends = _merge_vertices(pool, tol)
        for ring in chain_pieces(ends.reshape(-1, 2), str(path), vertices):
            rings.append(np.concatenate([(open_pieces[k] if forward
                                          else open_pieces[k][::-1])[:-1]
                                         for k, forward in ring]))
    boundaries = {}
    for pts, closed, layer in pieces:
        chain = np.concatenate([pts, pts[:1]]) if closed else pts
        boundaries.setdefault(layer, []).append(np.stack([chain[:-1], chain[1:]], axis=1))
    regions = polygons_from_rings(rings, str(path))
    if not regions:
        raise GeometryError(f"{path}: no closed outline found")
    return {"regions": regions,
            "boundaries": {k: np.concatenate(v) for k, v in boundaries.items()},
            "region_names": [None] * len(regions)}
