"""`cnem.spatial.family_search`: every method gives exactly the brute-force families.

``j`` is in the family of ``i`` iff ``0 < |x_j - x_i| < horizon_i`` (minimum image
under periodic boundaries). The reference (`reference.brute_family`) tests every
pair against all 3**d periodic images. Clouds: uniform, clustered, graded (per
point horizons), integer lattices (points at exactly the horizon, which the
strict ``<`` must leave out), 2-D and 3-D, open and periodic.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

import reference as R
from cnem import config
from cnem.spatial import Family, family_search

METHODS = ["auto", "rtree", "cells", "kdtree", "brute"]
CASES = R.SPATIAL_CASES
case_id = R.spatial_case_id
SIZES = {2: 1200, 3: 800}
#: Integer horizons on the integer lattice: 5**2 = 3**2 + 4**2, many exact ties.
LATTICE_HORIZON = {2: 5.0, 3: 2.0}


@functools.lru_cache(maxsize=None)
def cloud(kind, dim, periodic):
    """Points, period (None if open), horizon and the brute-force families."""
    pts, ext, spacing = R.spatial_cloud(kind, dim, SIZES[dim], periodic=periodic, seed=0)
    if kind == "lattice":
        horizon = LATTICE_HORIZON[dim]
    elif kind == "graded":
        horizon = 3.0 * spacing
    else:
        horizon = 2.5 * spacing[0]
    period = ext if periodic else None
    return pts, period, horizon, R.brute_family(pts, horizon, period)


def assert_family(fam, n, ref, what=""):
    """``fam`` is a well-formed Family whose rows are the reference sets."""
    assert isinstance(fam, Family) and len(fam) == n
    assert fam.offsets.dtype == np.int64 and fam.offsets.shape == (n + 1,)
    assert fam.indices.dtype == np.int32
    assert fam.offsets[0] == 0 and (np.diff(fam.offsets) >= 0).all()
    assert fam.offsets[-1] == len(fam.indices)
    diff = R.csr_row_differences(fam.offsets, fam.indices, *ref)
    assert not diff, f"{what}: families differ from brute force, (row, missing, extra): {diff}"


@pytest.mark.slow
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_family_matches_brute(case, method):
    pts, period, horizon, ref = cloud(*case)
    fam = family_search(pts, horizon, period=period, method=method)
    assert_family(fam, len(pts), ref, f"method={method}")
    assert np.array_equal(fam.horizon, np.broadcast_to(horizon, (len(pts),)))
    if period is None:
        assert np.isinf(fam.period).all() and fam.period.shape == (pts.shape[1],)
    else:
        assert np.array_equal(fam.period, period)
    assert fam.counts.mean() > 5


@functools.lru_cache(maxsize=None)
def lattice_reference(dim, periodic, up):
    pts, period, h, ref = cloud("lattice", dim, periodic)
    return R.brute_family(pts, np.nextafter(h, np.inf), period) if up else ref


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
def test_lattice_points_at_exactly_the_horizon(method, dim, periodic):
    """On the integer lattice with an integer horizon h, lattice vectors of length
    exactly h are not in the family; with h + 1 ulp they are. Under periodic
    boundaries every point has the same family size."""
    pts, period, h, _ = cloud("lattice", dim, periodic)
    v = np.stack(np.meshgrid(*[np.arange(-6, 7)] * dim, indexing="ij"), -1).reshape(-1, dim)
    n2 = (v * v).sum(axis=1)
    inside, on = int(((n2 > 0) & (n2 < h * h)).sum()), int((n2 == h * h).sum())
    assert on > 0
    for up, expect in ((False, inside), (True, inside + on)):
        horizon = np.nextafter(h, np.inf) if up else h
        fam = family_search(pts, horizon, period=period, method=method)
        assert_family(fam, len(pts), lattice_reference(dim, periodic, up), f"h = {horizon!r}")
        if periodic:
            assert (fam.counts == expect).all(), (horizon, np.unique(fam.counts))
        else:
            assert fam.counts.max() == expect, horizon
        bond = pts[fam.indices] - pts[np.repeat(np.arange(len(pts)), fam.counts)]
        if periodic:
            bond -= period * np.round(bond / period)
        length2 = (bond * bond).sum(axis=1)
        assert (length2 > 0).all() and (length2 < horizon * horizon).all()
        if horizon == h:
            assert (length2 < h * h).all()
        else:
            assert (length2 == h * h).sum() > len(pts)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
def test_scalar_horizon_families_are_symmetric(method, periodic):
    pts, period, horizon, _ = cloud("clustered", 2, periodic)
    fam = family_search(pts, horizon, period=period, method=method)
    pairs = fam.pairs()
    n = len(pts)
    assert pairs.dtype == np.int64 and pairs.shape == (len(fam.indices), 2)
    assert np.array_equal(np.sort(pairs[:, 0] * n + pairs[:, 1]),
                          np.sort(pairs[:, 1] * n + pairs[:, 0]))
    assert np.array_equal(fam.row(7), fam.indices[fam.offsets[7]:fam.offsets[8]])


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
def test_per_point_horizons(method, dim, periodic):
    """Horizons varying 10x between neighbours (families are not symmetric)."""
    pts, period, h, ref = per_point_case(dim, periodic)
    fam = family_search(pts, h, period=period, method=method)
    assert_family(fam, len(pts), ref, f"method={method}")


@functools.lru_cache(maxsize=None)
def per_point_case(dim, periodic):
    ext = np.array([1.0, 0.75, 0.5][:dim])
    rng = np.random.default_rng(dim)
    pts = rng.random((1200, dim)) * ext
    h = (0.02 if dim == 2 else 0.06) * np.exp(rng.uniform(np.log(0.3), np.log(3.0), len(pts)))
    period = ext if periodic else None
    return pts, period, h, R.brute_family(pts, h, period)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
def test_horizon_equal_to_a_distance(method, periodic):
    """Per-point horizon = the distance to the 5th neighbour (as sqrt of the squared
    distance) and one ulp either side: all methods decide like the reference,
    ``d2 < h * h``, however close the neighbour is to the horizon."""
    pts, period, horizons = near_distance_case(periodic)
    for h, ref in horizons:
        fam = family_search(pts, h, period=period, method=method)
        assert_family(fam, len(pts), ref, f"method={method}")


@functools.lru_cache(maxsize=None)
def near_distance_case(periodic):
    rng = np.random.default_rng(11)
    pts = rng.random((800, 2))
    period = np.ones(2) if periodic else None
    if not periodic:
        pts += 10.0                  # away from the origin: larger rounding in boxes and cells
    d2 = R.point_dist2(pts, pts, period)
    h0 = np.sqrt(np.sort(d2, axis=1)[:, 5])
    hs = (h0, np.nextafter(h0, 0), np.nextafter(h0, np.inf))
    return pts, period, [(h, R.brute_family(pts, h, period)) for h in hs]


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("dim", [2, 3])
def test_points_on_the_cell_faces(method, dim):
    """Points at 0 and at np.nextafter(L, 0) on every axis are neighbours through the boundary."""
    L = np.array([1.0, 0.75, 0.5][:dim])
    top = np.nextafter(L, 0)
    corners = np.array(np.meshgrid(*[[0.0, 1.0]] * dim, indexing="ij")).reshape(dim, -1).T
    rng = np.random.default_rng(dim)
    pts = np.vstack([np.where(corners > 0, top, 0.0), rng.random((200, dim)) * L])
    fam = family_search(pts, 1e-3, period=L, method=method)
    k = 2 ** dim
    for i in range(k):
        assert sorted(fam.row(i).tolist()) == [j for j in range(k) if j != i]
    assert_family(fam, len(pts), R.brute_family(pts, 1e-3, L), f"method={method}")
    fam = family_search(pts, 0.1 * L.min(), period=L, method=method)
    assert_family(fam, len(pts), R.brute_family(pts, 0.1 * L.min(), L), f"method={method}")


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("fraction", [0.49, 0.5, 0.7])
@pytest.mark.parametrize("cell", ["cube", "box"])
def test_horizon_near_half_the_cell(method, dim, fraction, cell):
    """Horizons around half the period (0.7 L: points reach each other by one image only,
    the minimum one)."""
    pts, L, h, ref = half_cell_case(dim, fraction, cell)
    fam = family_search(pts, h, period=L, method=method)
    assert_family(fam, len(pts), ref, f"method={method}, h={h}")


@functools.lru_cache(maxsize=None)
def half_cell_case(dim, fraction, cell):
    L = np.ones(dim) if cell == "cube" else np.array([1.0, 0.75, 0.5][:dim])
    rng = np.random.default_rng([dim, int(100 * fraction)])
    pts = rng.random((300, dim)) * L
    h = fraction * L.min()
    return pts, L, h, R.brute_family(pts, h, L)


@pytest.mark.parametrize("method", METHODS)
def test_half_period_apart(method):
    """x = np.nextafter(L / 2, 0) is at minimum-image distance L/2 - 1 ulp from 0,
    so with horizon L/2 each is in the other's family."""
    L = 1.0
    x = np.nextafter(0.5 * L, 0)
    pts = np.array([[0.0, 0.0], [x, 0.0], [0.0, x], [0.5, 0.5]])
    fam = family_search(pts, 0.5 * L, period=[L, L], method=method)
    ref = R.brute_family(pts, 0.5 * L, [L, L])
    assert sorted(ref[1][ref[0][0]:ref[0][1]].tolist()) == [1, 2]
    assert_family(fam, len(pts), ref, f"method={method}")


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
def test_duplicate_points_are_not_in_each_others_family(method, periodic):
    rng = np.random.default_rng(3)
    base = rng.random((400, 2))
    pts = np.vstack([base, base[:50], base[:10]])
    period = np.ones(2) if periodic else None
    fam = family_search(pts, 0.06, period=period, method=method)
    assert_family(fam, len(pts), R.brute_family(pts, 0.06, period), f"method={method}")
    for i in range(10):
        assert {i, 400 + i, 450 + i} & set(fam.row(i).tolist()) == set()
        assert set(fam.row(i).tolist()) == set(fam.row(400 + i).tolist())


