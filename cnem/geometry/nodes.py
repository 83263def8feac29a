"""Node clouds on a `Domain`: regular, irregular, graded, or the user's own points.

On a `Domain3D` the same functions build 3-D clouds (`cnem.geometry.nodes3d`).

Every polygon corner, interface vertex and crack vertex is a node; the generated
clouds put nodes about one local spacing apart along every boundary, interface
and crack edge (and at least one inside a crack edge between two tips, so that
the crack can open).

>>> import cnem
>>> from cnem.geometry import rectangle
>>> cloud = cnem.nodes.regular(rectangle(), 0.25)
>>> len(cloud.points)
25
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import shapely
from numpy.typing import ArrayLike
from scipy.spatial import cKDTree

from .. import config
from ..errors import GeometryError, check_real
from . import nodes3d
from .cloud import NodeCloud
from .domain3d import Domain3D
from .pslg import SegmentKind, segment_projection
from .spacing import check_grading
from .spacing import check_node_count as _check_count
from .spacing import count_along as _count_along
from .spacing import check_seed as _check_seed
from .spacing import check_spacing as _check_spacing
from .spacing import point_spacing as _point_spacing
from .._sets import isin

if TYPE_CHECKING:
    from .domain import Domain

__all__ = ["regular", "irregular", "graded", "from_points", "NodeCloud"]

def _uniform_count(dom, h):
    """Nodes of a cloud of spacing ``h``: the area over h^2 and the PSLG's length over h."""
    v, e = dom.pslg.vertices, dom.pslg.edges
    return dom.area / h**2 + np.linalg.norm(v[e[:, 1]] - v[e[:, 0]], axis=1).sum() / h


def _check_uniform_count(dom, h, caller):
    _check_count(_uniform_count(dom, h), f"{caller} with h = {h:g}",
                 f"h >= {np.sqrt(dom.area / config.MAX_NODES):.3g}")


def _edge_lines(dom):
    v, e = dom.pslg.vertices, dom.pslg.edges
    return shapely.linestrings(np.stack([v[e[:, 0]], v[e[:, 1]]], axis=1))


def _tip_to_tip(dom):
    """(e,) bool: crack edges whose both ends are crack tips.

    Such a crack has no node that could be split to open it, so it needs one
    inside (a crack opens by duplicating its non-tip nodes).
    """
    v, edges, kinds = dom.pslg.vertices, dom.pslg.edges, dom.pslg.kind
    if len(dom.tips) == 0:
        return np.zeros(len(edges), dtype=bool)
    is_tip = cKDTree(dom.tips).query(v)[0] <= dom.tolerance
    return (kinds == SegmentKind.CRACK) & is_tip[edges[:, 0]] & is_tip[edges[:, 1]]


def _boundary_nodes(dom, spacing_of, jitter=None):
    """Nodes along every PSLG edge, about ``spacing_of(x)`` apart.

    Returns ``points (n0, 2), segments (s, 2), kind (s,)``.
    """
    v, edges, kinds = dom.pslg.vertices, dom.pslg.edges, dom.pslg.kind
    needs_split = _tip_to_tip(dom)
    points, segments, seg_kind = [v], [], []
    count = len(v)
    for (a, b), k, split in zip(edges, kinds, needs_split):
        pa, pb = v[a], v[b]
        samples, cum = _count_along(pa, pb, spacing_of)
        pieces = max(2 if split else 1, int(round(cum[-1])))
        t = np.interp(np.linspace(0, cum[-1], pieces + 1)[1:-1], cum, samples)
        if jitter is not None and len(t):
            t = np.sort(t + jitter.uniform(-0.2, 0.2, len(t)) / pieces)
        chain = np.concatenate([[a], count + np.arange(len(t)), [b]])
        points.append(pa + t[:, None] * (pb - pa))
        segments.append(np.column_stack([chain[:-1], chain[1:]]))
        seg_kind.append(np.full(len(chain) - 1, k, dtype=np.int8))
        count += len(t)
    return np.concatenate(points), np.concatenate(segments), np.concatenate(seg_kind)


