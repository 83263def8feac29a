"""`mesh_domain`: a quality triangle mesh of a domain for the P1 anchor (`triangle`).

Every triangle lies in one region, material interfaces are mesh edges and cracks
are opened (their nodes duplicated, tips excepted), so that crack faces are
traction-free boundaries.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

import numpy as np
import triangle
from shapely.geometry import Polygon

from .. import config
from ..errors import GeometryError, InputError
from ..geometry.cracks import split_cracks
from ..geometry.pslg import BOUNDARY, CRACK

if TYPE_CHECKING:
    from ..geometry.domain import Domain

__all__ = ["mesh_domain"]

log = logging.getLogger(__name__)

#: Segment markers handed to `triangle` are ``kind + _MARK`` (0 and 1 are its own).
_MARK = 2


# ---------------------------------------------------------------------- meshing
def _hole_points(domain):
    """One point inside each connected empty area enclosed by the domain."""
    union = domain.polygon
    pieces = getattr(union, "geoms", [union])
    points = []
    for piece in pieces:
        for ring in piece.interiors:
            empty = Polygon(ring).difference(union)
            for part in getattr(empty, "geoms", [empty]):
                if part.area > 0:
                    points.append(part.representative_point().coords[0])
    return np.asarray(points, dtype=float).reshape(-1, 2)


def _pslg_input(domain):
    """`triangle` input: PSLG vertices and segments (crack edges between two
    tips split at their midpoint so that they can be opened), region seeds, holes."""
    pslg = domain.pslg
    vertices, edges, kind = pslg.vertices, pslg.edges, pslg.kind
    crack = edges[kind == CRACK]
    degree = np.bincount(crack.ravel(), minlength=len(vertices))
    on_boundary = np.zeros(len(vertices), dtype=bool)
    on_boundary[edges[kind == BOUNDARY].ravel()] = True
    fixed = (degree >= 2) | on_boundary
    lone = np.flatnonzero((kind == CRACK) & ~fixed[edges].any(axis=1))
    if lone.size:
        mid = np.arange(len(vertices), len(vertices) + lone.size)
        vertices = np.concatenate([vertices, vertices[edges[lone]].mean(axis=1)])
        halves = np.column_stack([edges[lone, 0], mid, mid, edges[lone, 1]]).reshape(-1, 2)
        keep = np.ones(len(edges), dtype=bool)
        keep[lone] = False
        edges = np.concatenate([edges[keep], halves])
        kind = np.concatenate([kind[keep], np.full(len(halves), CRACK, dtype=kind.dtype)])
    seeds = [[*region.representative_point().coords[0], i, 0.0]
             for i, region in enumerate(domain.regions)]
    data = {"vertices": np.ascontiguousarray(vertices, dtype=float),
            "segments": np.ascontiguousarray(edges, dtype=np.int32),
            "segment_markers": (kind.astype(np.int32) + _MARK)[:, None],
            "regions": np.asarray(seeds, dtype=float)}
    holes = _hole_points(domain)
    if len(holes):
        data["holes"] = holes
    return data


def _number(value):
    """A positive float as `triangle` parses it: digits and a point, no exponent."""
    return np.format_float_positional(float(value), trim="-")


def _triangulate(data, quality, max_area):
    switches = f"pq{_number(quality)}AQ" + ("" if max_area is None else f"a{_number(max_area)}")
    return triangle.triangulate(data, switches)


def mesh_domain(domain: Domain, *, nodes: int | None = None, max_area: float | None = None,
                quality: float = 30.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Quality triangle mesh of a domain, opened along its cracks.

    Parameters
    ----------
    domain : Domain
    nodes : int, optional
        Target node count (before crack opening): starting from a maximum
        triangle area of ``2 * area / nodes``, the area is corrected (at most
        6 meshes) until the count lies within 2 % of the target; a warning is
        logged if the best mesh is more than 5 % off.
    max_area : float, optional
        Maximum triangle area (``triangle``'s ``a`` switch). Give at most one
        of ``nodes`` and ``max_area``; with neither, only the quality bound
        applies (the coarsest quality mesh).
    quality : float
        Minimum angle in degrees (``triangle``'s ``q`` switch), at most 34.

    Returns
    -------
    points : (n, 2) ndarray
        Node coordinates; crack nodes appear once per crack face.
    triangles : (t, 3) int64 ndarray
        Counter-clockwise triangles.
    region : (t,) int64 ndarray
        Region index of each triangle.

    Raises
    ------
    InputError
        Both ``nodes`` and ``max_area`` given, non-positive values, a quality
        above 34 degrees, or a target node count below the coarsest mesh.
    GeometryError
        If a crack cannot be opened.
    """
    if nodes is not None and max_area is not None:
        raise InputError(f"give either nodes or max_area, received nodes={nodes!r} and "
                         f"max_area={max_area!r}; drop one of them")
    if not 0.0 < float(quality) <= 34.0:
        raise InputError(f"quality: expected a minimum angle in (0, 34] degrees, received "
                         f"{quality!r} (triangle may not terminate above 34)")
    if max_area is not None and not float(max_area) > 0.0:
        raise InputError(f"max_area: expected a positive number, received {max_area!r}")
    data = _pslg_input(domain)
    if nodes is None:
        out = _triangulate(data, quality, max_area)
    else:
        out = _mesh_for_nodes(data, domain.area, int(nodes), quality)
    points = out["vertices"]
    tri = out["triangles"].astype(np.int64)
    region = np.rint(out["triangle_attributes"][:, 0]).astype(np.int64)
    ab, ac = points[tri[:, 1]] - points[tri[:, 0]], points[tri[:, 2]] - points[tri[:, 0]]
    flip = ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0] < 0
    tri[flip] = tri[flip][:, [0, 2, 1]]
    segments = out["segments"].astype(np.int64)
    kind = (out["segment_markers"].ravel() - _MARK).astype(np.int8)
    if (kind < 0).any():
        raise GeometryError("triangle returned segments that are not in the domain's PSLG; "
                            "check the domain for crossing boundaries")
    points, _, tri, _, _ = split_cracks(points, tri, segments, kind)
    return points, tri, region


