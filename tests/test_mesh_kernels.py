"""`cnem.geometry._mesh_kernels` against brute-force NumPy references (sorts of every
triangle and edge key) on Delaunay triangulations of random and lattice points, with
the serial and the parallel copies of the kernels."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import Delaunay

from cnem._parallel import always_parallel
from cnem.geometry import _mesh_kernels as mk
from cnem.geometry._kernels import place_rows


def _points(kind, seed=0):
    rng = np.random.default_rng(seed)
    if kind == "random":
        return rng.random((400, 2))
    g = np.arange(12, dtype=float)                       # cocircular quadruples
    return np.column_stack([np.repeat(g, 12), np.tile(g, 12)])


def _mesh(kind, seed=0):
    pts = _points(kind, seed)
    tri = Delaunay(pts).simplices.astype(np.int64)
    rng = np.random.default_rng(seed + 1)
    tri = tri[rng.permutation(len(tri))]                 # not in any sorted order
    flip = rng.random(len(tri)) < 0.5                    # half of them clockwise
    tri[flip] = tri[flip][:, [0, 2, 1]]
    return pts, np.ascontiguousarray(tri)


def _neighbors_by_sort(tri):
    """The triangle across each edge, by sorting the 3 t edge keys."""
    a, b = tri[:, [1, 2, 0]].ravel(), tri[:, [2, 0, 1]].ravel()
    n = int(tri.max()) + 1
    key = np.minimum(a, b) * n + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    pair = np.flatnonzero(key[order][1:] == key[order][:-1])
    nb = np.full(3 * len(tri), -1, dtype=np.int64)
    nb[order[pair]] = order[pair + 1] // 3
    nb[order[pair + 1]] = order[pair] // 3
    return nb.reshape(-1, 3)


both_copies = pytest.mark.parametrize("parallel", [False, True])
meshes = pytest.mark.parametrize("kind", ["random", "lattice"])


def _run(parallel, fn, *args):
    if parallel:
        with always_parallel():
            return fn(*args)
    return fn(*args)


@both_copies
@meshes
def test_orientation_and_centroids(kind, parallel):
    pts, tri = _mesh(kind)
    before = tri.copy()
    centroid = _run(parallel, mk.orient_and_centroids, pts, tri)
    a, b, c = (pts[tri[:, k]] for k in range(3))
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    assert (area2 > 0).all()
    assert (np.sort(tri, axis=1) == np.sort(before, axis=1)).all()
    np.testing.assert_array_equal(centroid, pts[tri].mean(axis=1))


@both_copies
@meshes
def test_canonical_order_is_the_lexicographic_sort(kind, parallel):
    pts, tri = _mesh(kind)
    rotated, order = _run(parallel, mk.canonical_order, tri, len(pts))
    first = np.argmin(tri, axis=1)[:, None]
    expect = np.take_along_axis(tri, (first + np.arange(3)) % 3, axis=1)
    ref = np.lexsort((expect[:, 2], expect[:, 1], expect[:, 0]))
    np.testing.assert_array_equal(order, ref)
    np.testing.assert_array_equal(rotated, expect[ref])


@meshes
def test_vertex_star_is_the_stable_argsort(kind):
    pts, tri = _mesh(kind)
    offsets, star = mk.vertex_star(tri, len(pts) + 3)    # three nodes in no triangle
    np.testing.assert_array_equal(star, np.argsort(tri.ravel(), kind="stable") // 3)
    np.testing.assert_array_equal(np.diff(offsets), np.bincount(tri.ravel(), minlength=len(pts) + 3))


@both_copies
@meshes
def test_neighbors_and_region_cut(kind, parallel):
    pts, tri = _mesh(kind)
    nb = _run(parallel, mk.edge_neighbors, tri, *mk.vertex_star(tri, len(pts)))
    ref = _neighbors_by_sort(tri)
    np.testing.assert_array_equal(nb, ref)
    region = (pts[tri].mean(axis=1)[:, 0] > pts[:, 0].mean()).astype(np.int64)
    cut = _run(parallel, mk.cut_regions, nb, region)
    other = ref >= 0
    expect = ref.copy()
    expect[other & (region[np.maximum(ref, 0)] != region[:, None])] = -1
    np.testing.assert_array_equal(cut, expect)


@both_copies
@meshes
def test_circumcentres_are_equidistant(kind, parallel):
    pts, tri = _mesh(kind)
    cc = _run(parallel, mk.circumcentres, pts, tri)
    d = np.linalg.norm(pts[tri] - cc[:, None, :], axis=2)
    size = np.ptp(pts, axis=0).max()
    np.testing.assert_allclose(d, d[:, :1].repeat(3, axis=1), rtol=0, atol=1e-12 * size)


@meshes
def test_close_neighbours_by_brute_force(kind):
    pts, tri = _mesh(kind)
    nb = _neighbors_by_sort(tri)
    cc = mk.circumcentres(pts, tri)
    tol = 1e-9 * np.ptp(pts, axis=0).max()
    low, high = mk.close_neighbours(cc, nb, tol)
    t, k = np.nonzero(nb > np.arange(len(nb))[:, None])
    u = nb[t, k]
    close = np.hypot(*(cc[t] - cc[u]).T) <= tol
    np.testing.assert_array_equal(low, t[close])
    np.testing.assert_array_equal(high, u[close])
    assert (len(low) > 0) == (kind == "lattice")         # the lattice's cocircular quads


@meshes
def test_edge_triangles_are_the_triangles_with_the_edge(kind):
    pts, tri = _mesh(kind)
    edges = np.concatenate([tri[:, [0, 1]], tri[::7, [2, 1]]])
    ptr, slot = mk.edge_triangles(tri, *mk.vertex_star(tri, len(pts)), edges)
    for g, (a, b) in enumerate(edges):
        s = slot[ptr[g]:ptr[g + 1]]
        ref = [3 * t + k for t in range(len(tri)) for k in range(3)
               if {tri[t, (k + 1) % 3], tri[t, (k + 2) % 3]} == {a, b}]
        np.testing.assert_array_equal(s, ref)


def test_place_rows_copies_blocks():
    rng = np.random.default_rng(3)
    src = rng.random((50, 2))
    length = np.array([3, 0, 5, 2])
    src_start = np.array([0, 10, 20, 40])
    dst_start = np.array([2, 5, 5, 12])
    dst = np.full((14, 2), np.nan)
    place_rows(src, src_start, dst, dst_start, length)
    for a, b, k in zip(src_start, dst_start, length):
        np.testing.assert_array_equal(dst[b:b + k], src[a:a + k])
    assert np.isnan(dst[[0, 1, 10, 11]]).all()
