"""3-D test bodies built from voxels of a (possibly non-uniform) tensor grid.

Each case returns ``(points (n, 3), boundary_faces (b, 3), boundary_face_regions (b, 2))``
as `cnem.nodes` gives them on a `Domain3D`: the body is a union of labelled voxels
(-1 = empty), its boundary and interfaces are the voxel faces between different
labels, each square cut into two triangles along a random diagonal (so ties with
Qhull's own choice occur both ways), oriented so that the normal points out of
``boundary_face_regions[:, 0]``. Nodes off the faces may be jittered.
"""

from __future__ import annotations

import numpy as np


def voxel_body(xs, ys, zs, labels, *, jitter=0.0, seed=0):
    """Nodes and boundary triangles of the voxels ``labels`` on the grid ``xs x ys x zs``.

    Parameters
    ----------
    xs, ys, zs : 1-D array_like
        Grid lines along each axis.
    labels : (len(xs)-1, len(ys)-1, len(zs)-1) int array_like
        Region of each voxel, -1 for empty.
    jitter : float
        Nodes not on any face move by up to ``jitter`` times the smallest spacing.
    """
    axes = [np.asarray(a, dtype=float) for a in (xs, ys, zs)]
    labels = np.asarray(labels)
    shape = tuple(len(a) for a in axes)
    rng = np.random.default_rng(seed)
    padded = np.pad(labels, 1, constant_values=-1)
    index = np.arange(np.prod(shape)).reshape(shape)
    quads, regs = [], []
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        sl_lo = [slice(1, -1)] * 3
        sl_hi = [slice(1, -1)] * 3
        sl_lo[a] = slice(0, -1)
        sl_hi[a] = slice(1, None)
        lower, upper = padded[tuple(sl_lo)], padded[tuple(sl_hi)]   # voxel on each side
        for pos in zip(*np.nonzero(lower != upper)):
            lo_label, hi_label = lower[pos], upper[pos]
            corner = list(pos)
            ring = []
            for db, dc in ((0, 0), (1, 0), (1, 1), (0, 1)):
                p = list(corner)
                p[b] += db
                p[c] += dc
                ring.append(index[tuple(p)])
            if lo_label >= 0:
                regs.append((lo_label, hi_label))
            else:
                ring = ring[::-1]
                regs.append((hi_label, -1))
            quads.append(ring)
    quads = np.array(quads)
    diag = rng.integers(0, 2, len(quads)).astype(bool)
    q = np.where(diag[:, None], quads, np.roll(quads, 1, axis=1))
    faces = np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
    face_regions = np.concatenate([regs, regs]).astype(np.int64)
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    used = np.zeros(len(grid), dtype=bool)
    for idx in zip(*np.nonzero(labels >= 0)):
        i, j, k = idx
        used[index[i:i + 2, j:j + 2, k:k + 2].ravel()] = True
    on_face = np.zeros(len(grid), dtype=bool)
    on_face[faces.ravel()] = True
    h = min(np.diff(a).min() for a in axes)
    free = used & ~on_face
    grid[free] += jitter * h * rng.uniform(-1, 1, (free.sum(), 3))
    new = -np.ones(len(grid), dtype=np.int64)
    new[used] = np.arange(used.sum())
    return grid[used], new[faces], face_regions


def box(n=6, *, jitter=0.3, seed=0, lengths=(1.0, 1.0, 1.0)):
    """The box ``[0, lx] x [0, ly] x [0, lz]`` with ``n`` voxels a side."""
    axes = [np.linspace(0.0, length, n + 1) for length in lengths]
    return voxel_body(*axes, np.zeros((n, n, n), dtype=int), jitter=jitter, seed=seed)