@pytest.mark.parametrize("method", METHODS)
def test_empty_single_and_pair(method):
    for dim in (2, 3):
        for period in (None, np.ones(dim)):
            fam = family_search(np.zeros((0, dim)), 0.1, period=period, method=method)
            assert len(fam) == 0 and fam.offsets.tolist() == [0] and len(fam.indices) == 0
            assert fam.indices.dtype == np.int32
            assert len(fam.pairs()) == 0
            fam = family_search(np.full((1, dim), 0.5), 0.1, period=period, method=method)
            assert fam.offsets.tolist() == [0, 0] and len(fam.indices) == 0
            pair = np.zeros((2, dim))
            pair[1, 0] = 0.25            # distance 0.25 exactly
            fam = family_search(pair, 0.25, period=period, method=method)
            assert fam.offsets.tolist() == [0, 0, 0], "distance == horizon is out"
            fam = family_search(pair, np.nextafter(0.25, 1), period=period, method=method)
            assert fam.offsets.tolist() == [0, 1, 2] and fam.indices.tolist() == [1, 0]
            fam = family_search(pair, [0.3, 0.2], period=period, method=method)
            assert fam.offsets.tolist() == [0, 1, 1] and fam.indices.tolist() == [1]
    fam = family_search([], 0.1, method=method)
    assert len(fam) == 0


