"""Linear elasticity by C-NEM + SCNI (`cnem.Elasticity`), and the scikit-fem style forms.

Physics checks only: the SCNI linear patch test to round-off on every catalogue
case, symmetric positive semi-definite stiffness with exactly the rigid
motions as null space, exact uniform states from tractions and body forces,
singular systems named, Poisson through the same forms.
"""

from __future__ import annotations

import gc
import weakref

import numpy as np
import pytest
from skfem.helpers import dot, grad

import cases
import cnem
from cnem.assembly import BilinearForm, CellBasis, LinearForm, condense, solve

NAMES = cases.NAMES
E, NU = 1000.0, 0.3


def _boundary_nodes(model):
    """Nodes on the outer boundary, holes and crack faces."""
    seg = model.segments[np.isin(model.segment_kind, (0, 2))]
    return np.unique(seg)


def _linear_field(x):
    return np.column_stack([1e-3 * (1.0 + 2.0 * x[:, 0] - 3.0 * x[:, 1]),
                            1e-3 * (-0.5 + 1.5 * x[:, 0] + 0.7 * x[:, 1])])


@pytest.mark.parametrize("plane", ["stress", "strain"])
@pytest.mark.parametrize("name", NAMES)
def test_patch_test(name, plane):
    """A linear field imposed on every boundary node (crack faces included) is
    reproduced at every node, and every cell has its exact strain."""
    _, _, model = cases.model(name)
    prob = cnem.Elasticity(model, (E, NU), plane=plane)
    prob.add_dirichlet(_boundary_nodes(model), None, _linear_field)
    sol = prob.solve(progress=False)
    exact = _linear_field(model.nodes)
    np.testing.assert_allclose(sol.u, exact, atol=1e-10 * np.abs(exact).max())
    strain = 1e-3 * np.array([2.0, 0.7, -3.0 + 1.5])
    np.testing.assert_allclose(sol.strain, np.broadcast_to(strain, sol.strain.shape), atol=1e-10 * 3e-3)
    C = cnem.elasticity.stiffness_matrix(E, NU, plane)
    np.testing.assert_allclose(sol.stress, np.broadcast_to(C @ strain, sol.stress.shape),
                               atol=1e-10 * np.abs(C @ strain).max())


@pytest.mark.parametrize("name", ["lshape_irregular", "annulus_sector_regular",
                                  "kinked_crack_irregular", "three_rectangles_irregular"])
def test_stiffness_is_spd_up_to_rigid_motions(name):
    _, _, model = cases.model(name)
    nreg = len(model.domain.regions)
    mats = [(E * (1 + r), NU - 0.1 * r) for r in range(nreg)]
    K = cnem.Elasticity(model, mats).stiffness().toarray()
    np.testing.assert_allclose(K, K.T, atol=1e-12 * np.abs(K).max())
    eig = np.linalg.eigvalsh(K)
    tol = 1e-10 * eig[-1]
    assert (eig > -tol).all(), eig[:4]
    assert (np.abs(eig) <= tol).sum() == 3, eig[:5]
    modes = cnem.solvers.linsolve.rigid_modes(model.nodes)
    np.testing.assert_allclose(K @ modes, 0.0, atol=1e-10 * eig[-1])


@pytest.mark.parametrize("weight", [0.0, 0.4, 1.0, 2.5])
@pytest.mark.parametrize("name", ["lshape_irregular", "kinked_crack_irregular",
                                  "three_rectangles_irregular"])
