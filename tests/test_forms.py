"""`BilinearForm.assemble` against the operator products it stands for.

``A = sum_k A_k P_b^T D_ab P_a`` with the basis's descriptor operators ``P`` (values
at the cells' nodes, smoothed gradients): forms mixing values and gradients take
the general path, forms of vector gradients only the 2 x 2 block path; both must
give the product written out with scipy.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from skfem.helpers import dot, grad, sym_grad, ddot

import cases
from cnem.assembly import BilinearForm, CellBasis
from cnem.errors import FormError


def _reference(basis, pairs):
    """``sum over (a, b, coefficient) of P_b^T diag(dx * coefficient) P_a``."""
    ops = basis.operators
    out = sp.csr_matrix((basis.N, basis.N))
    for a, b, c in pairs:
        out = out + ops[b].T @ sp.diags(basis.dx * c) @ ops[a]
    return out.toarray()


@pytest.fixture(scope="module")
def model():
    return cases.model("three_rectangles_irregular")[2]


def test_scalar_mass_convection_and_diffusion(model):
    basis = CellBasis(model)
    x = basis.x[0]

    @BilinearForm
    def form(u, v, w):
        return 2.0 * u * v + w.x[0] * grad(u)[0] * v + dot(grad(u), grad(v))

    ref = _reference(basis, [(0, 0, 2.0 + 0 * x), (1, 0, x), (1, 1, 1 + 0 * x),
                             (2, 2, 1 + 0 * x)])
    np.testing.assert_allclose(form.assemble(basis).toarray(), ref, atol=1e-12 * abs(ref).max())
    # nodal integration: the mass matrix is diagonal, each node's cell areas
    mass = BilinearForm(lambda u, v, w: u * v).assemble(basis)
    np.testing.assert_allclose(mass.toarray(),
                               np.diag(np.bincount(model.cells.node, model.cells.area,
                                                   minlength=len(model.nodes))))


@pytest.mark.parametrize("with_mass", [False, True])
def test_vector_forms_block_and_general_paths(model, with_mass):
    """Elasticity-like gradient form (block path), plus a mass term (general path)."""
    basis = CellBasis(model, vector=True)
    lam = 1.0 + model.cells.region.astype(float)

    @BilinearForm
    def form(u, v, w):
        out = 2.0 * ddot(sym_grad(u), sym_grad(v)) + w.lam * grad(u)[0, 0] * grad(v)[1, 1]
        return out + (3.0 * dot(u, v) if with_mass else 0.0)

    one = np.ones(len(lam))
    # descriptors: u0, u1, du0/dx, du0/dy, du1/dx, du1/dy
    pairs = [(2, 2, 2 * one), (5, 5, 2 * one), (3, 3, one), (4, 4, one), (3, 4, one),
             (4, 3, one), (2, 5, lam)]
    if with_mass:
        pairs += [(0, 0, 3 * one), (1, 1, 3 * one)]
    ref = _reference(basis, pairs)
    got = form.assemble(basis, lam=lam).toarray()
    np.testing.assert_allclose(got, ref, atol=1e-12 * abs(ref).max())


def test_groups_evaluate_the_form_once_per_group(model):
    """Per-material keywords with ``groups`` give the matrix of the per-cell keywords."""
    basis = CellBasis(model, vector=True)
    region = model.cells.region
    lam_r = np.array([1.0, 2.5, 4.0])[:region.max() + 1]
    mu_r = np.array([0.5, 0.7, 0.9])[:region.max() + 1]

    @BilinearForm
    def form(u, v, w):
        return 2.0 * w.mu * ddot(sym_grad(u), sym_grad(v)) + w.lam * grad(u)[0, 0] * grad(v)[1, 1]

    ref = form.assemble(basis, lam=lam_r[region], mu=mu_r[region]).toarray()
    got = form.assemble(basis, groups=region, lam=lam_r, mu=mu_r).toarray()
    np.testing.assert_allclose(got, ref, atol=1e-13 * abs(ref).max())
    scalar = form.assemble(basis, groups=region, lam=lam_r, mu=0.5).toarray()
    np.testing.assert_allclose(scalar, form.assemble(basis, lam=lam_r[region], mu=0.5).toarray(),
                               atol=1e-13 * abs(ref).max())


def test_groups_are_checked(model):
    basis = CellBasis(model)
    m = len(model.cells.area)
    form = BilinearForm(lambda u, v, w: w.k * dot(grad(u), grad(v)))
    with pytest.raises(ValueError, match=rf"groups: expected \({m},\) non-negative integers"):
        form.assemble(basis, groups=np.zeros(m - 1, dtype=int), k=np.ones(1))
    with pytest.raises(ValueError, match="one value per group"):
        form.assemble(basis, groups=np.zeros(m, dtype=int), k=np.ones((2, 2)))
    with pytest.raises(ValueError, match="groups: index 1 but the keywords hold 1 values"):
        form.assemble(basis, groups=np.arange(m) % 2, k=np.ones(1))


def _basis_on_unsorted_gradients(rng, m=12, n=9, d=3):
    """A vector `CellBasis` on random gradient operators with reversed (unsorted) rows
    on different patterns, as 3-D smoothed gradients may come; and those operators."""
    from types import SimpleNamespace
    grads = [sp.random(m, n, density=0.4, format="csr", random_state=k) for k in range(d)]
    for g in grads:
        for i in range(m):
            lo, hi = g.indptr[i], g.indptr[i + 1]
            g.indices[lo:hi], g.data[lo:hi] = g.indices[lo:hi][::-1].copy(), g.data[lo:hi][::-1].copy()
        g.has_sorted_indices = False
    assert not all(np.array_equal(grads[0].indices, g.indices) for g in grads[1:])
    basis = CellBasis.from_operators(SimpleNamespace(nodes=rng.uniform(size=(n, d))),
                                     sp.identity(m, format="csr")[:, :n], grads,
                                     rng.uniform(0.5, 2.0, m), rng.uniform(size=(m, d)),
                                     vector=True)
    return basis, grads


def test_vector_operators_survive_scipy_sorting_one_of_them():
    """The components of a vector basis share their node operator's values: scipy's
    ``abs`` and ``+`` sort a non-canonical operand in place, which once reordered the
    values under the other components' unsorted indices (3-D F-bar's patches took
    ``abs`` of the u_0 gradients and corrupted u_1's and u_2's: an indefinite tangent).
    The basis spreads canonical copies; its inputs stay as they were."""
    rng = np.random.default_rng(3)
    basis, grads = _basis_on_unsorted_gradients(rng)
    inputs = [(g.indices.copy(), g.data.copy()) for g in grads]
    ops = basis.operators
    before = [op.toarray() for op in ops]
    for op in ops:
        abs(op) + op
    for op, old in zip(basis.operators, before):
        np.testing.assert_array_equal(op.toarray(), old)
    for g, (indices, data) in zip(grads, inputs):
        np.testing.assert_array_equal(g.indices, indices)
        np.testing.assert_array_equal(g.data, data)


def test_gradient_gram_of_3d_gradients_on_different_patterns():
    """3-D smoothed gradients may drop an exact zero along one axis only, so the axes'
    patterns differ: `gradient_gram` takes the node-block path on their union and
    gives the product written out with scipy, leaving the basis's operators as they
    were (unsorted node operators share their values with them)."""
    from cnem.assembly.forms import gradient_gram
    rng = np.random.default_rng(5)
    basis, _ = _basis_on_unsorted_gradients(rng)
    m, d = len(basis.dx), basis.dim
    before = [op.toarray() for op in basis.operators]
    coeff = rng.uniform(-1, 1, (m, d * d, d * d))
    ops = basis.operators[d:]
    ref = sum((ops[b].T @ sp.diags(basis.dx * coeff[:, a, b]) @ ops[a]).toarray()
              for a in range(d * d) for b in range(d * d))
    assert basis.component_gradients() is not None
    np.testing.assert_allclose(gradient_gram(basis, coeff).toarray(), ref,
                               atol=1e-12 * abs(ref).max())
    for op, old in zip(basis.operators, before):
        np.testing.assert_array_equal(op.toarray(), old)


@pytest.mark.parametrize("by_blocks", [True, False])
def test_gradient_gram_over_two_bases_in_one_pass(model, by_blocks):
    """`GradientGram` over the cells of two bases (node blocks on one kept pattern, or by
    descriptors for operators set otherwise) equals the two products written out with
    scipy and added, for two sets of coefficients on the same pattern."""
    from cnem.assembly.forms import GradientGram
    basis = CellBasis(model, vector=True)
    m, d = len(basis.dx), basis.dim
    other = basis.at_points(basis.operators, 0.5 * basis.dx, basis.x.T)   # no node blocks
    second = CellBasis(model, vector=True) if by_blocks else other
    bases = [basis if by_blocks else other, second]
    gram = GradientGram(bases)
    rng = np.random.default_rng(3)
    for _ in range(2):
        coeff = rng.uniform(-1, 1, (2 * m, d * d, d * d))
        ref = sum((b.operators[d + j].T @ sp.diags(b.dx * c[:, i, j])
                   @ b.operators[d + i]).toarray()
                  for b, c in zip(bases, (coeff[:m], coeff[m:]))
                  for i in range(d * d) for j in range(d * d))
        np.testing.assert_allclose(gram.matrix(coeff).toarray(), ref,
                                   atol=1e-12 * abs(ref).max())
    with pytest.raises(FormError, match="expected coefficients of shape"):
        gram.matrix(coeff[:m])
