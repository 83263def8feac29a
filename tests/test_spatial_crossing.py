"""`cnem.spatial.remove_crossing`: bonds that properly cross a pre-crack are dropped.

Compared with `reference.crossing_keep`, which tests every bond against every
segment with orientation signs. A bond that only touches a segment (an end on
the crack line, passing through a crack tip, collinear with it) is kept.
"""

from __future__ import annotations

import numpy as np
import pytest

import reference as R
from cnem.spatial import Family, family_search, remove_crossing


def check_removed(fam, pts, segments, what=""):
    """``remove_crossing`` keeps exactly the reference bonds, row by row in the original order."""
    out = remove_crossing(fam, pts, segments)
    keep = R.crossing_keep(pts, fam.offsets, fam.indices, segments)
    assert isinstance(out, Family) and len(out) == len(fam)
    assert out.offsets.dtype == np.int64 and out.offsets.shape == fam.offsets.shape
    assert out.indices.dtype == fam.indices.dtype
    assert out.offsets[0] == 0 and out.offsets[-1] == len(out.indices)
    assert (np.diff(out.offsets) >= 0).all()
    assert out.horizon is fam.horizon or np.array_equal(out.horizon, fam.horizon)
    rows = np.repeat(np.arange(len(fam)), fam.counts)
    want = np.bincount(rows[keep], minlength=len(fam))
    bad = np.flatnonzero(out.counts != want)
    assert not len(bad), (f"{what}: rows {bad[:5]} keep {out.counts[bad[:5]]} bonds, "
                          f"expected {want[bad[:5]]}")
    # each row is the original row without the crossing bonds, in the same order
    assert np.array_equal(out.indices, fam.indices[keep]), f"{what}: kept bonds differ"
    return out, keep


def cloud(n=3000, seed=0):
    return np.random.default_rng(seed).random((n, 2))


@pytest.mark.parametrize("method", ["rtree", "cells"])
def test_inclined_crack_through_a_random_cloud(method):
    pts = cloud()
    fam = family_search(pts, 0.04, method=method)
    crack = np.array([[[0.2, 0.31], [0.73, 0.64]]])
    out, keep = check_removed(fam, pts, crack, "inclined crack")
    assert 100 < (~keep).sum() < len(keep) // 5
    # bonds across the line's extension beyond the tips are kept
    rows = np.repeat(np.arange(len(fam)), fam.counts)
    p, q = pts[rows], pts[fam.indices]
    a, b = crack[0]
    side_p, side_q = R.orient2d(a, b, p), R.orient2d(a, b, q)
    beyond = (side_p * side_q < 0) & ((p[:, 0] > 0.8) & (q[:, 0] > 0.8) | (p[:, 0] < 0.15) & (q[:, 0] < 0.15))
    assert beyond.sum() > 10 and keep[beyond].all()
    # the filter is symmetric: (i, j) dropped iff (j, i) dropped
    dropped = set(zip(rows[~keep].tolist(), fam.indices[~keep].tolist()))
    assert dropped == {(j, i) for i, j in dropped}


@pytest.mark.slow
def test_kinked_crack_and_several_segments():
    pts = cloud(2500, seed=1)
    h = 0.02 + 0.03 * pts[:, 0]             # per-point horizons: families not symmetric
    fam = family_search(pts, h)
    kinked = np.array([[[0.2, 0.3], [0.5, 0.5]], [[0.5, 0.5], [0.8, 0.45]],
                       [[0.1, 0.9], [0.9, 0.8]], [[0.6, 0.05], [0.6, 0.3]]])
    out, keep = check_removed(fam, pts, kinked, "kinked crack")
    assert (~keep).sum() > 200
    # removing segment by segment gives the same result as all at once
    step = fam
    for seg in kinked:
        step = remove_crossing(step, pts, seg[None])
    assert np.array_equal(step.offsets, out.offsets) and np.array_equal(step.indices, out.indices)


def test_touching_is_kept():
    """Crack along y = 0.5 from x = 0.25 to x = 0.75 through a dyadic lattice: the
    lattice points on the crack keep their bonds, bonds through the tips are
    kept, bonds collinear with the crack are kept, bonds across it are dropped."""
    g = np.arange(0, 1.0001, 0.0625)
    pts = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)
    fam = family_search(pts, 0.19)             # up to three lattice steps
    crack = np.array([[[0.25, 0.5], [0.75, 0.5]]])
    out, keep = check_removed(fam, pts, crack, "lattice crack")
    rows = np.repeat(np.arange(len(fam)), fam.counts)
    p, q = pts[rows], pts[fam.indices]
    on_line = (p[:, 1] == 0.5) | (q[:, 1] == 0.5)
    assert on_line.sum() > 100 and keep[on_line].all(), "a point on the crack keeps its bonds"
    across = ((p[:, 1] - 0.5) * (q[:, 1] - 0.5) < 0)
    xc = p[:, 0] + (q[:, 0] - p[:, 0]) * (0.5 - p[:, 1]) / np.where(across, q[:, 1] - p[:, 1], 1.0)
    inside = across & (xc > 0.25) & (xc < 0.75)
    through_tip = across & ((xc == 0.25) | (xc == 0.75))
    outside = across & ((xc < 0.25) | (xc > 0.75))
    assert inside.sum() > 100 and not keep[inside].any(), "bonds across the crack are cut"
    assert through_tip.sum() >= 8 and keep[through_tip].all(), "bonds through a tip are kept"
    assert outside.sum() > 50 and keep[outside].all()


