"""Finite-strain C-NEM (`cnem.Hyperelasticity`): the finite-strain patch test in 2-D on
a holed irregular model and in 3-D on synthetic tetrahedral cells, Newton's quadratic
convergence, the small-strain limit against linear `Elasticity`, the tangent against
finite differences of the internal forces, uniaxial tension to 100 % stretch against
the closed-form plane-strain neo-Hookean answer, non-convergence and bad inputs."""

from __future__ import annotations

from types import SimpleNamespace

import meshio
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import brentq
from test_dimension import _tetrahedral_patch

import cnem
from cnem.assembly import CellBasis
from cnem.elasticity.finite_strain import FiniteStrainOperator
from cnem.material import NeoHookean, SaintVenantKirchhoff
from cnem.solvers.newton import newton

#: The homogeneous deformation of the patch tests: stretch plus shear, det F = 1.25.
F2 = np.array([[1.6, 0.3], [0.1, 0.8]])
F3 = np.array([[1.5, 0.3, 0.1], [0.1, 0.8, 0.2], [-0.1, 0.15, 1.3]])
MATERIALS = [NeoHookean(1.0, 3.0), SaintVenantKirchhoff(2.0, 0.3)]


@pytest.fixture(scope="module")
def holed():
    dom = cnem.geometry.plate_with_hole(1.0, 1.0, 0.2, spacing=0.05)
    return cnem.discretize(cnem.nodes.irregular(dom, 0.06, seed=11))


def _outer(p):
    return (np.abs(p - 0.5) > 0.5 - 1e-9).any(axis=1)


def _homogeneous(F):
    """The displacement ``(F - I) X`` at points ``(p, d)``."""
    return lambda p: p @ (F - np.eye(len(F))).T


def _order(history):
    """Newton's order of convergence from the last three residuals above round-off
    (1e-13 of the first): ``log(r2 / r1) / log(r1 / r0)``."""
    above = [r for r in history if r > 1e-13 * history[0]]
    r0, r1, r2 = above[-3:]
    return np.log(r2 / r1) / np.log(r1 / r0)


# -- the finite-strain patch test --------------------------------------------------------
@pytest.mark.parametrize("mat", MATERIALS, ids=repr)
def test_patch_test_whole_boundary(holed, mat):
    """F on the whole boundary (outer edges and hole): every node takes (F - I) X, every
    cell F~ = F and the law's Cauchy stress; the first Newton correction already lands
    on it (the tangent at a homogeneous state reproduces linear fields)."""
    prob = cnem.Hyperelasticity(holed, mat)
    boundary = np.unique(prob.boundary_edges()[0])
    prob.add_dirichlet(boundary, None, _homogeneous(F2))
    sol = prob.solve()
    np.testing.assert_allclose(sol.u, _homogeneous(F2)(holed.nodes), rtol=0, atol=1e-10)
    np.testing.assert_allclose(sol.deformation_gradient,
                               np.broadcast_to(F2, sol.deformation_gradient.shape), rtol=0, atol=1e-10)
    _, P, _ = mat.evaluate(F2[None])
    cauchy = P[0] @ F2.T / np.linalg.det(F2)
    np.testing.assert_allclose(sol.stress, np.broadcast_to(
        [cauchy[0, 0], cauchy[1, 1], cauchy[0, 1]], sol.stress.shape), rtol=0, atol=1e-9)
    green = 0.5 * (F2.T @ F2 - np.eye(2))
    np.testing.assert_allclose(sol.strain[0], [green[0, 0], green[1, 1], 2 * green[0, 1]],
                               rtol=0, atol=1e-10)
    assert len(sol.residual_history) == 1 and len(sol.residual_history[0]) <= 3


