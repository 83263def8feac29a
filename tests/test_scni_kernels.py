"""Kernels of the SCNI boundary quadrature against plain NumPy references."""

from __future__ import annotations

import numpy as np
import pytest

from cnem.assembly import _kernels as K


@pytest.mark.parametrize("seed", range(4))
def test_edge_pieces_match_a_sort_of_all_crossings(seed):
    rng = np.random.default_rng(seed)
    counts = rng.integers(0, 6, size=200)
    counts[:3] = 0
    offsets = np.concatenate([[0], np.cumsum(counts)])
    t = rng.random(offsets[-1])
    dup = np.arange(1, len(t), 7)
    t[dup] = t[dup - 1]                    # circles crossing an edge at the same point
    ne = len(counts)
    edge_ref = np.concatenate([np.repeat(np.arange(ne), counts), np.arange(ne), np.arange(ne)])
    t_ref = np.concatenate([t, np.zeros(ne), np.ones(ne)])
    order = np.lexsort((t_ref, edge_ref))
    edge_ref, t_ref = edge_ref[order], t_ref[order]
    same = edge_ref[1:] == edge_ref[:-1]
    edge, t0, t1 = K.edge_pieces(offsets, t.copy())
    np.testing.assert_array_equal(edge, edge_ref[:-1][same])
    np.testing.assert_array_equal(t0, t_ref[:-1][same])
    np.testing.assert_array_equal(t1, t_ref[1:][same])


def test_unique_rows_matches_numpy_unique():
    rng = np.random.default_rng(0)
    base = rng.integers(0, 30, size=(40, 5)).astype(np.float64)
    base[0, 0] = -0.0                      # bit for bit: -0.0 and 0.0 differ
    base[1, 0] = 0.0
    rows = np.ascontiguousarray(base[rng.integers(0, 40, size=500)])
    first, occurrence = K.unique_rows(rows.view(np.uint64))
    np.testing.assert_array_equal(rows.view(np.uint64)[first][occurrence], rows.view(np.uint64))
    assert len(np.unique(rows.view(np.uint64)[first], axis=0)) == len(first)
    assert len(first) == len(np.unique(rows.view(np.uint64), axis=0))
    assert (np.diff(first) > 0).all()      # order of first appearance
    empty_first, empty_occ = K.unique_rows(np.zeros((0, 5), dtype=np.uint64))
    assert len(empty_first) == 0 and len(empty_occ) == 0
