"""The system on the free dofs against scipy's fancy indexing and skfem.condense."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import skfem
from skfem.models.poisson import laplace

from cnem._parallel import always_parallel
from cnem.solvers.condensation import (FreeBlock, condensed_system, free_dofs, free_system,
                                        principal_submatrix)
from cnem.solvers.constrained import solve_constrained
from cnem.solvers.linsolve import solve_spd
from cnem.solvers.symmetric import UpperTriangle
from cnem.errors import InputError

N = 60


def _matrix(seed, fmt):
    """A random non-symmetric (N, N) matrix with empty rows (3, 10, 17, ...)."""
    rng = np.random.default_rng(seed)
    nnz = 400
    rows, cols = rng.integers(0, N, nnz), rng.integers(0, N, nnz)
    rows[rows % 7 == 3] = 0
    return sp.coo_matrix((rng.uniform(-1, 1, nnz), (rows, cols)), shape=(N, N)).asformat(fmt)


def _unsorted_with_duplicates(seed, fmt):
    """A compressed matrix whose index runs are reversed and carry repeated entries."""
    A = _matrix(seed, fmt)
    ptr, idx, data = A.indptr, A.indices, A.data
    new_idx, new_data, new_ptr = [], [], [0]
    for r in range(N):
        run_idx, run_data = idx[ptr[r]:ptr[r + 1]][::-1], data[ptr[r]:ptr[r + 1]][::-1]
        if len(run_idx):                                   # split the first entry in two
            run_idx = np.concatenate([run_idx, run_idx[:1]])
            run_data = np.concatenate([run_data / 2, run_data[:1] / 2])
            run_data[1:-1] *= 2
        new_idx.append(run_idx)
        new_data.append(run_data)
        new_ptr.append(new_ptr[-1] + len(run_idx))
    M = type(A)((np.concatenate(new_data), np.concatenate(new_idx).astype(np.int32),
                 np.array(new_ptr)), shape=(N, N))
    assert not M.has_canonical_format
    return M, A


FIXED = {"some": np.array([5, 0, 17, 5, 59, 3]), "none": np.array([], dtype=int),
         "all": np.arange(N), "all twice": np.concatenate([np.arange(N)] * 2)}


def _check(K, reference, D, parallel):
    rng = np.random.default_rng(len(D))
    f, x = rng.uniform(-1, 1, N), rng.uniform(-1, 1, N)
    if parallel:
        with always_parallel():
            A, b, x_out, I = condensed_system(K, f, x=x, D=D)
    else:
        A, b, x_out, I = condensed_system(K, f, x=x, D=D)
    A_ref, b_ref, _, I_ref = skfem.condense(reference.tocsr(), f, x=x, D=np.unique(D))
    np.testing.assert_array_equal(I, I_ref)
    assert A.shape == A_ref.shape and A.format == (K.format if K.format == "csc" else "csr")
    scale = abs(reference).max()
    np.testing.assert_allclose(A.toarray(), A_ref.toarray(), rtol=0, atol=1e-14 * scale)
    np.testing.assert_allclose(b, b_ref, rtol=0, atol=1e-14 * scale * N)
    assert x_out is x
    for r in range(A.shape[0]):                            # sorted, no duplicates
        assert np.all(np.diff(A.indices[A.indptr[r]:A.indptr[r + 1]]) > 0)


@pytest.mark.parametrize("parallel", [False, True])
@pytest.mark.parametrize("fixed", list(FIXED))
@pytest.mark.parametrize("fmt", ["csr", "csc", "coo"])
def test_condense_matches_skfem(fmt, fixed, parallel):
    K = _matrix(1, fmt)
    _check(K, K, FIXED[fixed], parallel)


@pytest.mark.parametrize("parallel", [False, True])
@pytest.mark.parametrize("fmt", ["csr", "csc"])
def test_condense_of_unsorted_matrix_with_duplicates(fmt, parallel):
    K, canonical = _unsorted_with_duplicates(2, fmt)
    _check(K, canonical, FIXED["some"], parallel)


@pytest.mark.parametrize("fmt", ["csr", "csc"])
def test_principal_submatrix_matches_fancy_indexing(fmt):
    A = _matrix(3, fmt)
    keep = np.flatnonzero(np.random.default_rng(3).random(N) < 0.6)
    mask = np.zeros(N, dtype=bool)
    mask[keep] = True
    expected = A.tocsr()[keep][:, keep].toarray()
    for kept in (keep, mask):
        S = principal_submatrix(A, kept)
        assert S.format == fmt and S.indices.dtype == np.int32
        np.testing.assert_array_equal(S.toarray(), expected)


def _symmetric(seed, fmt):
    """A random SPD (N, N) matrix: a diagonally dominant symmetric pattern."""
    A = _matrix(seed, "csr")
    S = A + A.T
    S = (S + sp.diags(abs(S).sum(axis=1).A1 + 1.0)).tocsr()
    return UpperTriangle.from_matrix(S) if fmt == "upper" else S.asformat(fmt)


@pytest.mark.parametrize("parallel", [False, True])
@pytest.mark.parametrize("fixed", list(FIXED))
@pytest.mark.parametrize("fmt", ["csr", "csc", "upper"])
def test_free_block_is_the_condensed_matrix(fmt, fixed, parallel):
    """The block's products, entries, count and sub-blocks are those of skfem.condense's
    matrix; its right-hand side and free dofs too; from the whole matrix or from its
    upper triangle alone (`UpperTriangle`)."""
    K, D = _symmetric(7, fmt), FIXED[fixed]
    rng = np.random.default_rng(8)
    f, x = rng.uniform(-1, 1, N), rng.uniform(-1, 1, N)
    A_ref, b_ref, _, I_ref = skfem.condense(K.tocsr(), f, x=x, D=np.unique(D))
    if parallel:
        with always_parallel():
            A, b, I = free_system(K, f, x=x, D=D)
    else:
        A, b, I = free_system(K, f, x=x, D=D)
    scale = abs(K.tocsr()).max()
    np.testing.assert_array_equal(I, I_ref)
    np.testing.assert_array_equal(A.free, I_ref)
    np.testing.assert_allclose(b, b_ref, rtol=0, atol=1e-14 * scale * N)
    assert A.shape == A_ref.shape and A.nnz == A_ref.nnz
    v = rng.uniform(-1, 1, len(I))
    np.testing.assert_allclose(A @ v, A_ref @ v, rtol=0, atol=1e-14 * scale * N)
    np.testing.assert_allclose(A.rmatvec(v), A_ref @ v, rtol=0, atol=1e-14 * scale * N)
    np.testing.assert_array_equal(A.matrix().toarray(), A_ref.toarray())
    assert A.matrix() is A.matrix()                         # formed once
    keep = np.arange(0, len(I), 3)
    np.testing.assert_array_equal(A.submatrix(keep).toarray(),
                                  A_ref[keep][:, keep].toarray())


def test_free_block_of_every_dof_is_the_matrix_itself():
    K = _symmetric(9, "csr")
    block = FreeBlock(K)
    assert block.matrix() is K and block.nnz == K.nnz
    v = np.random.default_rng(9).uniform(-1, 1, N)
    np.testing.assert_allclose(block @ v, K @ v, rtol=0, atol=1e-14 * abs(K).max() * N)
    U = UpperTriangle.from_matrix(K)
    block = FreeBlock(U)
    assert block.upper() is U and block.nnz == K.nnz
    np.testing.assert_array_equal(block.matrix().toarray(), K.toarray())
    np.testing.assert_allclose(block @ v, K @ v, rtol=0, atol=1e-14 * abs(K).max() * N)


@pytest.mark.parametrize("fixed", ["some", "none"])
def test_constrained_solve_of_the_upper_triangle_is_the_full_one(fixed):
    """solve_constrained given K's upper triangle alone gives the solution given K."""
    K, D = _symmetric(11, "csr"), np.unique(FIXED[fixed])
    rng = np.random.default_rng(12)
    f, values = rng.uniform(-1, 1, N), rng.uniform(-1, 1, len(D))
    expected = solve_constrained(K, f, D, values, points=None)
    got = solve_constrained(UpperTriangle.from_matrix(K), f, D, values, points=None)
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


