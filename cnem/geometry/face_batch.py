"""Many single-triangle surface patches filled and triangulated at once.

A curved surface made of small triangles is one patch per face: calling ``triangle``
once per face costs a millisecond each. Here each face is laid out in its own plane
frame, the frames placed side by side on one 2-D canvas, and the whole canvas is
triangulated in a single constrained call (every face's border is a chain of
segments, so no triangle crosses from one face into another; the triangles in the
gaps between faces are dropped).

>>> import numpy as np
>>> from cnem.geometry.face_batch import fill_faces
>>> nodes = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.5, 0, 0]], float)
>>> pieces = np.array([[0, 3], [3, 1], [1, 2], [2, 0]])
>>> tris, _, new = fill_faces(nodes, 4, np.array([[0, 1, 2]]), np.zeros(4, int), pieces, 0.5,
...                           None)
>>> sorted(map(sorted, tris.tolist())), len(new)
([[0, 2, 3], [1, 2, 3]], 0)
"""

from __future__ import annotations

import numpy as np
import triangle

from .. import config

__all__ = ["fill_faces"]


def _frames(corners):
    """Per face: origin (the start of its longest edge), in-plane axes u (along that edge)
    and v = n x u, with n its unit normal."""
    edge = np.roll(corners, -1, axis=1) - corners                       # (m, 3, 3)
    k = np.argmax(np.einsum("mki,mki->mk", edge, edge), axis=1)
    rows = np.arange(len(corners))
    u = edge[rows, k] / np.linalg.norm(edge[rows, k], axis=1)[:, None]
    n = np.cross(edge[:, 0], edge[:, 1])
    n /= np.linalg.norm(n, axis=1)[:, None]
    return corners[rows, k], u, np.cross(n, u)


def _to_plane(points, origin, u, v):
    d = points - origin
    return np.column_stack([np.einsum("ij,ij->i", d, u), np.einsum("ij,ij->i", d, v)])


def _lattices(tri2d, h, rng):
    """Lattice points (spacing ``h``, jittered with ``rng``) inside each 2-D triangle and
    half a spacing from its sides: ``(points (q, 2), face (q,))``."""
    lo, hi = tri2d.min(axis=1), tri2d.max(axis=1)
    offset = 0.0 if rng is None else 0.5 * h
    count = (np.ceil((hi - lo) / h)).astype(np.int64) + 1                 # (m, 2)
    per_face = count[:, 0] * count[:, 1]
    face = np.repeat(np.arange(len(tri2d)), per_face)
    j = np.arange(len(face)) - np.repeat(np.cumsum(per_face) - per_face, per_face)
    ij = np.column_stack([j // count[face, 1], j % count[face, 1]])
    pts = lo[face] + offset + h * ij
    if rng is not None:
        pts = pts + rng.uniform(-0.35 * h, 0.35 * h, pts.shape)
    keep = np.ones(len(pts), dtype=bool)
    for k in range(3):                      # signed distance to each side, inside positive
        a, b = tri2d[face, k], tri2d[face, (k + 1) % 3]
        d = b - a
        side = (d[:, 0] * (pts[:, 1] - a[:, 1]) - d[:, 1] * (pts[:, 0] - a[:, 0])) \
            / np.linalg.norm(d, axis=1)
        keep &= side >= config.CLEARANCE * h * (1 - 1e-9)
    return pts[keep], face[keep]


def fill_faces(nodes: np.ndarray, first_new: int, faces: np.ndarray, piece_face: np.ndarray,
               pieces: np.ndarray, h: float | None,
               rng: np.random.Generator | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lattice nodes inside single-triangle patches, and their triangulations.

    Parameters
    ----------
    nodes : (n, 3) ndarray
        The nodes on the faces' sides (local frame).
    first_new : int
        The number the first new node gets.
    faces : (m, 3) int ndarray
        The faces (node numbers of their corners), counter-clockwise seen from outside.
    piece_face : (s,) int ndarray
        The face (row of ``faces``) of each border piece.
    pieces : (s, 2) int ndarray
        The pieces of the faces' sides between consecutive nodes, running along each
        face's own direction.
    h : float or None
        Lattice spacing (None: no lattice).
    rng : numpy.random.Generator or None
        Jitter the lattices by up to 0.35 h.

    Returns
    -------
    triangles : (t, 3) int64 ndarray
        Node numbers, oriented like the faces.
    triangle_face : (t,) int64 ndarray
        The face (row of ``faces``) each triangle lies in.
    new : (q, 3) ndarray
        The new nodes (lattice points, and any point ``triangle`` added).
    """
    corners = nodes[faces]
    origin, u, v = _frames(corners)
    tri2d = np.stack([_to_plane(corners[:, k], origin, u, v) for k in range(3)], axis=1)
    if h is None:
        lattice, lattice_face = np.empty((0, 2)), np.empty(0, dtype=np.int64)
    else:
        lattice, lattice_face = _lattices(tri2d, h, rng)
    # one canvas: face i in the cell (i % columns, i // columns), cells wider than any face
    width = 1.25 * (tri2d.max(axis=1) - tri2d.min(axis=1)).max()
    columns = int(np.ceil(np.sqrt(len(faces))))
    shift = width * np.column_stack([np.arange(len(faces)) % columns,
                                     np.arange(len(faces)) // columns]) - tri2d.min(axis=1)
    key = piece_face[:, None] * len(nodes) + pieces                      # (face, node) copies
    copies, inverse = np.unique(key.ravel(), return_inverse=True)
    copy_face, copy_node = copies // len(nodes), copies % len(nodes)
    xy = _to_plane(nodes[copy_node], origin[copy_face], u[copy_face], v[copy_face]) \
        + shift[copy_face]
    canvas = np.concatenate([xy, lattice + shift[lattice_face]])
    out = triangle.triangulate({"vertices": canvas, "segments": inverse.reshape(-1, 2)}, "pQ")
    verts, tris = out["vertices"], out["triangles"]
    # the face of each canvas point by its cell (face i's box starts at its cell's corner);
    # triangles whose centroid lies outside
    # their cell's face are the gaps between faces
    def face_at(points):
        cell = np.floor(points / width).astype(np.int64)
        return np.clip(cell[:, 0] + columns * cell[:, 1], 0, len(faces) - 1)

    centroid = verts[tris].mean(axis=1)
    f = face_at(centroid)
    inside = np.ones(len(tris), dtype=bool)
    for k in range(3):
        a, b = tri2d[f, k] + shift[f], tri2d[f, (k + 1) % 3] + shift[f]
        inside &= (b[:, 0] - a[:, 0]) * (centroid[:, 1] - a[:, 1]) \
            - (b[:, 1] - a[:, 1]) * (centroid[:, 0] - a[:, 0]) > 0
    tris, f = tris[inside], f[inside]
    extra = verts[len(canvas):]
    fe = face_at(extra)
    local = extra - shift[fe]
    lifted = np.concatenate([lattice[:, :1] * u[lattice_face] + lattice[:, 1:] * v[lattice_face]
                             + origin[lattice_face],
                             origin[fe] + local[:, :1] * u[fe] + local[:, 1:] * v[fe]])
    number = np.concatenate([copy_node, first_new + np.arange(len(lifted))])
    return number[tris].astype(np.int64), f, lifted