def _keep_interior(dom, pts, clearance):
    """Points inside the domain and farther than ``clearance`` from every constraint.

    ``clearance`` is a number or a ``(p,)`` array aligned with ``pts``.
    """
    inside = dom.region_of(pts) >= 0
    pts = pts[inside]
    # a hair below the clearance, so that lattice rows exactly at it are kept
    # on every side alike whatever the rounding
    clearance = np.broadcast_to(clearance, inside.shape)[inside] * (1 - 1e-9)
    tree = shapely.STRtree(_edge_lines(dom))
    near, _ = tree.query(shapely.points(pts), predicate="dwithin", distance=clearance)
    keep = np.ones(len(pts), dtype=bool)
    keep[near] = False
    return pts[keep]


def _lattice(dom, h, offset=0.0):
    """Square lattice of spacing ``h`` over the domain's bounding box."""
    xmin, ymin, xmax, ymax = dom.bounds
    xs = xmin + offset + h * np.arange(int(np.ceil((xmax - xmin) / h)) + 1)
    ys = ymin + offset + h * np.arange(int(np.ceil((ymax - ymin) / h)) + 1)
    gx, gy = np.meshgrid(xs, ys)
    return np.column_stack([gx.ravel(), gy.ravel()])


def _lattice_near(dom, h, offset, centres, reach):
    """The points of `_lattice` ``(dom, h, offset)`` within a box of half-width
    ``reach`` around each centre (each lattice point once).

    A box per centre, not one around them all: two crack tips far apart at a
    tiny spacing would otherwise fill the whole strip between them.
    """
    xmin, ymin, xmax, ymax = dom.bounds
    corner = np.array([xmin, ymin]) + offset
    top = np.ceil(np.array([xmax - xmin, ymax - ymin]) / h).astype(np.int64)
    lo = np.clip(np.floor((centres - reach - corner) / h), 0, top).astype(np.int64)
    hi = np.clip(np.ceil((centres + reach - corner) / h), 0, top).astype(np.int64)
    boxes = []
    for (i0, j0), (i1, j1) in zip(lo, hi):
        gi, gj = np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1))
        boxes.append(np.column_stack([gi.ravel(), gj.ravel()]))
    ij = np.unique(np.concatenate(boxes), axis=0)
    return np.column_stack([xmin + offset + h * ij[:, 0], ymin + offset + h * ij[:, 1]])


def _assemble(dom, boundary, interior, spacing_of):
    pts_b, segs, kinds = boundary
    points = np.concatenate([pts_b, interior])
    return NodeCloud(dom, points, segs.astype(np.int64), kinds, spacing_of(points))


def regular(domain: Domain, h: float) -> NodeCloud:
    """Square lattice of spacing ``h`` plus boundary nodes every ~h.

    Parameters
    ----------
    domain : Domain or Domain3D
    h : float
        Node spacing, ``0 < h < domain.diameter``.

    Returns
    -------
    NodeCloud
    """
    if isinstance(domain, Domain3D):
        return nodes3d.regular(domain, h)
    h = _check_spacing(domain, h)
    _check_uniform_count(domain, h, "regular")
    spacing_of = lambda x: np.full(len(x), h)  # noqa: E731
    lattice = _lattice(domain, h)
    interior = _keep_interior(domain, lattice, config.CLEARANCE * h)
    return _assemble(domain, _boundary_nodes(domain, spacing_of), interior, spacing_of)


def irregular(domain: Domain, h: float, *, seed: int = 0) -> NodeCloud:
    """Randomly perturbed lattice of mean spacing ``h`` (reproducible with ``seed``).

    Interior nodes are moved by up to 0.35 h in each direction and boundary
    nodes by up to 0.2 of their spacing along their edge; corners stay put.

    Returns
    -------
    NodeCloud
    """
    if isinstance(domain, Domain3D):
        return nodes3d.irregular(domain, h, seed=seed)
    h = _check_spacing(domain, h)
    _check_uniform_count(domain, h, "irregular")
    rng = np.random.default_rng(_check_seed(seed))
    spacing_of = lambda x: np.full(len(x), h)  # noqa: E731
    lattice = _lattice(domain, h, offset=0.5 * h)
    lattice = lattice + rng.uniform(-0.35 * h, 0.35 * h, lattice.shape)
    interior = _keep_interior(domain, lattice, config.CLEARANCE * h)
    boundary = _boundary_nodes(domain, spacing_of, jitter=rng)
    return _assemble(domain, boundary, interior, spacing_of)


