"""The numba sparse products of SCNI assembly against scipy's general products."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import pytest

from cnem.assembly import _sparse_kernels as SK


def _random_csr(rng, shape, density):
    A = sp.random(*shape, density=density, random_state=rng, format="csr")
    A.data = rng.uniform(-1, 1, A.nnz)
    return A


@pytest.mark.parametrize("nch", [1, 3, 16])
@pytest.mark.parametrize("c", [1, 3])
def test_weighted_gram_matches_scipy(c, nch):
    rng = np.random.default_rng(c + nch)
    m, ncol = 40, 25
    Q = _random_csr(rng, (c * m, ncol), 0.15)
    coeff = rng.uniform(-1, 1, (m, c, c))
    coeff[:, 0, -1] = 0.0                                  # some couplings absent
    W = sp.lil_matrix((c * m, c * m))
    for k in range(m):
        for a in range(c):
            for b in range(c):
                W[b * m + k, a * m + k] = coeff[k, a, b]
    expected = (Q.T @ W.tocsr() @ Q).toarray()
    T = Q.T.tocsr()
    indptr, indices, data = SK.weighted_gram(Q.indptr, Q.indices, Q.data, T.indptr, T.indices,
                                             T.data, coeff, m, ncol, nch)
    K = sp.csr_matrix((data, indices, indptr), shape=(ncol, ncol))
    np.testing.assert_allclose(K.toarray(), expected, atol=1e-13)
    for i in range(ncol):                                  # sorted, no duplicates
        row = indices[indptr[i]:indptr[i + 1]]
        assert np.all(np.diff(row) > 0)


@pytest.mark.parametrize("nch", [1, 5])
@pytest.mark.parametrize("same_values", [False, True])
def test_weighted_row_sums_match_scipy(nch, same_values):
    """X = Wx @ P Vx and Y = Wy @ P Vy (P: rows given in another order), one pattern,
    rows sorted; and the two steps of SCNI (points -> edges -> cells) give
    to_cells @ W @ phi."""
    rng = np.random.default_rng(nch)
    m, q, n = 30, 90, 20
    pattern = _random_csr(rng, (m, q), 0.1)
    wx = pattern.copy()
    wy = sp.csr_matrix((rng.uniform(-1, 1, pattern.nnz), pattern.indices, pattern.indptr),
                       shape=pattern.shape)
    vx = _random_csr(rng, (q, n), 0.2)
    vy = vx.copy() if same_values else sp.csr_matrix(
        (rng.uniform(-1, 1, vx.nnz), vx.indices, vx.indptr), shape=vx.shape)
    order = rng.permutation(q)                     # item p is row where[p] of the values
    where = np.empty(q, dtype=np.int64)
    where[order] = np.arange(q)
    px, py = vx[order], vy[order]
    indptr, indices, x, y = SK.weighted_row_sums(
        wx.indptr, wx.indices, wx.data, wy.data, where, px.indptr[:-1], px.indptr[1:],
        px.indices, px.data, py.data, nch)
    for got, w, v in ((x, wx, vx), (y, wy, vy)):
        got = sp.csr_matrix((got, indices, indptr), shape=(m, n))
        np.testing.assert_allclose(got.toarray(), (w @ v).toarray(), atol=1e-13)
    assert all(np.all(np.diff(indices[indptr[i]:indptr[i + 1]]) > 0) for i in range(m))
    # the second step: cells from edges
    to_cells = _random_csr(rng, (12, m), 0.2)
    ex = sp.csr_matrix((x, indices, indptr), shape=(m, n))
    ey = sp.csr_matrix((y, indices, indptr), shape=(m, n))
    indptr, indices, cx, cy = SK.weighted_row_sums(
        to_cells.indptr, to_cells.indices, to_cells.data, to_cells.data, np.arange(m),
        ex.indptr[:-1], ex.indptr[1:], ex.indices, ex.data, ey.data, nch)
    for got, w, v in ((cx, wx, vx), (cy, wy, vy)):
        got = sp.csr_matrix((got, indices, indptr), shape=(12, n))
        np.testing.assert_allclose(got.toarray(), (to_cells @ w @ v).toarray(), atol=1e-13)


@pytest.mark.parametrize("nch", [1, 4])
def test_weighted_row_sums_with_long_rows_and_far_columns(nch):
    """Rows summing hundreds of entries (the column tables grow) over columns up to
    10^7, duplicates among them, still equal W @ V."""
    rng = np.random.default_rng(7)
    m, q, n = 8, 60, 10_000_000
    w = _random_csr(rng, (m, q), 0.5)
    cols = rng.choice(n, 400, replace=False)                 # few distinct, far apart
    v = sp.csr_matrix((rng.uniform(-1, 1, (q, 40)).ravel(),
                       rng.choice(cols, (q, 40)).ravel(), np.arange(0, 40 * q + 1, 40)),
                      shape=(q, n))
    v.sum_duplicates()
    indptr, indices, x, y = SK.weighted_row_sums(
        w.indptr, w.indices, w.data, 2.0 * w.data, np.arange(q), v.indptr[:-1],
        v.indptr[1:], v.indices, v.data, v.data, nch)
    want = (w @ v).tocsr()
    want.sort_indices()
    np.testing.assert_array_equal(indptr, want.indptr)
    np.testing.assert_array_equal(indices, want.indices)
    np.testing.assert_allclose(x, want.data, atol=1e-13)
    np.testing.assert_allclose(y, 2.0 * want.data, atol=1e-13)


@pytest.mark.parametrize("nch", [1, 3, 16])
@pytest.mark.parametrize("grouped", [False, True])
def test_gradient_block_gram_matches_scipy(nch, grouped):
    """Vector operators spread from scalar gradients: K = Q^T W Q by 2 x 2 blocks,
    the couplings of a cell its weight times those of its group."""
    rng = np.random.default_rng(nch)
    m, n = 40, 25
    G = _random_csr(rng, (m, n), 0.2)
    gy = rng.uniform(-1, 1, G.nnz)
    count = 5 if grouped else m
    coeff = rng.uniform(-1, 1, (count, 4, 4))
    coeff[:, 1, 2] = 0.0
    group = rng.integers(0, count, m) if grouped else np.arange(m)
    weight = rng.uniform(0.5, 2.0, m) if grouped else np.ones(m)
    per_cell = weight[:, None, None] * coeff[group]
    # descriptor a = 2 c + d: component c, direction d, on dofs 2 j + c
    ops = []
    for c in range(2):
        for values in (G.data, gy):
            ops.append(sp.csr_matrix((values, G.indices * 2 + c, G.indptr), shape=(m, 2 * n)))
    expected = sum((ops[b].T @ sp.diags(per_cell[:, a, b]) @ ops[a]).toarray()
                   for a in range(4) for b in range(4))
    indptr, indices, data = SK.gradient_block_gram(G.indptr, G.indices, G.data, gy, coeff,
                                                   group, weight, n, nch)
    K = sp.csr_matrix((data, indices, indptr), shape=(2 * n, 2 * n))
    np.testing.assert_allclose(K.toarray(), expected, atol=1e-13)
    for i in range(2 * n):                                 # sorted, no duplicates
        assert np.all(np.diff(indices[indptr[i]:indptr[i + 1]]) > 0)


@pytest.mark.parametrize("nch", [1, 3, 16])
@pytest.mark.parametrize("d", [2, 3])
def test_gradient_block_upper_triangle_is_the_triangle_of_the_whole(d, nch):
    """The upper-triangle pattern and values of a symmetric gradient gram are those of
    the whole matrix's right of its diagonal, exactly (the same sums in the same order);
    a node in no cell keeps a stored zero diagonal, its row's first entry."""
    rng = np.random.default_rng(10 * d + nch)
    m, n = 40, 25
    G = _random_csr(rng, (m, n), 0.2)
    G = sp.csr_matrix((G.data, G.indices, G.indptr), shape=(m, n + 1))    # node n: no cell
    grads = np.vstack([G.data] + [rng.uniform(-1, 1, G.nnz) for _ in range(d - 1)])
    coeff = rng.uniform(-1, 1, (5, d * d, d * d))
    coeff = coeff + coeff.transpose(0, 2, 1)                  # a symmetric form
    group, weight = rng.integers(0, 5, m), rng.uniform(0.5, 2.0, m)
    indptr, indices, data = SK.gradient_block_gram_nd(G.indptr, G.indices, grads, coeff,
                                                      group, weight, n + 1, nch)
    whole = sp.triu(sp.csr_matrix((data, indices, indptr), shape=(d * (n + 1),) * 2), format="csr")
    whole.sort_indices()
    out_ptr, out_idx, *pattern = SK.gradient_block_pattern(G.indptr, G.indices, d, n + 1, nch,
                                                           True)
    t_ptr, t_row, t_pos = pattern[2:]
    upper = SK.gradient_block_values_nd(G.indptr, G.indices, grads, coeff, group, weight, t_ptr,
                                        t_row, t_pos, pattern[0], pattern[1], out_ptr, n + 1,
                                        nch, True)
    last = out_ptr[d * n]                                     # the lone node's d (d + 1) / 2
    assert len(upper) - last == d * (d + 1) // 2 and not upper[last:].any()
    np.testing.assert_array_equal(out_ptr[:d * n + 1], whole.indptr[:d * n + 1])
    np.testing.assert_array_equal(out_idx[:last], whole.indices)
    np.testing.assert_array_equal(upper[:last], whole.data)
    np.testing.assert_array_equal(out_idx[out_ptr[d * np.arange(n + 1)]], d * np.arange(n + 1))
