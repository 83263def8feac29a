"""Numba kernels that find the constrained Bowyer-Watson cavity of a point in a
tetrahedrisation (arrays and scalars only): point location, the special cases
(at a node, on a constraint face or feature edge) and the cavity itself.

The cavity of ``x`` holds the tetrahedra whose circumsphere holds ``x``
strictly, reached from its tetrahedron across unconstrained faces that ``x``
does not see from behind, then shelled until ``x`` sees every boundary face
from the inside: it is star-shaped from ``x``, so every natural neighbour (a
vertex of the cavity) is visible from ``x``. `cnem.shape._kernels3d` computes
the coordinates from it.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import parallel_kernel

#: Row kinds (``FALLBACK``: barycentric in the tetrahedron, where the cavity's
#: coordinates are not a partition into non-negative weights, see `_kernels3d._bad_row`).
CAVITY, AT_NODE, ON_FACE, ON_EDGE, FALLBACK = 0, 1, 2, 3, 4

#: Largest cavity (tetrahedra); its boundary has at most twice as many faces.
MAX_CAVITY = 1024
#: Faces opposite each vertex of a positive tetrahedron, oriented outwards.
FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]], dtype=np.int64)
#: The six edges (i, j) of a tetrahedron, with (k, l) so that (i, j, k, l) is even.
PAIRS = np.array([[0, 1, 2, 3], [0, 2, 3, 1], [0, 3, 1, 2], [1, 2, 0, 3], [1, 3, 2, 0],
                  [2, 3, 0, 1]], dtype=np.int64)

#: Relative size of a determinant under which a point counts as on a plane (a point
#: that near a constraint face of its tetrahedron is on it).
PLANE_RTOL = 1e-14
#: Relative size of the in-sphere determinant under which a point counts as on a sphere.
SPHERE_RTOL = 1e-14


@numba.njit(cache=True, inline="always")
def _det(ax, ay, az, bx, by, bz, cx, cy, cz):
    return ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx)


@numba.njit(cache=True, inline="always")
def _face_side(nodes, a, b, c, x):
    """``det[a - x, b - x, c - x]`` (> 0: ``x`` on the inner side of the outward face
    ``(a, b, c)``) and its permanent (the scale of its round-off)."""
    ax, ay, az = nodes[a, 0] - x[0], nodes[a, 1] - x[1], nodes[a, 2] - x[2]
    bx, by, bz = nodes[b, 0] - x[0], nodes[b, 1] - x[1], nodes[b, 2] - x[2]
    cx, cy, cz = nodes[c, 0] - x[0], nodes[c, 1] - x[1], nodes[c, 2] - x[2]
    det = _det(ax, ay, az, bx, by, bz, cx, cy, cz)
    la = np.sqrt(ax * ax + ay * ay + az * az)
    lb = np.sqrt(bx * bx + by * by + bz * bz)
    lc = np.sqrt(cx * cx + cy * cy + cz * cz)
    return det, la * lb * lc


@numba.njit(cache=True)
def _in_sphere(nodes, tet, t, x, p):
    """Whether ``x`` lies strictly inside the circumsphere of positive tetrahedron ``t``
    (filtered: when round-off could flip the sign the answer is no, consistently);
    ``p`` is a ``(4, 4)`` work array."""
    for k in range(4):
        v = tet[t, k]
        for d in range(3):
            p[k, d] = nodes[v, d] - x[d]
        p[k, 3] = p[k, 0] * p[k, 0] + p[k, 1] * p[k, 1] + p[k, 2] * p[k, 2]
    det = 0.0
    perm = 0.0
    for k in range(4):                       # expansion along the lifted column
        a, b, c = FACES[k, 0], FACES[k, 1], FACES[k, 2]
        m = _det(p[a, 0], p[a, 1], p[a, 2], p[b, 0], p[b, 1], p[b, 2], p[c, 0], p[c, 1], p[c, 2])
        det += p[k, 3] * m
        perm += p[k, 3] * (abs(p[a, 0]) + abs(p[a, 1]) + abs(p[a, 2])) * \
            (abs(p[b, 0]) + abs(p[b, 1]) + abs(p[b, 2])) * (abs(p[c, 0]) + abs(p[c, 1]) + abs(p[c, 2]))
    # sum_k |p_k|^2 det(outward face opposite k) = -6 volume * power of x: > 0 inside
    return det > SPHERE_RTOL * perm


@numba.njit(cache=True)
def _face_at_edge(tet, nb, t, a, b):
    """A tetrahedron round the edge ``(a, b)`` from ``t`` with a constraint face holding
    the edge: ``(tetrahedron, face)``, or ``(-1, -1)``."""
    prev = -1
    for _ in range(tet.shape[0]):
        moved = False
        for k in range(4):
            v = tet[t, k]
            if v == a or v == b:
                continue
            o = nb[t, k]
            if o < 0:
                return t, k
            if o != prev and not moved:
                nxt = o
                moved = True
        if not moved:
            return -1, -1
        prev, t = t, nxt
    return -1, -1


@numba.njit(cache=True)
def _special(nodes, tet, nb, cedges, features, t, x, tol):
    """Node, constraint-face or feature-edge case: ``(kind, a, b, c, la, lb, lc)``;
    for ``ON_FACE``, ``a`` is the tetrahedron and ``b`` its constraint face holding x."""
    n = nodes.shape[0]
    for k in range(4):
        v = tet[t, k]
        d2 = 0.0
        for d in range(3):
            d2 += (nodes[v, d] - x[d]) ** 2
        if d2 <= tol * tol:
            return AT_NODE, v, v, v, 1.0, 0.0, 0.0
    for k in range(4):
        if nb[t, k] >= 0:
            continue
        a, b, c = tet[t, FACES[k, 0]], tet[t, FACES[k, 1]], tet[t, FACES[k, 2]]
        nrm = np.cross(nodes[b] - nodes[a], nodes[c] - nodes[a])
        r = nodes[a] - x
        dist = (r[0] * nrm[0] + r[1] * nrm[1] + r[2] * nrm[2]) / np.sqrt(
            nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2])
        det, perm = _face_side(nodes, a, b, c, x)
        if abs(dist) > tol and det > PLANE_RTOL * perm:
            continue
        for e in range(3):            # on a feature edge of the face: linear there
            kind, i, j, s = _on_edge(nodes, cedges, features, tet[t, FACES[k, e]],
                                     tet[t, FACES[k, (e + 1) % 3]], x, tol, n)
            if kind == ON_EDGE:
                return ON_EDGE, i, j, j, 1.0 - s, s, 0.0
        return ON_FACE, t, k, -1, 0.0, 0.0, 0.0
    for e in range(6):
        kind, i, j, s = _on_edge(nodes, cedges, features, tet[t, PAIRS[e, 0]],
                                 tet[t, PAIRS[e, 1]], x, tol, n)
        if kind == ON_EDGE:
            return ON_EDGE, i, j, j, 1.0 - s, s, 0.0
        if kind == ON_FACE:
            u, k = _face_at_edge(tet, nb, t, i, j)
            if u >= 0:
                return ON_FACE, u, k, -1, 0.0, 0.0, 0.0
    return CAVITY, -1, -1, -1, 0.0, 0.0, 0.0


@numba.njit(cache=True)
def _on_edge(nodes, cedges, features, a, b, x, tol, n):
    """Whether ``x`` lies on the edge ``(a, b)`` of constraint faces: ``(ON_EDGE, a, b,
    s)`` on a feature edge (``x = a + s (b - a)``), ``(ON_FACE, a, b, s)`` on an edge
    inside a flat patch of constraint faces, else ``(CAVITY, ...)``."""
    ed = _rel(nodes, b, nodes[a])            # the distance first: no search for most
    r = (x[0] - nodes[a, 0], x[1] - nodes[a, 1], x[2] - nodes[a, 2])
    l2 = ed[0] * ed[0] + ed[1] * ed[1] + ed[2] * ed[2]
    s = (r[0] * ed[0] + r[1] * ed[1] + r[2] * ed[2]) / l2
    off2 = 0.0
    for d in range(3):
        off2 += (r[d] - s * ed[d]) ** 2
    if off2 > tol * tol:
        return CAVITY, a, b, 0.0
    key = min(a, b) * n + max(a, b)
    pos = np.searchsorted(cedges, key)
    if pos >= cedges.shape[0] or cedges[pos] != key:
        return CAVITY, a, b, 0.0
    pos = np.searchsorted(features, key)
    if pos < features.shape[0] and features[pos] == key:
        return ON_EDGE, a, b, min(max(s, 0.0), 1.0)
    return ON_FACE, a, b, 0.0


@numba.njit(cache=True)
def _cavity(nodes, tet, nb, t, x, stamp, mark, cav, limit, sph):
    """The star-shaped constrained cavity of ``x`` from tetrahedron ``t``: its size, or
    -1 if it does not fit or has to lose ``t``. ``mark[o] == stamp`` for its members.
    With ``limit`` (``x`` on a constraint face, the cavity of points tending to it
    from inside) faces through ``x`` stay on its boundary."""
    cav[0] = t
    mark[t] = stamp
    size = 1
    head = 0
    while head < size:
        c = cav[head]
        head += 1
        for k in range(4):
            o = nb[c, k]
            if o < 0 or mark[o] == stamp or mark[o] == -stamp:
                continue
            det, perm = _face_side(nodes, tet[c, FACES[k, 0]], tet[c, FACES[k, 1]],
                                   tet[c, FACES[k, 2]], x)
            if det < -PLANE_RTOL * perm:        # x sees the face from behind: not visible
                continue
            if not _in_sphere(nodes, tet, o, x, sph):
                mark[o] = -stamp
                continue
            if size == cav.shape[0]:
                return -1
            mark[o] = stamp
            cav[size] = o
            size += 1
    for _ in range(cav.shape[0]):       # shell: drop tetrahedra with a face x does not face
        dropped = -1
        for m in range(size):
            c = cav[m]
            for k in range(4):
                o = nb[c, k]
                if o >= 0 and mark[o] == stamp:
                    continue
                det, perm = _face_side(nodes, tet[c, FACES[k, 0]], tet[c, FACES[k, 1]],
                                       tet[c, FACES[k, 2]], x)
                if det < -PLANE_RTOL * perm if limit else det <= PLANE_RTOL * perm:
                    dropped = m
                    break
            if dropped >= 0:
                break
        if dropped < 0:
            return size
        if cav[dropped] == t:
            return -1
        mark[cav[dropped]] = -stamp
        size -= 1
        cav[dropped] = cav[size]
    return -1


@numba.njit(cache=True, inline="always")
def _rel(nodes, v, x):
    """``nodes[v] - x`` as a tuple (no array allocated)."""
    return (nodes[v, 0] - x[0], nodes[v, 1] - x[1], nodes[v, 2] - x[2])


@numba.njit(cache=True, inline="always")
def _cross(u, v):
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


@numba.njit(cache=True)
def _walk(nodes, tet, nbw, t, x, max_steps):
    """Walk from tetrahedron ``t`` to the one holding ``x``; -1 if it leaves the
    tetrahedrisation or takes too long (a cycle: the caller searches then)."""
    for _ in range(max_steps):       # across the face x lies farthest behind
        worst, exit_face = 0.0, -1
        for k in range(4):
            det, perm = _face_side(nodes, tet[t, FACES[k, 0]], tet[t, FACES[k, 1]],
                                   tet[t, FACES[k, 2]], x)
            if det < worst * perm:
                worst, exit_face = det / perm, k
        if exit_face < 0:
            return t
        t = nbw[t, exit_face]
        if t < 0:
            return -1
    return -1


@parallel_kernel("points")
def locate_walk(nodes, tet, nbw, points, starts):
    """Tetrahedra holding points, each walked to from its tetrahedron ``starts``
    (a tetrahedron of its nearest node); -1 where the walk leaves the body."""
    out = np.empty(points.shape[0], dtype=np.int64)
    for q in numba.prange(points.shape[0]):
        out[q] = _walk(nodes, tet, nbw, starts[q], points[q], 8192)
    return out


@parallel_kernel("points")
def locate(nodes, tet, points, cand_off, cand_idx, tol):
    """The candidate tetrahedron that contains each point best (-1 if none within
    ``tol``): the largest smallest signed distance to its faces."""
    p = points.shape[0]
    out = np.full(p, -1, dtype=np.int64)
    for q in numba.prange(p):
        best = -np.inf
        for c in range(cand_off[q], cand_off[q + 1]):
            t = cand_idx[c]
            worst = np.inf
            for k in range(4):
                a, b, cc = tet[t, FACES[k, 0]], tet[t, FACES[k, 1]], tet[t, FACES[k, 2]]
                det, perm = _face_side(nodes, a, b, cc, points[q])
                nrm = np.cross(nodes[b] - nodes[a], nodes[cc] - nodes[a])
                worst = min(worst, det / np.sqrt(nrm[0] ** 2 + nrm[1] ** 2 + nrm[2] ** 2))
            if worst > best:
                best = worst
                if worst >= -tol:
                    out[q] = t
    return out