def _check_graded_count(dom, h, h_min, growth, centres):
    """Refuse a graded cloud of too many nodes: the uniform part, plus about
    ``2 pi / growth^2 ln(h / h_min)`` nodes around each centre (the integral of
    ``1 / s^2`` over the disc where the spacing ``s = h_min + growth d`` is below h)."""
    distinct = len(np.unique(centres, axis=0))
    per_centre = 2 * np.pi / growth**2 * np.log(h / h_min)
    uniform = _uniform_count(dom, h)
    if uniform > 0.5 * config.MAX_NODES:
        fix = f"h >= {np.sqrt(2 * dom.area / config.MAX_NODES):.3g}"
    else:
        room = (config.MAX_NODES - uniform) / distinct
        fix = (f"h_min >= {h * np.exp(-room * growth**2 / (2 * np.pi)):.3g}, a larger growth "
               "or fewer refinement centres")
    _check_count(uniform + distinct * per_centre,
                 f"graded with h = {h:g}, h_min = {h_min:g}, growth = {growth:g} around "
                 f"{distinct} centres", fix)


def graded(domain: Domain, h: float, *, near: ArrayLike, h_min: float, growth: float = 0.3,
           seed: int | None = None) -> NodeCloud:
    """Nodes whose spacing shrinks from ``h`` to ``h_min`` towards given points.

    The local spacing is ``s(x) = min(h, h_min + growth * d(x))`` with ``d`` the
    distance to the nearest point of ``near`` (crack tips, say).

    Parameters
    ----------
    domain : Domain or Domain3D
    h : float
        Largest spacing.
    near : (q, 2) array_like (``(q, 3)`` on a `Domain3D`)
        Refinement centres.
    h_min : float
        Spacing at the centres, ``0 < h_min <= h``.
    growth : float
        Spacing increase per unit distance (a grading rate, 0 < growth <= 1).
    seed : int, optional
        When given, interior nodes are perturbed by up to 0.25 s(x).

    Returns
    -------
    NodeCloud
    """
    if isinstance(domain, Domain3D):
        return nodes3d.graded(domain, h, near=near, h_min=h_min, growth=growth, seed=seed)
    h, h_min, centres = check_grading(domain, h, h_min, growth, near, 2)
    _check_graded_count(domain, h, h_min, growth, centres)
    tree = cKDTree(centres)

    def spacing_of(x):
        return np.minimum(h, h_min + growth * tree.query(x)[0])

    levels = int(np.floor(np.log2(h / h_min))) if h > h_min else 0
    interior = []
    for k in range(levels + 1):
        hk = h / 2 ** k
        # level k is used only where s(x) < 2 hk, i.e. near the centres
        if k == 0:
            pts = _lattice(domain, hk, offset=0.5 * hk)
        else:
            pts = _lattice_near(domain, hk, 0.5 * hk, centres, (2 * hk - h_min) / growth)
        s = spacing_of(pts)
        level = np.clip(np.floor(np.log2(h / s)), 0, levels)
        interior.append(pts[level == k])
    interior = np.concatenate(interior)
    if seed is not None:
        rng = np.random.default_rng(_check_seed(seed))
        interior = interior + rng.uniform(-0.25, 0.25, interior.shape) * spacing_of(interior)[:, None]
    interior = _keep_interior(domain, interior, config.CLEARANCE * spacing_of(interior))
    return _assemble(domain, _boundary_nodes(domain, spacing_of), interior, spacing_of)