# ---------------------------------------------------------------------- errors
def test_errors():
    pts = np.random.default_rng(0).random((50, 2))
    with pytest.raises(ValueError, match=r"method must be one of .*'octree'"):
        family_search(pts, 0.1, method="octree")
    big = np.random.default_rng(0).random((20_001, 2))
    with pytest.raises(ValueError, match=r"20000 points, received 20001"):
        family_search(big, 0.01, method="brute")
    for bad in (0.0, -0.1, np.nan, np.inf):
        with pytest.raises(ValueError, match="horizon must be positive"):
            family_search(pts, bad)
    h = np.full(50, 0.1)
    h[7] = 0.0
    with pytest.raises(ValueError, match="horizon must be positive"):
        family_search(pts, h)
    with pytest.raises(ValueError):
        family_search(pts, np.full(49, 0.1))
    with pytest.raises(ValueError, match=r"\(n, 2\) or \(n, 3\).*\(50, 4\)"):
        family_search(np.zeros((50, 4)), 0.1)
    with pytest.raises(ValueError, match=r"\(n, 2\) or \(n, 3\)"):
        family_search(np.zeros(10), 0.1)
    nan = pts.copy()
    nan[3, 1] = np.nan
    with pytest.raises(ValueError, match="finite"):
        family_search(nan, 0.1)
    for method in METHODS:
        for outside in ([1.0, 0.5], [0.5, -1e-12], [2.0, 3.0]):
            with pytest.raises(ValueError, match=r"1 points lie outside the periodic cell.*np\.mod"):
                family_search(np.vstack([pts, [outside]]), 0.1, period=[1.0, 1.0], method=method)
    with pytest.raises(ValueError, match="period"):
        family_search(pts, 0.1, period=[1.0, 0.0])


def lines_cloud(rng, dim):
    """Points on lines along the last axis (every column of the cell list a line, so
    the extents of its points have no width) with rows of the lines jittered or
    not, scaled and shifted: the clouds where the gap between columns is tight."""
    m = rng.integers(3, 9)
    grid = np.stack(np.meshgrid(*[np.arange(m)] * (dim - 1), indexing="ij"), -1)
    feet = grid.reshape(-1, dim - 1).astype(float)
    if rng.random() < 0.5:
        feet += rng.uniform(-0.3, 0.3, feet.shape) * (rng.random(feet.shape) < 0.5)
    per_line = rng.integers(5, 30)
    heights = rng.choice([0.0, 1.0]) * rng.random((len(feet), per_line)) * m
    heights += np.arange(per_line) * (m / per_line)
    pts = np.column_stack([np.repeat(feet, per_line, axis=0), heights.reshape(-1)])
    return pts[rng.permutation(len(pts))]