@pytest.mark.parametrize("stabilization", [0.0, 1.0])
@pytest.mark.parametrize("mat", MATERIALS, ids=repr)
def test_patch_test_with_dead_tractions_converges_quadratically(holed, mat, stabilization):
    """F on the outer boundary and its dead traction ``P N`` on the hole: Newton has to
    work (the predictor is the linear answer) and converges quadratically to the
    homogeneous state, reproduced to 1e-10; the sub-cell stabilisation vanishes there."""
    _, P, _ = mat.evaluate(F2[None])
    prob = cnem.Hyperelasticity(holed, mat, stabilization=stabilization)
    prob.add_dirichlet(_outer, None, _homogeneous(F2))
    prob.add_traction(lambda x, n: np.linalg.norm(x - 0.5, axis=1) < 0.3, lambda x, n: n @ P[0].T)
    sol = prob.solve(steps=2, tol=1e-12)
    np.testing.assert_allclose(sol.u, _homogeneous(F2)(holed.nodes), rtol=0, atol=1e-10)
    np.testing.assert_allclose(sol.deformation_gradient,
                               np.broadcast_to(F2, sol.deformation_gradient.shape), rtol=0, atol=1e-10)
    for history in sol.residual_history:
        assert 4 <= len(history) <= 9
        assert _order(history) > 1.7


def _tetrahedral_basis():
    """The synthetic 3-D cells of tests/test_dimension.py (P1 tetrahedra of a jittered
    4^3 lattice, a basis that reproduces linear fields): nodes and vector basis."""
    nodes, value, gradients, volume, centroids = _tetrahedral_patch()
    basis = CellBasis.from_operators(SimpleNamespace(nodes=nodes), value, gradients, volume,
                                     centroids, vector=True)
    return nodes, basis


@pytest.mark.parametrize("mat", MATERIALS, ids=repr)
def test_patch_test_3d_on_synthetic_cells(mat):
    """F on the cube's faces, the interior started off it (a bubble): Newton converges
    quadratically to (F - I) X at every node, F~ = F in every cell."""
    nodes, basis = _tetrahedral_basis()
    op = FiniteStrainOperator(basis, [mat], np.zeros(len(basis.dx), dtype=np.int64))
    boundary = np.flatnonzero(np.any((nodes == 0.0) | (nodes == 1.0), axis=1))
    dofs = basis.get_dofs(boundary)
    exact = _homogeneous(F3)(nodes).reshape(-1)
    bubble = np.prod(np.sin(np.pi * nodes), axis=1)           # zero on the faces, small:
    start = (bubble[:, None] * [0.02, -0.02, 0.01]).reshape(-1)   # the slivers amplify it
    u, history = newton(op.evaluate, np.zeros(basis.N), dofs, exact[dofs], points=nodes,
                        initial=start)
    np.testing.assert_allclose(u, exact, rtol=0, atol=1e-10)
    np.testing.assert_allclose(op.deformation_gradient(u), np.broadcast_to(F3, (len(basis.dx), 3, 3)),
                               rtol=0, atol=1e-10)
    assert len(history) == 1 and 4 <= len(history[0]) <= 8 and _order(history[0]) > 1.7
    W, _, _ = mat.evaluate(F3[None])
    np.testing.assert_allclose(op.energy(u), W[0] * basis.dx.sum(), rtol=1e-12)


# -- consistency -------------------------------------------------------------------------
@pytest.mark.parametrize("stabilization", [0.0, 0.7])
@pytest.mark.parametrize("mat", MATERIALS, ids=repr)
def test_tangent_is_the_derivative_of_the_internal_forces(holed, mat, stabilization):
    op = cnem.Hyperelasticity(holed, mat, stabilization=stabilization).system
    rng = np.random.default_rng(5)
    u = 0.002 * rng.normal(size=holed.nodes.size) + _homogeneous(F2 * 0.3 + 0.7 * np.eye(2))(
        holed.nodes).reshape(-1)
    f, K = op.evaluate(u)
    v = rng.normal(size=holed.nodes.size)
    h = 1e-6
    fd = (op.evaluate(u + h * v, False)[0] - op.evaluate(u - h * v, False)[0]) / (2 * h)
    np.testing.assert_allclose(K @ v, fd, atol=1e-7 * np.abs(K @ v).max())
    energy = (op.energy(u + h * v) - op.energy(u - h * v)) / (2 * h)
    np.testing.assert_allclose(energy, f @ v, rtol=1e-7)
    assert abs(K - K.T).max() <= 1e-12 * abs(K).max()