def test_explicit_touching_cases():
    pts = np.array([[0.5, 0.5],        # 0: on the crack
                    [0.5, 0.625],      # 1: above it
                    [0.5, 0.375],      # 2: below it
                    [0.375, 0.375],    # 3, 4: bond through the tip (0.5, 0.5) of the second crack
                    [0.625, 0.625],
                    [0.0, 0.5],        # 5, 6: collinear with the first crack, overlapping it
                    [0.125, 0.5]])
    fam = family_search(pts, 1.0, method="brute")
    cracks = np.array([[[0.0625, 0.5], [0.9375, 0.5]], [[0.5, 0.5], [0.5, 0.5625]]])
    out, keep = check_removed(fam, pts, cracks[:1], "horizontal crack")
    # 0 keeps all its bonds; 1-2 cross; 5-6 lie on the line
    assert set(out.row(0).tolist()) == set(fam.row(0).tolist())
    assert 2 not in out.row(1) and 1 not in out.row(2)
    assert 6 in out.row(5) and 5 in out.row(6)
    out2, _ = check_removed(fam, pts, cracks[1:], "vertical crack from (0.5, 0.5)")
    assert 4 in out2.row(3) and 3 in out2.row(4), "a bond through the crack tip is kept"


def test_last_points_without_bonds():
    """Trailing points with empty families (and empty rows in between)."""
    pts = np.vstack([cloud(500, seed=2) * 0.5, [[5.0, 5.0], [9.0, 9.0]]])
    pts = np.vstack([[[-5.0, -5.0]], pts])
    fam = family_search(pts, 0.05)
    assert fam.counts[0] == 0 and fam.counts[-1] == 0 and fam.counts[-2] == 0
    check_removed(fam, pts, [[[0.1, 0.0], [0.3, 0.5]]], "trailing empty rows")


def test_no_segments_and_no_bonds():
    pts = cloud(200, seed=3)
    fam = family_search(pts, 0.1)
    out = remove_crossing(fam, pts, np.zeros((0, 2, 2)))
    assert np.array_equal(out.offsets, fam.offsets) and np.array_equal(out.indices, fam.indices)
    lonely = family_search(pts, 1e-4)
    assert len(lonely.indices) == 0
    out = remove_crossing(lonely, pts, [[[0.0, 0.0], [1.0, 1.0]]])
    assert np.array_equal(out.offsets, lonely.offsets) and len(out.indices) == 0
    empty = family_search(np.zeros((0, 2)), 0.1)
    assert len(remove_crossing(empty, np.zeros((0, 2)), [[[0.0, 0.0], [1.0, 1.0]]])) == 0
    # a crack far from every bond removes nothing
    out = remove_crossing(fam, pts, [[[3.0, 3.0], [4.0, 4.0]]])
    assert np.array_equal(out.indices, fam.indices)


def test_errors():
    pts = cloud(100, seed=4)
    crack = [[[0.2, 0.5], [0.8, 0.5]]]
    periodic = family_search(pts, 0.1, period=[1.0, 1.0])
    with pytest.raises(ValueError, match="periodic"):
        remove_crossing(periodic, pts, crack)
    pts3 = np.random.default_rng(0).random((100, 3))
    fam3 = family_search(pts3, 0.2)
    with pytest.raises(ValueError, match=r"\(100, 2\).*\(100, 3\)"):
        remove_crossing(fam3, pts3, crack)
    fam = family_search(pts, 0.1)
    with pytest.raises(ValueError, match=r"\(100, 2\).*\(99, 2\)"):
        remove_crossing(fam, pts[:99], crack)


def test_bond_through_an_inner_vertex_of_a_polyline_is_cut():
    """A bond through the shared vertex of two crack segments crosses the crack
    when the segments leave on opposite sides of it; through a tip it only touches."""
    pts = np.array([[1.0, -0.5], [1.0, 0.5], [3.0, -0.5], [3.0, 0.5]])
    fam = family_search(pts, 1.5)
    polyline = [[[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [2.0, 0.0]], [[2.0, 0.0], [4.0, 0.0]]]
    assert len(remove_crossing(fam, pts, polyline).indices) == 0
    # a "^" kink at the bond: its legs leave on both sides of the bond, which it cuts
    apex = [[[0.0, -1.0], [1.0, 0.0]], [[1.0, 0.0], [2.0, -1.0]]]
    assert [0, 1] not in remove_crossing(fam, pts, apex).pairs().tolist()
    # a "<" kink whose legs both leave on the left of the bond: touching, kept
    kink = [[[0.0, -1.0], [1.0, 0.0]], [[1.0, 0.0], [0.0, 1.0]]]
    kept = remove_crossing(fam, pts, kink).pairs().tolist()
    assert [0, 1] in kept and [1, 0] in kept
    # the crack's tip on the bond: touching, kept
    tip = remove_crossing(fam, pts, [[[0.0, 0.0], [1.0, 0.0]]]).pairs().tolist()
    assert [0, 1] in tip and [2, 3] in tip


def test_segments_of_the_wrong_shape_are_refused():
    pts = np.array([[0.0, 0.0], [1.0, 0.0]])
    with pytest.raises(ValueError, match=r"\(s, 2, 2\)"):
        remove_crossing(family_search(pts, 1.5), pts, np.zeros((3, 2, 3)))