def _mesh_for_nodes(data, area, target, quality):
    """Mesh whose node count is within `cnem.config.MESH_NODES_STOP` of ``target`` if possible
    (secant on ``log count`` against ``log max_area``)."""
    if target < 3:
        raise InputError(f"nodes: expected a target node count >= 3, received {target}")
    coarsest = _triangulate(data, quality, None)
    if len(coarsest["vertices"]) >= (1.0 - config.MESH_NODES_RTOL) * target:
        if len(coarsest["vertices"]) <= (1.0 + config.MESH_NODES_RTOL) * target:
            return coarsest
        raise InputError(f"nodes: the coarsest quality-{quality:g} mesh of this domain already "
                         f"has {len(coarsest['vertices'])} nodes, more than the target {target}; "
                         "ask for more nodes or a coarser domain description")
    tries = []
    max_area = 2.0 * area / target
    for _ in range(config.MESH_NODES_TRIES):
        out = _triangulate(data, quality, max_area)
        count = len(out["vertices"])
        tries.append((abs(count / target - 1.0), count, max_area, out))
        if abs(count / target - 1.0) <= config.MESH_NODES_STOP:
            break
        slope = -1.0
        if len(tries) >= 2 and tries[-1][2] != tries[-2][2] and tries[-1][1] != tries[-2][1]:
            slope = (np.log(tries[-1][1] / tries[-2][1])
                     / np.log(tries[-1][2] / tries[-2][2]))
            slope = min(max(slope, -2.0), -0.5)
        max_area *= (target / count) ** (1.0 / slope)
    best = min(tries, key=lambda item: item[0])
    if best[0] > config.MESH_NODES_RTOL:
        log.warning("mesh_domain: %d nodes for a target of %d (max area %.3g)",
                    best[1], target, best[2])
    log.info("mesh_domain: %d nodes (target %d) after %d meshes", best[1], target, len(tries))
    return best[3]


# ------------------------------------------------------------------------ problem
