"""The numba kernels of the 3-D smoothed gradients against scipy products and a dict."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from cnem.assembly import _facet_kernels as FK


@pytest.mark.parametrize("nch", [1, 4])
def test_weighted_rows_match_scipy_on_one_pattern(nch):
    """``X_c = W_c @ V`` for three weight matrices on one pattern, each equal to scipy's
    product (bit for bit: the same sums in the same order), all on the union pattern
    (with the entries that cancel kept), rows sorted."""
    rng = np.random.default_rng(nch)
    m, q, n = 30, 90, 25
    W = sp.random(m, q, density=0.08, random_state=rng, format="csr")
    W.sort_indices()
    weight = rng.uniform(-1, 1, (W.nnz, 3))
    weight[::7, 0] = 0.0                              # a component that vanishes
    V = sp.random(q, n, density=0.2, random_state=rng, format="csr")
    V.data = rng.uniform(0, 1, V.nnz)
    indptr, indices, data = FK.weighted_rows(W.indptr.astype(np.int64), W.indices, weight,
                                             V.indptr.astype(np.int64), V.indices, V.data, n,
                                             nch)
    union = (abs(W) @ abs(V)).tocsr()
    union.sort_indices()
    np.testing.assert_array_equal(indptr, union.indptr)
    np.testing.assert_array_equal(indices, union.indices)
    for c in range(3):
        Wc = sp.csr_matrix((weight[:, c], W.indices, W.indptr), shape=W.shape)
        expected = (Wc @ V).toarray()
        got = sp.csr_matrix((data[c], indices, indptr), shape=(m, n)).toarray()
        np.testing.assert_array_equal(got, expected)


def test_reverse_edges_match_a_dict():
    """The twin of each directed edge (same owner, ends swapped, exact coordinates) is
    the first such edge, -1 if none; near misses (one bit off, another owner) are not
    twins."""
    rng = np.random.default_rng(0)
    corners = rng.uniform(-1, 1, (12, 3))
    e = 400
    owner = rng.integers(0, 5, e)
    ends = rng.integers(0, 12, (e, 2))
    p, q = corners[ends[:, 0]].copy(), corners[ends[:, 1]].copy()
    p[::50, 1] = np.nextafter(p[::50, 1], 2.0)        # one bit off: another point
    first = {}
    for i in range(e):
        first.setdefault((owner[i], p[i].tobytes(), q[i].tobytes()), i)
    expected = [first.get((owner[i], q[i].tobytes(), p[i].tobytes()), -1) for i in range(e)]
    got = FK.reverse_edges(owner.astype(np.int64), p.view(np.uint64), q.view(np.uint64))
    np.testing.assert_array_equal(got, expected)
    assert (got >= 0).sum() > 50 and (got < 0).sum() > 50
