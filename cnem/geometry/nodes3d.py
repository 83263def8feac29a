"""Node clouds on a `Domain3D`: regular, irregular, or the user's own points.

`cnem.nodes.regular`, `irregular`, `graded` and `from_points` call these for a 3-D domain.
Every input vertex is a node; feature edges and planar patches of the surface get
nodes about ``h`` apart (`cnem.geometry.surface_nodes`), the inside a cubic lattice
kept half a spacing from the surface. The cloud carries the triangulation of its
boundary nodes (``boundary_faces``), which tiles every input face.

>>> import cnem
>>> from cnem.geometry import box
>>> cloud = cnem.nodes.regular(box(), 0.25)
>>> len(cloud.points), len(cloud.boundary_faces)
(125, 192)
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial import cKDTree

from .. import config
from ..errors import GeometryError, check_points, check_real
from .cloud import NodeCloud
from .domain3d import Domain3D
from .spacing import (SpacingLaw, check_grading, check_node_count, check_seed, check_spacing,
                      point_spacing)
from .surface_nodes import sample_surface, surface_patches
from .surface_queries import faces_within

__all__ = ["regular", "irregular", "graded", "from_points"]


def _check_uniform_count(dom, h, caller):
    estimate = dom.volume / h**3 + dom.area / h**2
    check_node_count(estimate, f"{caller} with h = {h:g}",
                     f"h >= {(dom.volume / config.MAX_NODES) ** (1 / 3):.3g}")


def _interior(dom, law, offset, rng, jitter):
    """Lattice points of ``law`` (local frame) inside ``dom``, each moved by up to
    ``jitter`` times its spacing with ``rng``, kept half a spacing from the surface;
    in global coordinates."""
    lo, hi = dom.local_vertices.min(axis=0), dom.local_vertices.max(axis=0)
    grid = law.lattice(lo, hi, offset=offset)
    if rng is not None:
        grid = grid + rng.uniform(-jitter, jitter, grid.shape) * law(grid)[:, None]
    points = dom.to_global(grid)
    clear = config.CLEARANCE * law(grid) * dom.size * (1 - 1e-9)
    inside = dom.region_of(points) >= 0
    inside[inside] = ~dom.near_surface(points[inside], clear[inside])
    return points[inside]


def _assemble(dom, surface, interior, spacing):
    nodes, faces, regions, segments, kinds = surface
    points = np.concatenate([dom.to_global(nodes), interior])
    points[:len(dom.vertices)] = dom.vertices       # the domain's own, bit for bit
    return NodeCloud(dom, points, segments, kinds, spacing(points), faces, regions)


def regular(domain: Domain3D, h: float) -> NodeCloud:
    """Cubic lattice of spacing ``h`` inside, surface nodes every ~h.

    Parameters
    ----------
    domain : Domain3D
    h : float
        Node spacing, ``0 < h < domain.size``.

    Returns
    -------
    NodeCloud
        ``points (n, 3)``: the domain's vertices first, then the other surface nodes,
        then the interior ones; ``boundary_faces (b, 3)`` and ``boundary_face_regions
        (b, 2)`` triangulate the surface nodes.
    """
    h = check_spacing(domain, h)
    _check_uniform_count(domain, h, "regular")
    law = SpacingLaw(h / domain.size)
    return _assemble(domain, sample_surface(domain, law), _interior(domain, law, 0.0, None, 0.0),
                     lambda x: np.full(len(x), h))


def irregular(domain: Domain3D, h: float, *, seed: int = 0) -> NodeCloud:
    """Randomly perturbed lattice of mean spacing ``h`` (reproducible with ``seed``).

    Interior nodes move by up to 0.35 h in each direction, nodes on the feature edges
    by up to 0.2 of their spacing along them, the patches' lattices by up to 0.35 h in
    their plane; vertices stay put.

    Returns
    -------
    NodeCloud
    """
    h = check_spacing(domain, h)
    _check_uniform_count(domain, h, "irregular")
    rng = np.random.default_rng(check_seed(seed))
    law = SpacingLaw(h / domain.size)
    surface = sample_surface(domain, law, rng)
    return _assemble(domain, surface, _interior(domain, law, 0.5, rng, 0.35),
                     lambda x: np.full(len(x), h))


def graded(domain: Domain3D, h: float, *, near: ArrayLike, h_min: float, growth: float = 0.3,
           seed: int | None = None) -> NodeCloud:
    """Nodes whose spacing shrinks from ``h`` to ``h_min`` towards given points.

    The local spacing is ``s(x) = min(h, h_min + growth * d(x))`` with ``d`` the distance
    to the nearest point of ``near``: interior lattices of spacing ``h / 2^k`` where
    ``s`` lies between ``h / 2^(k+1)`` and ``h / 2^k``, the feature edges and patches
    sampled at ``s`` (as the 2-D `cnem.nodes.graded`).

    Parameters
    ----------
    domain : Domain3D
    h : float
    near : (q, 3) array_like
        Refinement centres.
    h_min : float
        Spacing at the centres, ``0 < h_min <= h``.
    growth : float
        Spacing increase per unit distance (0 < growth <= 1).
    seed : int, optional
        When given, interior nodes are perturbed by up to 0.25 s(x).

    Returns
    -------
    NodeCloud
    """
    h, h_min, centres = check_grading(domain, h, h_min, growth, near, 3)
    distinct = len(np.unique(centres, axis=0))
    # the integral of 1 / s^3 over the ball where s < h, per centre
    per_centre = 4 * np.pi / growth**3 * np.log(h / h_min)
    check_node_count(domain.volume / h**3 + domain.area / h**2 + distinct * per_centre,
                     f"graded with h = {h:g}, h_min = {h_min:g}, growth = {growth:g} around "
                     f"{distinct} centres", "a larger h_min or growth, or fewer centres")
    law = SpacingLaw(h / domain.size, h_min=h_min / domain.size, growth=growth,
                     centres=domain.to_local(centres))
    rng = None if seed is None else np.random.default_rng(check_seed(seed))
    return _assemble(domain, sample_surface(domain, law), _interior(domain, law, 0.5, rng, 0.25),
                     lambda x: law(domain.to_local(x)) * domain.size)


def _classify(domain, local):
    """Where the user's points touch the surface: ``(vertex (p,) or -1, edge (p,) or -1,
    t (p,), patch (p,) or -1, snapped (p, 3))`` in the local frame."""
    tol = domain.tolerance / domain.size
    verts = domain.local_vertices
    dv, iv = cKDTree(verts).query(local)
    vertex = np.where(dv <= tol, iv, -1)
    patch_of, edges, face_edge, border = surface_patches(verts, domain.faces,
                                                         domain.face_regions, tol)
    point, face, dist = faces_within(local, verts, domain.faces, tol)
    order = np.lexsort((dist, point))
    point, face = point[order], face[order]
    first = np.unique(point, return_index=True)[1]
    point, face = point[first], face[first]
    point, face = point[vertex[point] < 0], face[vertex[point] < 0]
    edge = np.full(len(local), -1)
    t = np.zeros(len(local))
    patch = np.full(len(local), -1)
    snapped = local.copy()
    snapped[vertex >= 0] = verts[vertex[vertex >= 0]]
    best = np.full(len(point), np.inf)
    for k in range(3):
        e = face_edge[face, k]
        a, b = verts[edges[e, 0]], verts[edges[e, 1]]
        s = np.clip(np.einsum("ij,ij->i", local[point] - a, b - a)
                    / np.einsum("ij,ij->i", b - a, b - a), 0.0, 1.0)
        d = np.linalg.norm(local[point] - a - s[:, None] * (b - a), axis=1)
        take = border[e] & (d <= tol) & (d < best)
        best[take] = d[take]
        edge[point[take]], t[point[take]] = e[take], s[take]
        snapped[point[take]] = (a + s[:, None] * (b - a))[take]
    inside = point[edge[point] < 0]
    f = face[edge[point] < 0]
    patch[inside] = patch_of[f]
    a = verts[domain.faces[f, 0]]
    n = np.cross(verts[domain.faces[f, 1]] - a, verts[domain.faces[f, 2]] - a)
    n /= np.linalg.norm(n, axis=1)[:, None]
    snapped[inside] = local[inside] - np.einsum("ij,ij->i", local[inside] - a, n)[:, None] * n
    return vertex, edge, t, patch, snapped


def from_points(domain: Domain3D, points: ArrayLike, *, fill: bool = True) -> NodeCloud:
    """The user's own nodes, with the surface nodes they lack.

    Points within ``domain.tolerance`` of the surface are snapped onto it (onto a vertex,
    then a feature edge, then a face). Every input vertex is a node; with ``fill=True``
    (the default) the feature edges and the surface patches get nodes at the user's
    median spacing ``s`` (the mean distance to the `cnem.config.SPACING_NEIGHBOURS` nearest
    others) where no user's point lies within ``cnem.config.FILL_SPACINGS / 2 * s`` (gaps
    wider than `cnem.config.FILL_SPACINGS` spacings are filled, as along the 2-D edges).

    Parameters
    ----------
    domain : Domain3D
    points : (p, 3) array_like
    fill : bool
        Add surface nodes (else only the missing vertices).

    Returns
    -------
    NodeCloud
        ``points[:p]`` are the user's points (snapped) in their order; missing vertices and
        the filled surface nodes follow.

    Raises
    ------
    GeometryError
        Points outside the domain, or duplicated (closer than the tolerance).
    """
    pts = check_points("points", check_real("points", points, error=GeometryError), dims=(3,),
                       error=GeometryError)
    local = domain.to_local(pts)
    vertex, edge, t, patch, snapped = _classify(domain, local)
    on_surface = (vertex >= 0) | (edge >= 0) | (patch >= 0)
    outside = np.flatnonzero(~on_surface & (domain.region_of(pts) < 0))
    if outside.size:
        raise GeometryError(
            f"{outside.size} of {len(pts)} points lie outside the domain, first (index: point) "
            + ", ".join(f"{i}: {pts[i].tolist()}" for i in outside[:5])
            + "; remove them or enlarge the domain")
    pairs = cKDTree(snapped).query_pairs(domain.tolerance / domain.size, output_type="ndarray")
    if len(pairs):
        raise GeometryError(
            f"{len(pairs)} pairs of duplicated points (closer than {domain.tolerance:.3g}), first "
            + ", ".join(f"{i} and {j}" for i, j in pairs[:5]) + "; remove the duplicates")
    spacing = point_spacing(pts)
    finite = spacing[np.isfinite(spacing)]
    h = float(np.median(finite)) if len(finite) else 0.1 * domain.size
    pin = np.flatnonzero((edge >= 0) | (patch >= 0))
    surface = sample_surface(domain, SpacingLaw(h / domain.size), None,
                             (snapped[pin], edge[pin], t[pin], patch[pin]), fill,
                             0.5 * config.FILL_SPACINGS * h / domain.size)
    nodes, faces, regions, segments, kinds = surface
    k, q = len(domain.vertices), len(pin)
    vertex_node = np.full(k, -1)
    vertex_node[vertex[vertex >= 0]] = np.flatnonzero(vertex >= 0)
    missing = np.flatnonzero(vertex_node < 0)
    vertex_node[missing] = len(pts) + np.arange(len(missing))
    generated = len(nodes) - k - q
    number = np.concatenate([vertex_node, pin,
                             len(pts) + len(missing) + np.arange(generated)])
    snapped_global = domain.to_global(snapped)
    snapped_global[vertex >= 0] = domain.vertices[vertex[vertex >= 0]]
    unchanged = ~on_surface
    snapped_global[unchanged] = pts[unchanged]
    all_points = np.concatenate([snapped_global, domain.vertices[missing],
                                 domain.to_global(nodes[k + q:])])
    nn = cKDTree(all_points).query(all_points, k=2)[0][:, 1]
    return NodeCloud(domain, all_points, number[segments], kinds, nn, number[faces], regions)