def test_stabilised_stiffness_is_the_difference_form(name, weight):
    """K = sum_k A_k B~_k^T C B~_k + a sum_s A_s (B~_s - B~_k)^T C_dev (B~_s - B~_k),
    built here term by term from the fan sub-cells (slow reference); the sub-cells'
    spokes integrated whole or cut, their integrals cancel between neighbours. The
    stabilisation's C_dev is the law of the shear modulus alone (`stabilization_lame`:
    in plane stress, these models', ``lam_s = 0``)."""
    import scipy.sparse as sp
    from cnem.assembly.subdivision import subdivide, tip_cells
    from cnem.elasticity.linear import elasticity_form, lame
    from cnem.elasticity.stabilization import stabilization_lame
    _, _, model = cases.model(name)
    nreg = len(model.domain.regions)
    mats = [(E * (1 + r), NU - 0.1 * r) for r in range(nreg)]
    prob = cnem.Elasticity(model, mats, stabilization=weight)
    K = prob.stiffness().toarray()
    coarse = prob.basis
    lam, mu = lame(*prob.cell_materials().T, "stress")
    reference = elasticity_form.assemble(coarse, lam=lam, mu=mu).toarray()
    sub, parent = subdivide(prob.cells, model.nodes, node_apex=tip_cells(model),
                            mark_spokes=True)
    fine = CellBasis(model, vector=True, cells=sub)
    to_sub = sp.csr_matrix((np.ones(len(parent)), (np.arange(len(parent)), parent)),
                           shape=(len(parent), len(prob.cells.area)))
    fine.operators = [f - to_sub @ c for f, c in zip(fine.operators, coarse.operators)]
    _, mu = lame(*prob.materials[sub.region].T, "stress")
    lam_s = stabilization_lame(mu, prob.materials[sub.region, 1], "stress")
    reference += weight * elasticity_form.assemble(fine, lam=lam_s, mu=mu).toarray()
    np.testing.assert_allclose(K, reference, atol=1e-11 * np.abs(reference).max())


def test_uniform_tension_by_traction():
    dom = cnem.geometry.rectangle(2.0, 1.0)
    model = cnem.discretize(cnem.nodes.irregular(dom, 0.1, seed=4))
    prob = cnem.Elasticity(model, (E, NU))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-12, 0)
    prob.add_dirichlet(lambda p: (p[:, 0] < 1e-12) & (p[:, 1] < 1e-12), 1)
    prob.add_traction(lambda x, n: n[:, 0] > 0.5, [5.0, 0.0])
    sol = prob.solve(progress=False)
    np.testing.assert_allclose(sol.stress, np.broadcast_to([5.0, 0.0, 0.0], sol.stress.shape), atol=1e-9)
    np.testing.assert_allclose(sol.u[:, 0], 5.0 / E * model.nodes[:, 0], atol=1e-12)
    np.testing.assert_allclose(sol.u[:, 1], -NU * 5.0 / E * model.nodes[:, 1], atol=1e-12)
    # displacement inside through the shape functions is the same linear field
    pts = np.array([[0.33, 0.41], [1.7, 0.95]])
    np.testing.assert_allclose(sol.displacement(pts)[:, 0], 5.0 / E * pts[:, 0], atol=1e-12)
    assert sol.energy_error(lambda x: np.tile([5.0, 0.0, 0.0], (len(x), 1))) < 1e-10


def test_linear_traction_and_body_force_totals():
    """Loads integrate exactly: total force of a linear traction and of a body force."""
    dom = cnem.geometry.l_shape(1.0, 0.5)
    model = cnem.discretize(cnem.nodes.irregular(dom, 0.08, seed=2))
    prob = cnem.Elasticity(model, (E, NU))
    prob.add_traction(lambda x, n: n[:, 1] > 0.5, lambda x, n: np.column_stack([x[:, 0], 0 * x[:, 0]]))
    prob.add_body_force([0.0, -2.0])
    f = prob.load().reshape(-1, 2)
    top = 0.5 ** 2 / 2 + (1.0 ** 2 - 0.5 ** 2) / 2       # ∫ x over the edges facing +y (y = 1 and y = 0.5)
    np.testing.assert_allclose(f.sum(axis=0), [top, -2.0 * dom.area], rtol=1e-12)