@pytest.mark.parametrize("stabilization", [0.0, 1.0])
def test_small_strain_limit_is_linear_elasticity(holed, stabilization):
    """A tiny load in one step: the linear `Elasticity` answer (plane strain, the
    linearised moduli, the same stabilisation weight: plain SCNI or the sub-cell term
    of the shear modulus alone) to 1e-6."""
    mat = NeoHookean(1.0, 1.5)
    E, nu = mat.linearized()
    nonlinear = cnem.Hyperelasticity(holed, mat, stabilization=stabilization)
    linear = cnem.Elasticity(holed, (E, nu), plane="strain", stabilization=stabilization,
                             gradients=nonlinear.gradients)
    for prob in (nonlinear, linear):
        prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
        prob.add_traction(lambda x, n: n[:, 0] > 0.5, [0.0, 1e-7])
        prob.add_body_force([2e-7, 0.0])
    # P from F = I + grad u: round-off ~ eps mu in the residual, so a tiny load needs a
    # looser relative tolerance than the default
    u = nonlinear.solve(tol=1e-8).u
    expected = linear.solve(progress=False, method="direct").u
    assert np.abs(expected).max() > 1e-8
    np.testing.assert_allclose(u, expected, atol=1e-6 * np.abs(expected).max())


def test_uniaxial_tension_to_twice_the_length():
    """A strip stretched to lambda = 2 between rollers, lateral edges free: the
    homogeneous plane-strain state, whose lateral stretch b solves P22 = 0,
    ``mu (b - 1/b) + lam ln(lambda b) / b = 0``, and nominal stress
    ``P11 = mu (lambda - 1/lambda) + lam ln(lambda b) / lambda``."""
    mu, lam, stretch, length, height = 1.0, 2.0, 2.0, 2.0, 0.5
    model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(length, height), 0.1,
                                                 seed=2))
    prob = cnem.Hyperelasticity(model, NeoHookean(mu, lam))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, 0)
    prob.add_dirichlet(lambda p: (p[:, 0] < 1e-9) & (p[:, 1] < 1e-9), 1)
    right = lambda p: p[:, 0] > length - 1e-9                      # noqa: E731
    prob.add_dirichlet(right, 0, (stretch - 1.0) * length)
    sol = prob.solve(steps=4)
    b = brentq(lambda b: mu * (b - 1 / b) + lam * np.log(stretch * b) / b, 0.1, 1.0, xtol=1e-15)
    nominal = mu * (stretch - 1 / stretch) + lam * np.log(stretch * b) / stretch
    F = sol.deformation_gradient
    np.testing.assert_allclose(F[:, 0, 0], stretch, rtol=1e-10)
    np.testing.assert_allclose(F[:, 1, 1], b, rtol=1e-9)
    np.testing.assert_allclose(sol.first_piola[:, 0, 0], nominal, rtol=1e-9)
    f_int = prob.operator.evaluate(sol.dofs, False)[0].reshape(-1, 2)
    force = f_int[right(model.nodes), 0].sum()                     # the reaction of the grip
    np.testing.assert_allclose(force, nominal * height, rtol=1e-9)
    np.testing.assert_allclose(sol.stress[:, 0], nominal * stretch / (stretch * b), rtol=1e-9)


def test_progress_bar_counts_the_load_steps(capsys):
    """``progress=True`` shows a tqdm bar on stderr that reaches the number of load steps;
    ``progress=False`` prints nothing."""
    model = cnem.discretize(cnem.nodes.regular(cnem.geometry.rectangle(1.0, 1.0), 0.25))
    prob = cnem.Hyperelasticity(model, NeoHookean(1.0, 2.0))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_dirichlet(lambda p: p[:, 0] > 1.0 - 1e-9, 0, 0.3)
    prob.solve(steps=3, progress=True)
    err = capsys.readouterr().err
    assert "hyperelasticity load steps" in err and "3/3" in err
    prob.solve(steps=3, progress=False)
    assert capsys.readouterr().err == ""


