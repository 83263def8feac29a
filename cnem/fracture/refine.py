"""Refinement that follows the crack tips: rings of nodes about every growing tip.

`grow` keeps a *background* cloud (the user's nodes, the crack vertices and the
nodes along the grown segments, `cnem.fracture.advance.grown_cloud`). The cloud
that is discretized at each increment is the background with, about every
growing tip, a disc of radius ``radius`` in which the background nodes are
replaced by concentric rings: ring ``k`` at radius ``r_k`` carries nodes about
``s(r_k)`` apart, ``s(r) = spacing + (h - spacing) r / radius`` (``h`` the
background spacing), and ``r_{k+1} = r_k + s(r_k)``. The nodes of a ring sit
symmetrically about the crack behind the tip; where a ring crosses a crack, a
hole or the boundary it gets a node on that edge, and its nodes closer than
half their spacing to an edge go. When a tip moves on, its old disc gets the
background nodes back: the cloud keeps the same size as the crack grows, and
away from the tips it is the background cloud. The local update
(`cnem.geometry.model_update.update`) takes any cloud change, so the refined model
equals `discretize` of the refined cloud.

By default (``refine="auto"``) rings go only where the interaction integral needs
them: about a tip whose own crack kinks closer behind it than the discs of `sif`
should reach (`cnem.fracture.discs`: the largest disc stays on the straight last
segment, ``SIF_REACH`` times its length, and holds ``SIF_BEND_SPACINGS`` node
spacings). A disc that spans a kink biases K_II (a 53 degree kink, K_I = K_II: the
sign of K_II flips on a disc three times the last segment), and the
next kink with it, so the run zig-zags; `auto_refinement` grades such tips to
`AUTO_FRACTION` of the straight length. A straight crack gets no rings.

>>> import cnem
>>> from cnem.geometry import rectangle
>>> dom = rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.4, 0.5]]])
>>> base = cnem.nodes.irregular(dom, 0.1, seed=0)
>>> fine = refined_cloud(base, dom.tips, Refinement(spacing=0.025, radius=0.3))
>>> len(fine) > len(base)
True
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np
import shapely
from scipy.spatial import cKDTree

from .. import config
from ..errors import GrowthError
from ..geometry.nodes import from_points
from .discs import clearance

if TYPE_CHECKING:
    from ..geometry.cloud import NodeCloud

__all__ = ["Refinement", "refined_cloud", "as_refinement", "auto_refinement"]

#: Default patch radius, in background spacings.
RADIUS_SPACINGS = 4.0
#: A ring node closer than this many of its spacings to a kept background node (the
#: seam) or to a finer ring node (the discs of two close tips) is dropped.
SEAM = 0.5
#: ``refine="auto"``: tip spacing as a fraction of the straight length behind the tip
#: (the largest disc, ``SIF_REACH`` of it, then holds about 18 spacings: with 9, K varied
#: by 1.5 % over the discs on a kinked DCB path; with 18, below the 1 % of `sif`'s check).
AUTO_FRACTION = 0.05


@dataclasses.dataclass(frozen=True)
class Refinement:
    """Nodes graded towards every growing crack tip.

    Attributes
    ----------
    spacing : float
        Node spacing at the tip (smaller than the background spacing there).
    radius : float, optional
        Radius of the refined disc about each tip, where the spacing has grown
        back to the background one; default `RADIUS_SPACINGS` background spacings.
    """

    spacing: float
    radius: float | None = None

    def __post_init__(self):
        for name in ("spacing", "radius"):
            value = getattr(self, name)
            if value is None and name == "radius":
                continue
            if isinstance(value, bool) or not np.isfinite(value) or value <= 0:
                raise GrowthError(f"Refinement.{name}: expected a positive number, received "
                                  f"{value!r}")


def as_refinement(refine: Refinement | float | str | None) -> Refinement | str | None:
    """``grow``'s ``refine`` argument as a `Refinement` (a number is the tip spacing),
    ``"auto"`` or None."""
    if refine is None or isinstance(refine, Refinement) or (isinstance(refine, str)
                                                             and refine == "auto"):
        return refine
    try:
        return Refinement(float(refine))
    except (TypeError, ValueError):
        raise GrowthError("refine: expected \"auto\", None, a tip spacing or a "
                          f"cnem.fracture.Refinement, received {refine!r}") from None


def auto_refinement(background: NodeCloud, tips: np.ndarray) -> tuple[np.ndarray, Refinement | None]:
    """The tips whose discs would span a kink of their own crack, and the rings they need.

    A tip needs rings when ``SIF_REACH`` times the straight length behind it
    (`cnem.fracture.discs.clearance`) holds fewer than ``SIF_BEND_SPACINGS``
    background spacings there; its tip spacing is `AUTO_FRACTION` of that length.

    Parameters
    ----------
    background : NodeCloud
    tips : (t, 2) array_like
        Crack tips of the background's domain.

    Returns
    -------
    tips : (k, 2) ndarray
        The tips that need rings (possibly none).
    refinement : Refinement or None
        The finest tip spacing over them (None when no tip needs rings).
    """
    dom = background.domain
    need, spacings = [], []
    for tip in np.asarray(tips, dtype=float).reshape(-1, 2):
        at, d = dom.tip_frame(tip)
        straight = clearance(dom, at, d).straight
        if not np.isfinite(straight):
            continue
        h = background_spacing(background, at[None])
        if config.SIF_REACH * straight < config.SIF_BEND_SPACINGS * h:
            need.append(at)
            spacings.append(AUTO_FRACTION * straight)
    if not need:
        return np.empty((0, 2)), None
    return np.array(need), Refinement(min(spacings))


def background_spacing(cloud: NodeCloud, tips: np.ndarray, k: int = 8) -> float:
    """The largest, over the tips, median nominal spacing of the ``k`` nodes nearest a tip."""
    _, idx = cKDTree(cloud.points).query(tips, k=min(k, len(cloud.points)))
    return float(np.median(cloud.spacing[np.atleast_2d(idx)], axis=1).max())


def _rings(tip, back, spacing, h, radius):
    """Ring nodes about ``tip`` ``(p, 2)``, their spacings ``(p,)`` and the rings ``[(r, s)]``."""
    growth = (h - spacing) / radius
    points, spacings, rings = [], [], []
    r = spacing
    while r + 0.5 * min(h, spacing + growth * r) < radius:
        s = min(h, spacing + growth * r)
        n = max(6, int(round(2 * np.pi * r / s)))
        angle = back + (np.arange(n) + 0.5) * (2 * np.pi / n)   # symmetric about the crack
        points.append(tip + r * np.column_stack([np.cos(angle), np.sin(angle)]))
        spacings.append(np.full(n, s))
        rings.append((r, s))
        r += s
    return np.concatenate(points), np.concatenate(spacings), rings


def _crossings(domain, tip, rings):
    """Where the rings cross the domain's edges: points ``(q, 2)`` and spacings ``(q,)``."""
    edges = shapely.multilinestrings(
        [[domain.pslg.vertices[a], domain.pslg.vertices[b]] for a, b in domain.pslg.edges])
    points, spacings = [], []
    for r, s in rings:
        circle = shapely.Point(tip).buffer(r, quad_segs=max(16, int(np.ceil(2 * r / s)) * 8))
        hit = shapely.get_coordinates(shapely.intersection(circle.exterior, edges))
        points.append(hit)
        spacings.append(np.full(len(hit), s))
    return np.concatenate(points).reshape(-1, 2), np.concatenate(spacings)