def test_crack_face_traction_is_on_both_faces():
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[cases.EDGE_CRACK])
    model = cnem.discretize(cnem.nodes.regular(dom, 0.1))
    prob = cnem.Elasticity(model, (E, NU))
    on_crack = lambda x, n: (np.abs(x[:, 1] - 0.5) < 1e-12) & (x[:, 0] < 0.5)
    prob.add_traction(on_crack, lambda x, n: -1.0 * n)        # pressure in the crack
    f = prob.load().reshape(-1, 2)
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-14)
    # each face carries the pressure times its length (0.5); at the tip the pushes
    # of the two faces' last edges (half their length each) cancel
    tip = np.flatnonzero(np.hypot(*(model.nodes - [0.5, 0.5]).T) < 1e-12)
    last = np.sort(np.hypot(*(model.nodes[np.abs(model.nodes[:, 1] - 0.5) < 1e-12] - [0.5, 0.5]).T))
    last = last[last > 1e-12][0]
    assert f[tip, 1] == pytest.approx(0.0, abs=1e-15)
    assert np.abs(f[:, 1]).sum() == pytest.approx(2 * (0.5 - last / 2), rel=1e-12)


def test_singular_systems_name_the_free_motion():
    _, _, model = cases.model("square_regular")
    prob = cnem.Elasticity(model, (E, NU))
    with pytest.raises(cnem.SolveError, match="translation in x.*translation in y.*rotation"):
        prob.solve(progress=False)
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-12, 0)
    with pytest.raises(cnem.SolveError, match="translation in y") as err:
        prob.solve(progress=False)
    assert "rotation" not in str(err.value)
    centre = np.argmin(np.hypot(*(model.nodes - 0.5).T))      # one node fixed: it can spin
    prob = cnem.Elasticity(model, (E, NU))
    prob.add_dirichlet([centre], None)
    x, y = model.nodes[centre]
    with pytest.raises(cnem.SolveError, match=rf"rotation about \({x:.6g}, {y:.6g}\)"):
        prob.solve(progress=False)


def test_body_cut_in_two_by_a_crack_is_reported():
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [1.0, 0.5]]])
    model = cnem.discretize(cnem.nodes.regular(dom, 0.125))
    prob = cnem.Elasticity(model, (E, NU))
    prob.add_dirichlet(lambda p: p[:, 1] < 1e-12, None)
    with pytest.raises(cnem.SolveError, match="part holding node"):
        prob.solve(progress=False)


@pytest.mark.parametrize("bad, match", [
    ((E,), "pair"), ([(E, NU)] * 3, "one pair per region"), ((-1.0, 0.3), "positive"),
    ((E, 0.5), r"\(-1, 0.5\)"),
])
def test_bad_materials(bad, match):
    _, _, model = cases.model("square_regular")
    with pytest.raises(ValueError, match=match):
        cnem.Elasticity(model, bad)


def test_bad_conditions():
    _, _, model = cases.model("square_regular")
    prob = cnem.Elasticity(model, (E, NU))
    with pytest.raises(ValueError, match="plane"):
        cnem.Elasticity(model, (E, NU), plane="axisymmetric")
    with pytest.raises(ValueError, match="component"):
        prob.add_dirichlet(lambda p: p[:, 0] < 1e-12, 2)
    with pytest.raises(ValueError, match="selects no node"):
        prob.add_dirichlet(lambda p: p[:, 0] < -1, 0)
    with pytest.raises(ValueError, match="bool"):
        prob.add_dirichlet(lambda p: p[:, 0], 0)
    with pytest.raises(ValueError, match="selects no boundary edge"):
        prob.add_traction(lambda x, n: n[:, 0] > 2, [1.0, 0.0])
    with pytest.raises(ValueError, match="shape"):
        prob.add_dirichlet(lambda p: p[:, 0] < 1e-12, None, lambda p: p[:, 0])


def test_poisson_through_the_forms():
    """-Δu = 0 with linear boundary data: reproduced exactly (scalar basis, forms)."""
    _, _, model = cases.model("plate_hole_irregular")
    basis = CellBasis(model)
    A = BilinearForm(lambda u, v, w: dot(grad(u), grad(v))).assemble(basis)
    b = LinearForm(lambda v, w: 0.0 * v).assemble(basis)
    exact = 2.0 - model.nodes[:, 0] + 3.0 * model.nodes[:, 1]
    D = basis.get_dofs(_boundary_nodes(model))
    u = solve(*condense(A, b, x=exact, D=D))
    np.testing.assert_allclose(u, exact, atol=1e-10)
    with pytest.raises(ValueError, match="not bilinear"):
        BilinearForm(lambda u, v, w: 1.0 + dot(grad(u), grad(v))).assemble(basis)