# -- failures and inputs -----------------------------------------------------------------
def test_non_convergence_raises_with_the_history(holed):
    mat = NeoHookean(1.0, 3.0)
    _, P, _ = mat.evaluate(F2[None])
    prob = cnem.Hyperelasticity(holed, mat)
    prob.add_dirichlet(_outer, None, _homogeneous(F2))
    prob.add_traction(lambda x, n: np.linalg.norm(x - 0.5, axis=1) < 0.3, lambda x, n: n @ P[0].T)
    with pytest.raises(cnem.ConvergenceError, match="did not converge in load step 1") as err:
        prob.solve(max_iterations=2)
    assert len(err.value.history) == 1 and len(err.value.history[0]) == 3


def test_inverting_cells_raise_convergence_error(holed):
    """Squeezing the plate to a tenth of its height in one step inverts cells: the
    energy is undefined there and Newton says so by name."""
    prob = cnem.Hyperelasticity(holed, NeoHookean(1.0, 3.0))
    prob.add_dirichlet(_outer, None, _homogeneous(np.diag([1.0, 0.1])))
    prob.add_traction(lambda x, n: np.linalg.norm(x - 0.5, axis=1) < 0.3, lambda x, n: 50.0 * n)
    with pytest.raises(cnem.ConvergenceError) as err:
        prob.solve(max_iterations=5)
    assert err.value.history


def test_bad_inputs_are_named(holed):
    mat = NeoHookean(1.0, 1.0)
    with pytest.raises(cnem.MaterialError, match="expected hyperelastic laws"):
        cnem.Hyperelasticity(holed, (1.0, 0.3))
    with pytest.raises(cnem.MaterialError, match="one material per region"):
        cnem.Hyperelasticity(holed, [mat, mat])
    with pytest.raises(cnem.OptionError, match="plane strain"):
        cnem.Hyperelasticity(holed, mat, plane="stress")
    with pytest.raises(cnem.InputError, match="stabilization"):
        cnem.Hyperelasticity(holed, mat, stabilization=-1.0)
    with pytest.raises(cnem.InputError, match="expects a Model"):
        cnem.Hyperelasticity(cnem.nodes.regular(cnem.geometry.rectangle(), 0.5), mat)
    prob = cnem.Hyperelasticity(holed, mat)
    with pytest.raises(cnem.ConditionError, match="finite"):
        prob.add_dirichlet(_outer, 0, np.nan)
    prob.add_dirichlet(_outer, None)
    with pytest.raises(cnem.InputError, match="steps"):
        prob.solve(steps=0)
    with pytest.raises(cnem.InputError, match="tol"):
        prob.solve(tol=np.nan)
    with pytest.raises(cnem.InputError, match="vector basis"):
        FiniteStrainOperator(CellBasis(holed), [mat], np.zeros(len(holed.cells.area), int))
    basis = prob.basis
    with pytest.raises(cnem.InputError, match="one material index per cell"):
        FiniteStrainOperator(basis, [mat], np.ones(len(basis.dx), dtype=np.int64))


def test_solution_writes_and_repr(holed, tmp_path):
    prob = cnem.Hyperelasticity(holed, NeoHookean(1.0, 1.0))
    prob.add_dirichlet(np.unique(prob.boundary_edges()[0]), None, _homogeneous(F2))
    sol = prob.solve()
    assert "Hyperelasticity plane strain" in repr(prob)
    assert "HyperelasticSolution" in repr(sol)
    path = sol.write(tmp_path / "finite.vtu")
    mesh = meshio.read(path)
    J = np.concatenate([block for block in mesh.cell_data["J"]])
    np.testing.assert_allclose(J[np.isfinite(J)], np.linalg.det(F2), rtol=1e-10)
    np.testing.assert_allclose(sol.displacement(np.array([[0.1, 0.1]])),
                               _homogeneous(F2)(np.array([[0.1, 0.1]])), rtol=0, atol=1e-10)