def l_block(n=6, *, jitter=0.3, seed=1):
    """The unit cube minus its quarter ``x > 0.5, y > 0.5`` (a re-entrant edge)."""
    labels = np.zeros((n, n, n), dtype=int)
    labels[n // 2:, n // 2:, :] = -1
    axes = [np.linspace(0.0, 1.0, n + 1)] * 3
    return voxel_body(*axes, labels, jitter=jitter, seed=seed)


def box_with_cavity(n=6, *, jitter=0.3, seed=2):
    """The unit cube with a cubic cavity of a third of its side at its centre."""
    labels = np.zeros((n, n, n), dtype=int)
    labels[n // 3:2 * n // 3, n // 3:2 * n // 3, n // 3:2 * n // 3] = -1
    axes = [np.linspace(0.0, 1.0, n + 1)] * 3
    return voxel_body(*axes, labels, jitter=jitter, seed=seed)


def stacked(n=6, *, jitter=0.3, seed=3):
    """Two unit-square boxes stacked along z: region 0 below z = 0.5, region 1 above."""
    labels = np.zeros((n, n, n), dtype=int)
    labels[:, :, n // 2:] = 1
    axes = [np.linspace(0.0, 1.0, n + 1)] * 3
    return voxel_body(*axes, labels, jitter=jitter, seed=seed)


def slotted(n=6, *, gap=0.02, jitter=0.3, seed=4):
    """The unit cube with a slot of width ``gap`` at ``z = 0.5``, cut from ``x = 0`` to ``x = 0.5``."""
    zs = np.concatenate([np.linspace(0.0, 0.5, n // 2 + 1), np.linspace(0.5 + gap, 1.0, n // 2 + 1)])
    axes = [np.linspace(0.0, 1.0, n + 1), np.linspace(0.0, 1.0, n + 1), zs]
    labels = np.zeros((n, n, n + 1), dtype=int)
    labels[:n // 2, :, n // 2] = -1
    return voxel_body(*axes, labels, jitter=jitter, seed=seed)


def region_surfaces(points, faces, face_regions):
    """The closed surface of every region of a voxel body, as `cnem.Domain3D` takes them.

    Parameters
    ----------
    points : (n, 3) ndarray
    faces : (b, 3) int64 ndarray
    face_regions : (b, 2) int64 ndarray
        As `voxel_body` returns them (normals out of ``face_regions[:, 0]``).

    Returns
    -------
    list of ((k, 3) ndarray, (f, 3) int64 ndarray)
        Region ``r``'s vertices and its faces oriented outwards (an interface face is in
        both regions' surfaces, once each way round).
    """
    out = []
    for r in range(int(face_regions.max()) + 1):
        own = np.concatenate([faces[face_regions[:, 0] == r],
                              faces[face_regions[:, 1] == r, ::-1]])
        used, local = np.unique(own, return_inverse=True)
        out.append((points[used], local.reshape(own.shape)))
    return out


def two_material_l_block():
    """The L-block of `l_block` (two voxels a side), region 0 below z = 0.5 and region 1
    above: the interface meets the re-entrant edge."""
    labels = np.zeros((2, 2, 2), dtype=int)
    labels[:, :, 1] = 1
    labels[1, 1, :] = -1
    axes = [np.linspace(0.0, 1.0, 3)] * 3
    return region_surfaces(*voxel_body(*axes, labels))


def two_material_cavity():
    """The unit cube with the cubic cavity of `box_with_cavity` (a third of its side at
    its centre), region 0 below z = 0.5 and region 1 above: the interface cuts the
    cavity in half."""
    third = np.linspace(0.0, 1.0, 4)
    zs = np.array([0.0, 1.0 / 3.0, 0.5, 2.0 / 3.0, 1.0])
    labels = np.zeros((3, 3, 4), dtype=int)
    labels[:, :, 2:] = 1
    labels[1, 1, 1:3] = -1
    return region_surfaces(*voxel_body(third, third, zs, labels))


def segments_blocked(a, b, tri):
    """Whether each segment ``a[k] -> b[k]`` crosses the interior of a triangle of ``tri``.

    Parameters
    ----------
    a, b : (s, 3) ndarray
    tri : (f, 3, 3) ndarray

    Returns
    -------
    (s,) bool ndarray
        True where the segment passes strictly through a triangle (touching at an
        end, an edge or lying in the plane does not count).
    """
    p0, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    d = (b - a)[:, None, :]
    pv = np.cross(d, e2[None])
    det = np.einsum("sfj,fj->sf", pv, e1)
    scale = np.linalg.norm(d, axis=2) * np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1)
    ok = np.abs(det) > 1e-12 * scale
    det = np.where(ok, det, 1.0)
    tv = a[:, None, :] - p0[None]
    u = np.einsum("sfj,sfj->sf", tv, pv) / det
    qv = np.cross(tv, e1[None])
    v = np.einsum("sfj,sj->sf", qv, b - a) / det
    t = np.einsum("sfj,fj->sf", qv, e2[None].repeat(1, 0)[0]) / det
    eps = 1e-9
    hit = ok & (u > eps) & (v > eps) & (u + v < 1 - eps) & (t > eps) & (t < 1 - eps)
    return hit.any(axis=1)


def tube_surface(inner, outer, height, segments=24):
    """A thick-walled tube along z (a cylinder with a coaxial hole), as triangles: the
    regular ``segments``-gons inscribed in the circles of radii ``inner < outer``.

    Returns ``(vertices (4 segments, 3), faces (8 segments, 3))``, faces pointing out of
    the wall (into the hole on the inner side).
    """
    t = 2.0 * np.pi * np.arange(segments) / segments
    ring = np.column_stack([np.cos(t), np.sin(t), np.zeros(segments)])
    up = np.array([0.0, 0.0, height])
    vertices = np.concatenate([outer * ring, outer * ring + up, inner * ring, inner * ring + up])
    i, j = np.arange(segments), (np.arange(segments) + 1) % segments
    ob, ot, ib, it = i, segments + i, 2 * segments + i, 3 * segments + i
    obj, otj, ibj, itj = j, segments + j, 2 * segments + j, 3 * segments + j
    faces = np.concatenate([
        np.column_stack([ob, obj, otj]), np.column_stack([ob, otj, ot]),      # outer wall
        np.column_stack([ib, it, itj]), np.column_stack([ib, itj, ibj]),      # inner wall
        np.column_stack([ot, otj, itj]), np.column_stack([ot, itj, it]),      # top
        np.column_stack([ob, ib, ibj]), np.column_stack([ob, ibj, obj])])     # bottom
    return vertices, faces


def nearest_visible(x, points, faces, candidates=24):
    """Index of the nearest node visible from each sample ``x (s, 3)`` (brute force).

    ``faces`` are the triangles that cut visibility: all boundary faces, or a subset
    (the blocking ones, `cnem.geometry.smooth_patches`; an empty ``(0, 3)`` array makes
    this the plain nearest node). Returns -1 where none of the ``candidates`` nearest
    nodes is visible.
    """
    from scipy.spatial import cKDTree
    tri = points[faces]
    dist, idx = cKDTree(points).query(x, k=min(candidates, len(points)))
    out = np.full(len(x), -1)
    todo = np.ones(len(x), dtype=bool)
    for k in range(idx.shape[1]):
        rows = np.flatnonzero(todo)
        if len(rows) == 0:
            break
        seen = ~segments_blocked(x[rows], points[idx[rows, k]], tri)
        out[rows[seen]] = idx[rows[seen], k]
        todo[rows[seen]] = False
    return out


def facet_flux(cells):
    """Per cell: the sum of its facets' area vectors ``(m, 3)`` (zero for a closed cell) and
    its surface area ``(m,)``."""
    area = cells.facet_areas()
    m = len(cells.node)
    flux = np.stack([np.bincount(cells.facet_cell, weights=cells.facet_normal[:, k] * area,
                                 minlength=m) for k in range(3)], axis=1)
    return flux, np.bincount(cells.facet_cell, weights=area, minlength=m)


def assert_same_cell(got, want):
    """Two computations ``(triangles (q, 3, 3), normals (q, 3), volume)`` of one cell agree:
    the volume to 1e-12 relative (as ``pytest.approx(rel=1e-12)``), and per facet plane
    the area and the centroid."""
    (tri, normal, volume), (want_tri, want_normal, want_volume) = got, want
    assert abs(volume - want_volume) <= max(1e-12 * abs(want_volume), 1e-12), (volume,
                                                                                 want_volume)
    keys, area, centroid = _per_plane(tri, normal)
    want_keys, want_area, want_centroid = _per_plane(want_tri, want_normal)
    np.testing.assert_array_equal(keys, want_keys)
    np.testing.assert_allclose(area, want_area, rtol=0, atol=1e-12 * want_area.max())
    np.testing.assert_allclose(centroid, want_centroid, rtol=0, atol=1e-12)


def _per_plane(tri, normal):
    """Facet planes (rounded normals) of one cell, the area and centroid on each."""
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    keys, inverse = np.unique(np.round(normal * 1e6), axis=0, return_inverse=True)
    inverse = inverse.ravel()
    total = np.bincount(inverse, weights=area)
    moment = np.column_stack([np.bincount(inverse, weights=area * tri[:, :, c].mean(axis=1))
                              for c in range(3)])
    return keys, total, moment / total[:, None]