def refined_cloud(background: NodeCloud, tips: np.ndarray, refinement: Refinement) -> NodeCloud:
    """The background cloud with rings of nodes about every crack tip.

    Parameters
    ----------
    background : NodeCloud
        Every vertex of its domain is a node of it.
    tips : (t, 2) array_like
        Crack tips of the background's domain to refine about (none:
        ``background`` itself).
    refinement : Refinement

    Returns
    -------
    NodeCloud
        The background nodes farther than ``radius`` from every tip, every vertex
        of the domain, and the ring nodes (inside the domain, clear of its edges,
        not closer than half their spacing to another node), with their nominal
        spacings.

    Raises
    ------
    GrowthError
        A tip spacing not smaller than the background spacing, or a radius
        smaller than the spacing difference (the spacing would grow faster than
        its own size per unit distance).
    """
    tips = np.asarray(tips, dtype=float).reshape(-1, 2)
    if len(tips) == 0:
        return background
    dom = background.domain
    h = background_spacing(background, tips)
    radius = RADIUS_SPACINGS * h if refinement.radius is None else refinement.radius
    if refinement.spacing >= h:
        raise GrowthError(f"Refinement.spacing = {refinement.spacing:g}: expected a spacing "
                          f"smaller than the background spacing {h:g} at the tips")
    if radius < h - refinement.spacing:
        raise GrowthError(f"Refinement.radius = {radius:g}: expected at least the spacing "
                          f"difference {h - refinement.spacing:g} (a spacing that grows by at "
                          "most its own size per unit distance)")
    new, new_h = [], []
    for tip in tips:
        at, d = dom.tip_frame(tip)
        pts, sp, rings = _rings(at, np.arctan2(-d[1], -d[0]), refinement.spacing, h, radius)
        inside = dom.region_of(pts) >= 0
        pts, sp = pts[inside], sp[inside]
        clear = _clear_of_edges(dom, pts, config.CLEARANCE * sp)
        on_edges, edge_h = _crossings(dom, at, rings)
        new += [pts[clear], on_edges]
        new_h += [sp[clear], edge_h]
    new, new_h = np.concatenate(new), np.concatenate(new_h)
    pts, spacing = background.points, background.spacing
    vertex = cKDTree(dom.pslg.vertices).query(pts)[0] <= dom.tolerance
    keep = (cKDTree(tips).query(pts)[0] >= radius) | vertex
    # drop ring nodes too close to a kept node, or to a finer ring node (overlapping discs)
    order = np.argsort(new_h, kind="stable")
    new, new_h = new[order], new_h[order]
    accepted = cKDTree(pts[keep]).query(new)[0] > SEAM * new_h
    pairs = cKDTree(new).query_pairs(SEAM * new_h.max(), output_type="ndarray")
    pairs = np.sort(pairs, axis=1)
    pairs = pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]
    for i, j in pairs:                    # i is the finer node
        if accepted[i] and np.hypot(*(new[i] - new[j])) <= SEAM * new_h[i]:
            accepted[j] = False
    new, new_h = new[accepted], new_h[accepted]
    out = from_points(dom, np.concatenate([pts[keep], new]))
    given = np.concatenate([spacing[keep], new_h])
    # from_points keeps the given points first and may append midpoints of lonely crack edges
    full = np.concatenate([given, out.spacing[len(given):]])
    return dataclasses.replace(out, spacing=full)


def _clear_of_edges(domain, points, clearance):
    """``(p,)`` bool: points farther than ``clearance`` ``(p,)`` from every edge of the domain."""
    v, e = domain.pslg.vertices, domain.pslg.edges
    tree = shapely.STRtree(shapely.linestrings(np.stack([v[e[:, 0]], v[e[:, 1]]], axis=1)))
    near, _ = tree.query(shapely.points(points), predicate="dwithin", distance=clearance)
    clear = np.ones(len(points), dtype=bool)
    clear[near] = False
    return clear
