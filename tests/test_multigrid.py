"""The parallel multigrid cycle (`cnem.solvers.multigrid`): its kernels against scipy and
a plain-Python Gauss-Seidel, the cycle's symmetry and definiteness (what CG needs), its
independence of the thread count, and CG with it on a P1 elasticity system."""
import contextlib

import numba
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from cnem._parallel import always_parallel
from cnem.solvers import _multigrid_kernels as kernels
from cnem.solvers.linsolve import rigid_modes
from cnem.solvers.multigrid import _csr, hierarchy, parallel_operator
from cnem.errors import InputError


def random_spd(n, seed):
    """A sparse SPD matrix with rows of every length (empty off-diagonal rows too)."""
    rng = np.random.default_rng(seed)
    B = sp.random(n, n, density=4.0 / n, random_state=rng, format="csr")
    return (B @ B.T + sp.eye(n)).tocsr()


def p1_elasticity(k):
    """P1 plane-strain stiffness of the unit square (k x k nodes), clamped at x = 0:
    the free block, its rigid modes and a load."""
    from skfem import Basis, ElementTriP1, ElementVector, MeshTri, asm, condense
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    mesh = MeshTri.init_tensor(np.linspace(0, 1, k), np.linspace(0, 1, k))
    basis = Basis(mesh, ElementVector(ElementTriP1()))
    K = asm(linear_elasticity(*lame_parameters(1.0, 0.3)), basis)
    D = basis.get_dofs(lambda x: x[0] < 1e-12).all()
    f = np.zeros(K.shape[0])
    f[basis.get_dofs(lambda x: x[0] > 1 - 1e-12).nodal["u^1"]] = 1.0
    A, b, _, interior = condense(K, f, D=D)
    points = mesh.p.T
    # skfem numbers the dofs node by node (u^1, u^2 of each node): interleaved
    return A.tocsr(), b, rigid_modes(points)[interior]


def gauss_seidel_reference(A, b, x, starts, backward):
    """One hybrid l1 Gauss-Seidel sweep written out row by row with dense rows."""
    A = A.toarray()
    x, before = x.copy(), x.copy()
    for lo, hi in zip(starts[:-1], starts[1:]):
        inside = np.zeros(len(b), dtype=bool)
        inside[lo:hi] = True
        for i in (range(hi - 1, lo - 1, -1) if backward else range(lo, hi)):
            d = A[i, i] + np.abs(A[i, ~inside]).sum()
            s = b[i] - A[i, inside] @ x[inside] - A[i, ~inside] @ before[~inside]
            x[i] += s / d
    return x