def _fill_edges(domain, pts, seg_of, user_spacing, fill):
    """Nodes along the gaps of each PSLG edge longer than `cnem.config.FILL_SPACINGS`
    local spacings (at each place, the `_point_spacing` of the user's point nearest
    to it, or the distance to that point if larger).

    Returns the new points and the edge each lies on; with ``fill=False`` a gap
    raises a `GeometryError` naming it.
    """
    v, edges, kinds = domain.pslg.vertices, domain.pslg.edges, domain.pslg.kind
    finite = np.isfinite(user_spacing)
    if not finite.any():
        return np.empty((0, 2)), np.empty(0, dtype=np.int64)
    tree = cKDTree(pts[finite])
    spacing = user_spacing[finite]

    def spacing_of(x):
        # a place farther from every point than their spacing lies in a gap of the cloud
        dist, j = tree.query(x)
        return np.maximum(spacing[j], dist)

    new, new_edge, gaps = [], [], []
    for k, (ea, eb) in enumerate(edges):
        on = pts[seg_of == k]
        t = (on - v[ea]) @ (v[eb] - v[ea])
        chain = np.concatenate([v[ea][None], on[np.argsort(t)], v[eb][None]])
        for pa, pb in zip(chain[:-1], chain[1:]):
            samples, cum = _count_along(pa, pb, spacing_of)
            if cum[-1] <= config.FILL_SPACINGS:
                continue
            if not fill:
                gaps.append((kinds[k] != SegmentKind.CRACK, k, pa, pb, cum[-1]))
                continue
            pieces = int(round(cum[-1]))
            t = np.interp(np.linspace(0, cum[-1], pieces + 1)[1:-1], cum, samples)
            new.append(pa + t[:, None] * (pb - pa))
            new_edge.append(np.full(len(t), k, dtype=np.int64))
    if gaps:
        _, k, pa, pb, count = min(gaps, key=lambda g: g[:2])     # cracks first
        kind = SegmentKind(kinds[k])
        harm = ("the crack face there stays straight and cannot open (K_I about half)"
                if kind == SegmentKind.CRACK else "it is integrated coarsely")
        raise GeometryError(
            f"{len(gaps)} gaps along the domain's edges hold no point over more than "
            f"{config.FILL_SPACINGS:g} local spacings, first the {kind.name.lower()} gap from "
            f"{pa.tolist()} to {pb.tolist()} (edge {k}, ~{count:.1f} spacings): {harm}; add "
            "points along it or pass fill=True")
    if not new:
        return np.empty((0, 2)), np.empty(0, dtype=np.int64)
    return np.concatenate(new), np.concatenate(new_edge)