@pytest.mark.parametrize("method", ["direct", "amg"])
def test_solve_on_the_free_block_is_the_condensed_solve(method):
    """solve_spd on a FreeBlock gives the solution of skfem.condense's system; with a
    preconditioner matrix the iterative path never forms the block's entries."""
    side = 30
    K = skfem.asm(laplace,
                  skfem.Basis(skfem.MeshTri.init_tensor(*[np.linspace(0, 1, side)] * 2),
                              skfem.ElementTriP1()))
    D = np.arange(side)                                     # the nodes on y = 0
    f, x = np.ones(K.shape[0]), np.zeros(K.shape[0])
    x[D] = 0.5
    A, b, I = free_system(K, f, x=x, D=D)
    A_ref, b_ref, _, _ = skfem.condense(K, f, x=x, D=D)
    u = solve_spd(A, b, method=method, tol=1e-12, preconditioner=A_ref.copy())
    expected = sp.linalg.spsolve(A_ref.tocsc(), b_ref)
    np.testing.assert_allclose(u, expected, rtol=0, atol=1e-9 * np.abs(expected).max())
    assert (A._matrix is None) == (method == "amg")


def test_free_dofs_is_the_complement():
    fixed = np.array([3, 3, 0, 9])
    np.testing.assert_array_equal(free_dofs(10, fixed), np.setdiff1d(np.arange(10), fixed))
    np.testing.assert_array_equal(free_dofs(4, []), np.arange(4))


@pytest.mark.parametrize("D", [np.array([0, N]), np.array([-1]), np.array([1.0, 2.0]),
                               np.array([True, False])])
def test_bad_fixed_dofs_raise(D):
    K = _matrix(4, "csr")
    with pytest.raises(InputError, match="fixed dofs"):
        condensed_system(K, np.zeros(N), x=np.zeros(N), D=D)


@pytest.mark.parametrize("keep", [np.array([2, 1]), np.array([1, 1]), np.array([0, N]),
                                  np.ones(N - 1, dtype=bool), np.array([0.5])])
def test_bad_kept_dofs_raise(keep):
    with pytest.raises(InputError, match="keep"):
        principal_submatrix(_matrix(5, "csr"), keep)


def test_bad_matrix_and_vectors_raise():
    K = _matrix(6, "csr")
    with pytest.raises(InputError, match="sparse"):
        condensed_system(K.toarray(), np.zeros(N), x=np.zeros(N), D=[0])
    with pytest.raises(InputError, match="square"):
        principal_submatrix(K[:-1], [0])
    with pytest.raises(InputError, match="x: expected shape"):
        condensed_system(K, np.zeros(N), x=np.zeros(N - 1), D=[0])
    with pytest.raises(InputError, match="f: expected shape"):
        free_system(K, np.zeros(N + 1), x=np.zeros(N), D=[0])
    with pytest.raises(InputError, match="keep"):
        FreeBlock(K, np.array([3, 2]))