@pytest.mark.parametrize("parallel", [False, True])
def test_products_equal_scipys(parallel):
    A = random_spd(300, 0)[:, :250][:280]            # rectangular, rows of 0..n entries
    rows, rng = _csr(A), np.random.default_rng(1)
    x, b, out = rng.random(250), rng.random(280), rng.random(280)
    start = out.copy()
    acc = out.copy()
    with always_parallel() if parallel else contextlib.nullcontext():
        kernels.multiply(rows.indptr, rows.indices, rows.data, x, out, False)
        kernels.multiply(rows.indptr, rows.indices, rows.data, x, acc, True)
        S = random_spd(280, 2)
        square, r = _csr(S), np.empty(280)
        kernels.residual(square.indptr, square.indices, square.data, b, b, r)
    np.testing.assert_allclose(out, A @ x, rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(acc, start + A @ x, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(r, b - S @ b, rtol=1e-13, atol=1e-13)


def test_accumulating_product_adds_to_the_output():
    A = random_spd(200, 3)
    rows, rng = _csr(A), np.random.default_rng(4)
    x, start = rng.random(200), rng.random(200)
    out = start.copy()
    kernels.multiply(rows.indptr, rows.indices, rows.data, x, out, True)
    np.testing.assert_allclose(out, start + A @ x, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("blocks", [1, 3, 7])
@pytest.mark.parametrize("backward", [False, True])
def test_sweep_equals_the_row_by_row_reference(blocks, backward):
    A = random_spd(120, 5)
    rows, rng = _csr(A), np.random.default_rng(6)
    b, x0 = rng.random(120), rng.random(120)
    starts = np.arange(blocks + 1, dtype=np.int64) * 120 // blocks
    diagonal = np.empty(120)
    kernels.l1_diagonal(rows.indptr, rows.indices, rows.data, starts, diagonal)
    x = x0.copy()
    kernels.sweep(rows.indptr, rows.indices, rows.data, diagonal, starts, b, x, x0.copy(),
                  backward)
    np.testing.assert_allclose(x, gauss_seidel_reference(A, b, x0, starts, backward),
                               rtol=1e-12, atol=1e-12)


def test_one_block_sweep_is_plain_gauss_seidel():
    A = random_spd(80, 7)
    b = np.random.default_rng(8).random(80)
    rows, starts = _csr(A), np.array([0, 80])
    diagonal = np.empty(80)
    kernels.l1_diagonal(rows.indptr, rows.indices, rows.data, starts, diagonal)
    np.testing.assert_array_equal(diagonal, A.diagonal())
    x = np.zeros(80)
    kernels.sweep(rows.indptr, rows.indices, rows.data, diagonal, starts, b, x, x.copy(), False)
    # forward Gauss-Seidel from zero solves the lower triangle: (D + L) x = b
    np.testing.assert_allclose(x, spla.spsolve_triangular(sp.tril(A).tocsr(), b), rtol=1e-12)


@pytest.fixture(scope="module")
def system():
    return p1_elasticity(60)                       # 7080 free dofs


@pytest.mark.parametrize("top", [False, True])
def test_cycle_is_symmetric_positive_definite(system, top):
    A, _, modes = system
    M = hierarchy(A, modes, top=A if top else None)
    assert M.levels >= 3
    rng = np.random.default_rng(9)
    for _ in range(3):
        x, y = rng.standard_normal(A.shape[0]), rng.standard_normal(A.shape[0])
        Mx, My = M.matvec(x), M.matvec(y)
        assert abs(y @ Mx - x @ My) <= 1e-12 * np.linalg.norm(x) * np.linalg.norm(Mx)
        assert x @ Mx > 0


def test_cycle_does_not_depend_on_the_thread_count(system):
    A, b, modes = system
    with always_parallel():
        M = hierarchy(A, modes)
        before = numba.get_num_threads()
        try:
            numba.set_num_threads(1)
            one = M.matvec(b)
            numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
            many = M.matvec(b)
        finally:
            numba.set_num_threads(before)
    serial = M.matvec(b)                               # the serial copies (small system)
    np.testing.assert_array_equal(one, many)
    np.testing.assert_array_equal(one, serial)


def test_cg_with_the_cycle_solves_elasticity(system):
    A, b, modes = system
    exact = spla.spsolve(A.tocsc(), b)
    its = []
    x, info = spla.cg(parallel_operator(A), b, rtol=1e-10, atol=0.0, maxiter=200,
                      M=hierarchy(A, modes), callback=lambda _: its.append(1))
    assert info == 0 and len(its) < 40
    np.testing.assert_allclose(x, exact, rtol=0, atol=1e-8 * np.abs(exact).max())


def test_top_of_another_shape_is_refused(system):
    A, _, modes = system
    with pytest.raises(InputError, match="top: expected shape"):
        hierarchy(A, modes, top=sp.eye(A.shape[0] + 2, format="csr"))


def test_smoothing_with_another_top_equals_building_with_it(system):
    """`VCycle.smoothing_with` gives the cycle `hierarchy(..., top=)` builds, and leaves
    the original cycle as it was."""
    A, b, modes = system
    P = (A + sp.diags(0.1 * A.diagonal())).tocsr()           # a preconditioner matrix
    plain = hierarchy(P, modes)
    before = plain.matvec(b)
    np.testing.assert_array_equal(plain.smoothing_with(A).matvec(b),
                                  hierarchy(P, modes, top=A).matvec(b))
    np.testing.assert_array_equal(plain.matvec(b), before)
    with pytest.raises(InputError, match="top: expected shape"):
        plain.smoothing_with(sp.eye(A.shape[0] + 2, format="csr"))