@pytest.mark.parametrize("stabilization", [0.0, 0.6])
def test_tangent_at_the_reference_state_is_the_linear_stiffness(holed, stabilization):
    """At u = 0 the tangent is `Elasticity`'s stiffness (plane strain, the linearised
    moduli, the same stabilisation weight), entry by entry."""
    mat = SaintVenantKirchhoff(3.0, 0.35)
    prob = cnem.Hyperelasticity(holed, mat, stabilization=stabilization)
    f, K = prob.system.evaluate(np.zeros(holed.nodes.size))
    linear = cnem.Elasticity(holed, mat.linearized(), plane="strain",
                             stabilization=stabilization).stiffness()
    assert np.abs(f).max() == 0.0
    assert abs(K - linear).max() <= 1e-12 * abs(linear).max()


# -- one-pass tangent and Newton's preconditioner ----------------------------------------
def _term_by_term(system, u):
    """The stabilised tangent the slow way: every term's ``sum_k V_k G_k^T A_k G_k`` by
    scipy products of the descriptor operators, weighted and added (a dense array)."""
    total = 0.0
    for w, op in system.terms:
        _, coeff, extra = op.local_evaluate(u)
        ops, d = op.basis.operators, op.dim
        K = sum(ops[d + b].T @ sp.diags(op.basis.dx * coeff[:, a, b]) @ ops[d + a]
                for a in range(d * d) for b in range(d * d))
        total = total + w * (K if extra is None else K + extra).toarray()
    return total


@pytest.mark.parametrize("volumetric", [None, "fbar"])
def test_summed_tangent_in_one_pass_equals_the_terms_added(holed, volumetric):
    """The stabilised tangent, assembled in one pass over cells and sub-cells on a kept
    pattern, equals its three terms assembled apart and added (values to 1e-12 of the
    largest, the pattern their union), at two states on the same pattern."""
    prob = cnem.Hyperelasticity(holed, NeoHookean(1.0, 30.0), volumetric=volumetric)
    system = prob.system
    rng = np.random.default_rng(2)
    patterns = []
    for scale in (0.3, 0.6):
        u = 0.001 * rng.normal(size=holed.nodes.size) + _homogeneous(
            scale * F2 + (1 - scale) * np.eye(2))(holed.nodes).reshape(-1)
        K = system.evaluate(u)[1]
        want = _term_by_term(system, u)
        assert np.abs(K.toarray() - want).max() <= 1e-12 * np.abs(want).max()
        assert np.all(K.toarray()[np.abs(want) > 1e-14 * np.abs(want).max()] != 0.0)
        patterns.append((K.indptr, K.indices))
    np.testing.assert_array_equal(patterns[0][0], patterns[1][0])
    np.testing.assert_array_equal(patterns[0][1], patterns[1][1])
    assert system.gram is system.gram                        # its pattern kept


def test_newton_corrections_share_one_p1_hierarchy(holed, monkeypatch):
    """With the iterative path forced, every correction is preconditioned by one
    smoothed-aggregation hierarchy on the P1 stiffness (built once per solve), and
    Newton reaches the direct path's answer in as many iterations."""
    import cnem.elasticity.hyperelasticity as module
    from cnem import config

    def solve(**kwargs):
        prob = cnem.Hyperelasticity(holed, NeoHookean(1.0, 1.5), **kwargs)
        prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None, 0.0)
        prob.add_traction(lambda x, n: x[:, 0] > 1 - 1e-9, [0.0, -0.05])
        return prob.solve(steps=2, tol=1e-10)

    direct = solve()
    built = []
    original = module.hierarchy
    monkeypatch.setattr(module, "hierarchy", lambda *a, **k: built.append(1) or original(*a, **k))
    monkeypatch.setattr(config, "DIRECT_NNZ", 0)
    iterative = solve()
    assert len(built) == 1
    assert [len(h) for h in iterative.residual_history] == \
        [len(h) for h in direct.residual_history]
    np.testing.assert_allclose(iterative.u, direct.u, rtol=0, atol=1e-8 * np.abs(direct.u).max())