#: Column widths of the one-horizon cell list: the default (by dimension) and one
#: number for every dimension, wide (a horizon) and narrow (a third of one).
COLUMNS = ["default", 1.0, 3.0]


@pytest.fixture(params=COLUMNS, ids=lambda c: f"columns-{c}")
def columns(request, monkeypatch):
    """`cnem.config.COLUMNS_PER_HORIZON` for the test (a number serves every dimension)."""
    if request.param != "default":
        monkeypatch.setattr(config, "COLUMNS_PER_HORIZON", request.param)
    return request.param


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("dim", [2, 3])
def test_cells_on_lines_match_brute(seed, dim, columns):
    """Property: random clouds of lines (lattices and jittered lattices included),
    random horizons (integer ones: ties), open (scaled and shifted) or periodic
    (scaled), columns of any width: method='cells' gives the brute-force families."""
    rng = np.random.default_rng(seed + 100 * dim)
    pts = lines_cloud(rng, dim)
    span = pts.max(axis=0) - pts.min(axis=0) + 1.0
    horizon = float(rng.choice([1.0, 2.0, rng.uniform(0.3, 0.5 * span.min())]))
    scale, shift = 2.0 ** rng.integers(-20, 20) * rng.uniform(0.5, 1), rng.uniform(-1e3, 1e3, dim)
    if rng.random() < 0.5:                         # periodic: the cloud wrapped into its cell
        period = np.ceil(pts.max(axis=0)) + rng.integers(0, 3, dim)
        pts, horizon, period = np.mod(pts, period) * scale, horizon * scale, period * scale
    else:
        pts, horizon, period = pts * scale + shift, horizon * scale, None
    ref = R.brute_family(pts, horizon, period)
    fam = family_search(pts, horizon, period=period, method="cells")
    assert_family(fam, len(pts), ref, f"seed {seed}")


@pytest.mark.parametrize("rel", [-1e-8, -1e-10, -1e-15, 0.0, 1e-15, 1e-10, 1e-8])
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("periodic", [False, True], ids=["open", "periodic"])
def test_cells_near_ties_on_a_lattice(rel, dim, periodic, columns):
    """Lattice distances sqrt(1..10) times a spacing that is not a power of two, the
    horizon within a relative 1e-15 .. 1e-8 of one of them (on either side), the
    lattice far from the origin: the members method='cells' takes without a distance
    test (lines whose extents leave the squared distance well below the horizon's)
    and those it tests give exactly the brute-force families."""
    m, spacing = 9, 0.1 * (1 + 1 / 3)
    axes = [np.arange(m) * spacing] * dim
    pts = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, dim)
    period = np.full(dim, m * spacing) if periodic else None
    if not periodic:
        pts = pts + 1e4
    for k2 in (2, 5, 8, 9):
        horizon = np.sqrt(k2) * spacing * (1.0 + rel)
        ref = R.brute_family(pts, horizon, period)
        fam = family_search(pts, horizon, period=period, method="cells")
        assert_family(fam, len(pts), ref, f"|v|^2 = {k2}")


@pytest.mark.parametrize("method", ["cells", "rtree", "kdtree", "brute"])
@pytest.mark.parametrize("period", [None, (1.0, 1.0)])
def test_a_horizon_far_beyond_the_body_takes_every_pair(method, period):
    """A horizon of 1e200 on a unit square: every other point is in each family (the
    scale is no longer set by the horizon alone, which underflowed the distances)."""
    pts = np.random.default_rng(3).random((60, 2))
    fam = family_search(pts, 1e200, method=method, period=period)
    for i in range(len(pts)):
        row = np.sort(fam.indices[fam.offsets[i]:fam.offsets[i + 1]])
        np.testing.assert_array_equal(row, np.delete(np.arange(len(pts)), i))


@pytest.mark.parametrize("scale", [1e-300, 1e-150, 1e-3, 1e3, 1e140])
def test_family_of_a_lattice_is_the_same_at_every_scale(scale):
    """The same lattice and horizon in any unit give the same families (brute force at
    unit scale as the reference)."""
    g = np.arange(6.0)
    pts = np.array([(x, y) for x in g for y in g])
    expected = family_search(pts, 1.5, method="brute")
    for method in ("cells", "rtree", "kdtree"):
        fam = family_search(pts * scale, 1.5 * scale, method=method)
        for i in range(len(pts)):
            np.testing.assert_array_equal(
                np.sort(fam.indices[fam.offsets[i]:fam.offsets[i + 1]]),
                np.sort(expected.indices[expected.offsets[i]:expected.offsets[i + 1]]))