def test_poisson_converges():
    """-Δu = f on the unit square with u = sin(pi x) sin(pi y): nodal error falls at
    least linearly (log-log slope over three clouds)."""
    errors, hs = [], []
    for h in (0.1, 0.05, 0.025):
        model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(), h, seed=1))
        basis = CellBasis(model)
        A = BilinearForm(lambda u, v, w: dot(grad(u), grad(v))).assemble(basis)
        f = lambda x: 2 * np.pi ** 2 * np.sin(np.pi * x[0]) * np.sin(np.pi * x[1])
        b = LinearForm(lambda v, w: f(w.nodes) * v).assemble(basis, nodes=basis.nodes)
        exact = np.sin(np.pi * model.nodes[:, 0]) * np.sin(np.pi * model.nodes[:, 1])
        D = basis.get_dofs(lambda p: (np.abs(p - 0.5) > 0.5 - 1e-12).any(axis=1))
        u = solve(*condense(A, b, x=np.zeros(basis.N), D=D))
        errors.append(np.abs(u - exact).max())
        hs.append(h)
    slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert slope > 1.0, (errors, slope)


@pytest.mark.parametrize("name", ["three_rectangles_irregular", "kinked_crack_irregular"])
def test_block_assembly_equals_the_general_one(name, monkeypatch):
    """Forms that see only gradients of a vector field are assembled by 2 x 2 node
    blocks; the result is the general descriptor-by-descriptor assembly's."""
    from cnem.elasticity.linear import elasticity_form, lame
    from cnem.elasticity.stabilization import stabilization_lame
    _, _, model = cases.model(name)
    nreg = len(model.domain.regions)
    prob = cnem.Elasticity(model, [(E * (1 + r), NU - 0.1 * r) for r in range(nreg)])
    lam, mu = lame(*prob.cell_materials().T, "stress")
    assert prob.basis.component_gradients() is not None
    blocks = elasticity_form.assemble(prob.basis, lam=lam, mu=mu)
    monkeypatch.setattr(CellBasis, "component_gradients", lambda self: None)
    general = elasticity_form.assemble(prob.basis, lam=lam, mu=mu)
    np.testing.assert_allclose(blocks.toarray(), general.toarray(),
                               atol=1e-13 * abs(general).max())


def test_stabilised_solve_keeps_no_sub_cell_gradients(monkeypatch):
    """The fan sub-cells' gradients serve K alone: neither assembling K nor solving
    afterwards (which needs the cells' B~, computed with them and kept) keeps them
    alive, and no gradient is computed twice."""
    from cnem.assembly import gradients as owner
    fans, alone = [], []
    fan_gradients, smoothed_gradient = owner._fan_gradients, owner.smoothed_gradient

    def watched_fan(*args, **kwargs):
        out = fan_gradients(*args, **kwargs)
        fans.append(weakref.ref(out[2]))
        return out

    monkeypatch.setattr(owner, "_fan_gradients", watched_fan)
    monkeypatch.setattr(owner, "smoothed_gradient",
                        lambda *a, **k: alone.append(1) or smoothed_gradient(*a, **k))
    dom = cnem.geometry.rectangle(1.0, 1.0)
    model = cnem.discretize(cnem.nodes.irregular(dom, 0.1, seed=7))
    prob = cnem.Elasticity(model, (E, NU))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-12, None)
    prob.add_traction(lambda x, n: n[:, 0] > 0.5, [1.0, 0.0])
    prob.stiffness()
    gc.collect()
    assert len(fans) == 1 and fans[0]() is None and alone == []
    prob.solve(progress=False)
    gc.collect()
    assert len(fans) == 1 and fans[0]() is None and alone == []


