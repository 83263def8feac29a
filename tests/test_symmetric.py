"""The upper-triangle storage of a symmetric matrix against scipy's CSR: products, the
symmetric Gauss-Seidel sweep against a plain Python one, the free block's triangle."""

from __future__ import annotations

import numba
import numpy as np
import pytest
import scipy.sparse as sp

from cnem._parallel import always_parallel
from cnem.errors import InputError
from cnem.solvers.condensation import FreeBlock, principal_submatrix
from cnem.solvers.symmetric import UpperTriangle


def random_symmetric(n, seed, density=0.05):
    """A random symmetric ``(n, n)`` CSR matrix with a dominant positive diagonal."""
    B = sp.random(n, n, density=density, random_state=seed, format="csr")
    B.data -= 0.5
    return (B + B.T + n * density * sp.eye(n) + sp.diags(np.arange(n) % 3.0)).tocsr()


def gauss_seidel(A, b, x, order):
    """Plain Gauss-Seidel over the rows in ``order`` (the reference)."""
    A = A.toarray()
    x = x.copy()
    for i in order:
        x[i] += (b[i] - A[i] @ x) / A[i, i]
    return x


@pytest.mark.parametrize("n, seed", [(1, 0), (7, 1), (200, 2), (1500, 3)])
def test_product_is_scipys(n, seed):
    A = random_symmetric(n, seed)
    U = UpperTriangle.from_matrix(A)
    x = np.random.default_rng(seed).standard_normal(n)
    assert U.nnz == sp.triu(A).nnz and U.shape == A.shape
    np.testing.assert_allclose(U @ x, A @ x, rtol=0, atol=1e-13 * np.abs(A).sum(axis=1).max())
    assert (abs(U.tocsr() - A)).max() == 0.0


def test_parallel_product_does_not_depend_on_the_threads():
    A = random_symmetric(3000, 4)
    U = UpperTriangle.from_matrix(A)
    x = np.random.default_rng(4).standard_normal(3000)
    before = numba.get_num_threads()
    with always_parallel():
        try:
            numba.set_num_threads(1)
            one = U @ x
            numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
            many = U @ x
        finally:
            numba.set_num_threads(before)
    np.testing.assert_allclose(one, A @ x, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(many, A @ x, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("n, seed", [(1, 5), (50, 6), (400, 7)])
def test_sweep_is_forward_then_backward_gauss_seidel(n, seed):
    A = random_symmetric(n, seed)
    rng = np.random.default_rng(seed)
    b, x = rng.standard_normal(n), rng.standard_normal(n)
    expected = gauss_seidel(A, b, gauss_seidel(A, b, x, range(n)), range(n - 1, -1, -1))
    U = UpperTriangle.from_matrix(A)
    residual = U.sweep(b, x)
    np.testing.assert_allclose(x, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
    np.testing.assert_allclose(residual, b - A @ x, rtol=0,
                               atol=1e-12 * (np.abs(b).max() + np.abs(A @ x).max()))


def test_sweep_from_zero_and_without_residual_is_the_same_sweep():
    A = random_symmetric(300, 11)
    b = np.random.default_rng(11).standard_normal(300)
    U = UpperTriangle.from_matrix(A)
    x, y = np.zeros(300), np.zeros(300)
    residual = U.sweep(b, x)
    np.testing.assert_array_equal(U.sweep(b, y, from_zero=True), residual)
    np.testing.assert_array_equal(y, x)
    assert U.sweep(b, x, residual=False) is None
    U.sweep(b, y)
    np.testing.assert_array_equal(x, y)


def test_sweeps_converge_to_the_solution():
    A = random_symmetric(300, 8)
    b = np.random.default_rng(8).standard_normal(300)
    U, x = UpperTriangle.from_matrix(A), np.zeros(300)
    for _ in range(200):
        U.sweep(b, x)
    np.testing.assert_allclose(A @ x, b, rtol=0, atol=1e-10)


def test_row_without_its_diagonal_is_refused():
    with pytest.raises(InputError, match="diagonal"):
        UpperTriangle(np.array([0, 1, 1]), np.array([1]), np.array([1.0]))


@pytest.mark.parametrize("fmt", ["csr", "csc"])
def test_free_blocks_triangle_is_the_submatrixs(fmt):
    A = random_symmetric(500, 9).asformat(fmt)
    free = np.flatnonzero(np.random.default_rng(9).random(500) < 0.8)
    block = FreeBlock(A, free)
    x = np.random.default_rng(10).standard_normal(len(free))
    before = block @ x
    sub = principal_submatrix(A.tocsr(), free)
    assert abs(block.upper().tocsr() - sub).max() == 0.0
    np.testing.assert_allclose(block @ x, before, rtol=1e-12, atol=1e-12)   # now on the triangle
    np.testing.assert_allclose(before, sub @ x, rtol=1e-12, atol=1e-12)


def test_principal_view_is_the_submatrixs_triangle():
    """The view of a triangle on some rows multiplies and sweeps as the triangle of the
    principal submatrix (formed apart) does, its arrays shared, not copied."""
    A = random_symmetric(400, 11)
    keep = np.flatnonzero(np.random.default_rng(11).random(400) < 0.7)
    U = UpperTriangle.from_matrix(A)
    view = U.principal(keep)
    sub = UpperTriangle.from_matrix(principal_submatrix(A, keep))
    assert view.shape == sub.shape and view.data is U.data
    rng = np.random.default_rng(12)
    x, b = rng.standard_normal(len(keep)), rng.standard_normal(len(keep))
    np.testing.assert_allclose(view @ x, sub @ x, rtol=0, atol=1e-12)
    assert abs(view.tocsr() - sub.tocsr()).max() == 0.0
    for from_zero in (False, True):
        start = np.zeros(len(keep)) if from_zero else x
        got, want = start.copy(), start.copy()
        r_got = view.sweep(b, got, from_zero=from_zero)
        r_want = sub.sweep(b, want, from_zero=from_zero)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
        np.testing.assert_allclose(r_got, r_want, rtol=0, atol=1e-11)
        np.testing.assert_allclose(r_got, b - sub @ got, rtol=0, atol=1e-11)
    with pytest.raises(InputError, match="keep"):
        U.principal(keep[::-1])