def from_points(domain: Domain, points: ArrayLike, *, fill: bool = True) -> NodeCloud:
    """The user's own nodes, with missing corners and crack vertices added.

    Points within ``domain.tolerance`` of a boundary, interface or crack are
    snapped onto it (onto the vertex if they are that close to one).

    A boundary, interface or crack edge needs nodes along it at about the local
    spacing: a crack face with no node between its tips stays a straight line
    and cannot open (K_I comes out at about half its value), a boundary is
    integrated coarsely. With ``fill=True`` (the default) every gap along an edge
    longer than `cnem.config.FILL_SPACINGS` local spacings (at each place, the
    mean distance of the user's point nearest to it to its
    `cnem.config.SPACING_NEIGHBOURS` nearest others, or the distance to that point
    if larger) gets nodes at that spacing; with ``fill=False`` such a gap is an error naming it.

    Parameters
    ----------
    domain : Domain or Domain3D
    points : (p, 2) array_like (``(p, 3)`` on a `Domain3D`)
    fill : bool
        Fill long gaps along the edges with nodes (else raise).

    Returns
    -------
    NodeCloud
        ``points[:p]`` are the user's points (snapped) in their order; nodes
        filled in along the edges and missing vertices follow.

    Raises
    ------
    GeometryError
        Points outside the domain or duplicated (closer than the tolerance);
        with ``fill=False``, an edge gap longer than `cnem.config.FILL_SPACINGS`
        local spacings.
    """
    if isinstance(domain, Domain3D):
        return nodes3d.from_points(domain, points, fill=fill)
    pts = np.array(check_real("points", points, error=GeometryError), dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise GeometryError(f"points: expected a (p, 2) array, received shape {pts.shape}")
    if not np.isfinite(pts).all():
        bad = np.flatnonzero(~np.isfinite(pts).all(axis=1))
        raise GeometryError(f"points: {len(bad)} rows are not finite, first {bad[:5].tolist()}")
    if len(pts) and np.abs(pts).max() >= config.COORDINATE_LIMIT:
        raise GeometryError(f"points: expected coordinates below {config.COORDINATE_LIMIT:g} in "
                            f"magnitude, received {np.abs(pts).max():g}; express the model in "
                            "other units (the domain's too)")
    tol = domain.tolerance
    v, edges = domain.pslg.vertices, domain.pslg.edges
    # snap onto vertices, then onto edges
    dv, iv = cKDTree(v).query(pts)
    on_vertex = dv <= tol
    pts[on_vertex] = v[iv[on_vertex]]
    tree = shapely.STRtree(_edge_lines(domain))
    pi, ei = tree.query(shapely.points(pts), predicate="dwithin", distance=tol)
    seg_of = np.full(len(pts), -1)
    keep = ~on_vertex[pi]
    pi, ei = pi[keep], ei[keep]
    seg_of[pi] = ei
    a, b = v[edges[ei, 0]], v[edges[ei, 1]]
    t, _ = segment_projection(pts[pi], a, b)
    pts[pi] = a + np.clip(t, 0, 1)[:, None] * (b - a)
    outside = np.flatnonzero((domain.region_of(pts) < 0) & (seg_of < 0) & ~on_vertex)
    if outside.size:
        raise GeometryError(
            f"{outside.size} of {len(pts)} points lie outside the domain, first (index: point) "
            + ", ".join(f"{i}: {pts[i].tolist()}" for i in outside[:5])
            + "; remove them or enlarge the domain")
    pairs = cKDTree(pts).query_pairs(tol, output_type="ndarray")
    if len(pairs):
        raise GeometryError(
            f"{len(pairs)} pairs of duplicated points (closer than {tol:.3g}), first "
            + ", ".join(f"{i} and {j}" for i, j in pairs[:5]) + "; remove the duplicates")
    user_spacing = _point_spacing(pts)
    filled, filled_edge = _fill_edges(domain, pts, seg_of, user_spacing, fill)
    seg_of = np.concatenate([seg_of, filled_edge])
    pts = np.concatenate([pts, filled])
    # a crack edge between two tips with no point on it gets its midpoint
    lonely = np.flatnonzero(_tip_to_tip(domain) & ~isin(np.arange(len(edges)), seg_of))
    mids = 0.5 * (v[edges[lonely, 0]] + v[edges[lonely, 1]])
    seg_of = np.concatenate([seg_of, lonely])
    pts = np.concatenate([pts, mids])
    # the user's points keep their order; missing vertices are appended
    vertex_node = np.full(len(v), -1)
    vertex_node[iv[on_vertex]] = np.flatnonzero(on_vertex)
    missing = np.flatnonzero(vertex_node < 0)
    vertex_node[missing] = len(pts) + np.arange(len(missing))
    all_pts = np.concatenate([pts, v[missing]])
    segments, kinds = [], []
    for k, (ea, eb) in enumerate(edges):
        inside = np.flatnonzero(seg_of == k)
        t = (pts[inside] - v[ea]) @ (v[eb] - v[ea])
        chain = np.concatenate([[vertex_node[ea]], inside[np.argsort(t)], [vertex_node[eb]]])
        segments.append(np.column_stack([chain[:-1], chain[1:]]))
        kinds.append(np.full(len(chain) - 1, domain.pslg.kind[k], dtype=np.int8))
    nn = cKDTree(all_pts).query(all_pts, k=2)[0][:, 1]
    return NodeCloud(domain, all_pts, np.concatenate(segments), np.concatenate(kinds), nn)