def _lame_errors(h, nu, stabilization=1.0):
    """Thick cylinder (radii 1 and 2, internal pressure, plane strain) on an irregular
    cloud of a quarter: relative error of u_r on the inner radius, L2 stress error."""
    from cnem.assembly.quadrature import cell_quadrature
    from cnem.exact import LayeredCylinder
    exact = LayeredCylinder([1.0, 2.0], [(1.0, nu)], plane="strain")
    dom = cnem.geometry.annulus([1.0, 2.0], angles=(0.0, np.pi / 2), spacing=h)
    model = cnem.discretize(cnem.nodes.irregular(dom, h, seed=0))
    prob = cnem.Elasticity(model, (1.0, nu), plane="strain", stabilization=stabilization)
    prob.add_dirichlet(lambda x: np.abs(x[:, 0]) < 1e-9, 0)
    prob.add_dirichlet(lambda x: np.abs(x[:, 1]) < 1e-9, 1)
    prob.add_traction(lambda x, n: np.hypot(*x.T) < 1.0 + 1e-6, lambda x, n: -n)
    sol = prob.solve(progress=False)
    r = np.hypot(*model.nodes.T)
    inner = np.abs(r - 1.0) < 1e-9
    ur = np.einsum("ij,ij->i", sol.u[inner], model.nodes[inner])      # r = 1 there
    u_error = abs(ur.mean() / exact.radial_displacement(1.0) - 1.0)
    owner, points, weights = cell_quadrature(model.cells, model.nodes, 4)
    sigma = exact.stress(points)
    stress_error = np.sqrt(weights @ ((sol.stress[owner] - sigma) ** 2).sum(axis=1)
                           / (weights @ (sigma ** 2).sum(axis=1)))
    return u_error, stress_error


@pytest.mark.slow
def test_default_stabilisation_does_not_lock():
    """Lamé's cylinder up to nu = 0.4999 with the default stabilisation: the inner
    displacement within 0.1 % and the L2 stress error bounded as nu -> 1/2 (both
    locked with a stabilisation carrying lam: -36.7 % and 1369 % at h = 0.1), and the
    stress error falling with h at every nu."""
    for nu in (0.3, 0.49, 0.4999):
        coarse = _lame_errors(0.1, nu)
        fine = _lame_errors(0.05, nu)
        assert coarse[0] < 1e-3 and fine[0] < 1e-3, (nu, coarse, fine)
        assert coarse[1] < 0.3 and fine[1] < 0.1, (nu, coarse, fine)
        assert fine[1] < 0.55 * coarse[1], (nu, coarse, fine)


def test_reaction_balances_the_loads_and_takes_any_where():
    """``sol.reaction(where)``: the clamp's force balances the body's weight and an end
    traction exactly (equilibrium of K u = f, to the solver's tolerance), the same by name,
    predicate, mask and indices; a boundary with no support carries none; an empty
    selection is refused."""
    dom = cnem.geometry.rectangle(3.0, 1.0, origin=(10.0, -5.0))
    prob = cnem.Elasticity(cnem.discretize(cnem.nodes.irregular(dom, 0.2, seed=1)), (100.0, 0.25))
    prob.add_dirichlet("left", None)
    prob.add_body_force([0.5, -2.0])                       # (1.5, -6) over the area 3
    prob.add_traction("right", [1.0, 3.0])                  # (1, 3) over the edge of length 1
    sol = prob.solve()
    expected = -np.array([1.5 + 1.0, -6.0 + 3.0])
    np.testing.assert_allclose(sol.reaction("left"), expected, atol=1e-8)
    left = np.abs(prob.model.nodes[:, 0] - 10.0) < 1e-9
    for where in (lambda x: np.abs(x[:, 0] - 10.0) < 1e-9, left, np.flatnonzero(left)):
        np.testing.assert_allclose(sol.reaction(where), expected, atol=1e-8)
    np.testing.assert_allclose(sol.reaction("right"), 0.0, atol=1e-8)
    with pytest.raises(cnem.errors.ConditionError, match="selects no node"):
        sol.reaction(lambda x: x[:, 0] > 100.0)
