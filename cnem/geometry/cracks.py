"""Opening cracks by node duplication.

Each crack node except a tip becomes one node per crack face; the triangles on
each side of the crack attach to that side's copy, so no triangle edge crosses
the crack and the crack faces become boundaries of the triangulation.
"""

from __future__ import annotations

import numpy as np

from ..errors import GeometryError
from .pslg import BOUNDARY, CRACK
from ._mesh_kernels import edge_triangles
from .topology import vertex_triangles

__all__ = ["split_cracks"]


def _fan_groups(v, fan, triangles, crack_neighbors):
    """Group the triangles around node ``v`` into sides separated by crack segments.

    Two triangles of the fan are on the same side when they share an edge
    ``(v, w)`` that is not a crack segment.
    """
    by_other = {}
    for k, t in enumerate(fan):
        for w in triangles[t].tolist():
            if w != v:
                by_other.setdefault(w, []).append(k)
    root = list(range(len(fan)))         # union-find over the fan: root[k] <= k

    def find(k):
        for _ in range(len(fan)):
            if root[k] == k:
                break
            k = root[k]
        return k

    for w, ks in by_other.items():
        if len(ks) == 2 and w not in crack_neighbors:
            a, b = find(ks[0]), find(ks[1])
            root[max(a, b)] = min(a, b)
    groups = {}
    for k, t in enumerate(fan):
        groups.setdefault(find(k), []).append(t)
    return sorted(groups.values(), key=min)


def split_cracks(points: np.ndarray, triangles: np.ndarray, segments: np.ndarray, kind: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Duplicate crack nodes so that each crack face has its own nodes.

    Parameters
    ----------
    points : (n0, 2) ndarray
    triangles : (t, 3) int64 ndarray
    segments : (s, 2) int64 ndarray
    kind : (s,) int8 ndarray

    Returns
    -------
    nodes : (n, 2) ndarray
    node_of_point : (n,) int64 ndarray
        Index into ``points`` of each node.
    triangles : (t, 3) int64 ndarray
        The same triangles, attached to the copies on their side.
    segments, kind : ndarray
        Constraint segments renumbered; each crack segment appears once per face.
    """
    crack = segments[kind == CRACK]
    n0 = len(points)
    if len(crack) == 0:
        return points.copy(), np.arange(n0), triangles.copy(), segments.copy(), kind.copy()
    degree = np.bincount(crack.ravel(), minlength=n0)
    on_boundary = np.zeros(n0, dtype=bool)
    on_boundary[segments[kind == BOUNDARY].ravel()] = True
    split = np.flatnonzero((degree >= 2) | ((degree == 1) & on_boundary))
    crack_nb = {}
    for a, b in crack:
        crack_nb.setdefault(int(a), set()).add(int(b))
        crack_nb.setdefault(int(b), set()).add(int(a))
    offsets, star = vertex_triangles(triangles, n0)
    new_tri = triangles.copy()
    copies = []
    for v in split:
        fan = star[offsets[v]:offsets[v + 1]].tolist()
        for group in _fan_groups(v, fan, triangles, crack_nb[int(v)])[1:]:
            copy = n0 + len(copies)
            copies.append(int(v))
            g = np.asarray(group)
            new_tri[g] = np.where(triangles[g] == v, copy, new_tri[g])
    node_of_point = np.concatenate([np.arange(n0), np.asarray(copies, dtype=np.int64)])
    # renumber segments through the triangles that carry them (each one's edge
    # opposite vertex k is slot 3 t + k)
    ptr, slot = edge_triangles(np.ascontiguousarray(triangles, dtype=np.int64), offsets, star,
                               np.ascontiguousarray(segments, dtype=np.int64))
    t, k = slot // 3, slot % 3
    seg_new = np.sort(np.column_stack([new_tri[t, (k + 1) % 3], new_tri[t, (k + 2) % 3]]),
                      axis=1).astype(np.int64)
    kind_new = np.repeat(kind, np.diff(ptr)).astype(np.int8)
    _, first = np.unique(seg_new, axis=0, return_index=True)
    first = np.sort(first)
    opened = np.count_nonzero(kind_new[first] == CRACK)
    if opened != 2 * len(crack):
        raise GeometryError(
            f"{2 * len(crack) - opened} crack segments could not be opened: a crack between "
            "two tips needs a node inside it (cnem.nodes adds one; with from_points, put a "
            "point on the crack)")
    return points[node_of_point], node_of_point, new_tri, seg_new[first], kind_new[first]
