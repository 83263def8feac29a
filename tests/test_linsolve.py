"""Linear solves: the P1 basis on a model's triangles (`cnem.assembly.triangles`), CG
preconditioned by smoothed aggregation built on its stiffness, and the rigid motions
a stiffness leaves free part by part.

Checked against scikit-fem's own P1 assembly on the same triangles, the iterative
solutions against the direct ones on the same systems, and the free motions of
bodies whose parts are known by construction.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
import scipy.sparse as sp
from skfem import Basis, ElementTriP1, ElementVector, MeshTri, asm
from skfem.helpers import dot, grad
from skfem.models.elasticity import linear_elasticity
from skfem.models.poisson import laplace

import cases
import cnem
from cnem.assembly import BilinearForm
from cnem.solvers import linsolve
from cnem.assembly.triangles import triangle_basis
from cnem.elasticity.linear import elasticity_form
from cnem.material import lame

E, NU = 1000.0, 0.3


@pytest.mark.parametrize("name", ["plate_hole_irregular", "kinked_crack_irregular",
                                  "three_rectangles_irregular"])
def test_triangle_basis_gives_the_p1_stiffness(name):
    """Elasticity (per-triangle materials) and Laplace forms on the triangle basis are
    scikit-fem's P1 matrices on the same triangles; the crack faces stay apart."""
    _, _, model = cases.model(name)
    mesh = MeshTri(model.nodes.T.copy(), model.triangles.T.copy())
    lam, mu = lame(E * (1.0 + model.triangle_region), NU, "strain")
    ours = elasticity_form.assemble(triangle_basis(model, vector=True), lam=lam, mu=mu)
    ref = asm(linear_elasticity(lam[:, None], mu[:, None]), Basis(mesh, ElementVector(ElementTriP1())))
    assert abs(ours - ref).max() <= 1e-12 * abs(ref).max()
    scalar = BilinearForm(lambda u, v, w: dot(grad(u), grad(v))).assemble(triangle_basis(model))
    ref = asm(laplace, Basis(mesh, ElementTriP1()))
    assert abs(scalar - ref).max() <= 1e-12 * abs(ref).max()


@pytest.mark.slow
@pytest.mark.parametrize("name, enrich, weight", [("three_rectangles_irregular", None, 1.0),
                                                  ("kinked_crack_irregular", None, 0.3),
                                                  ("kinked_crack_irregular", None, 0.0),
                                                  ("edge_crack_regular", dict(radius=0.2), 1.0)])
def test_amg_solution_is_the_direct_one(name, enrich, weight, caplog):
    """pyamg + CG (hierarchy on the P1 stiffness, finest level smoothed with K for plain
    SCNI; with enrichment, whose extra dofs P1 does not have, on K's nodal block plus an
    LU of the enriched block) gives the direct solution."""
    _, _, model = cases.model(name)
    nreg = len(model.domain.regions)
    mats = [(E * (1 + r), NU - 0.1 * r) for r in range(nreg)]
    lo = model.nodes.min(axis=0)

    def solve(method):
        prob = cnem.Elasticity(model, mats, enrich=enrich, stabilization=weight)
        prob.add_dirichlet(lambda p: p[:, 0] < lo[0] + 1e-9, None)
        prob.add_traction(lambda x, nrm: nrm[:, 0] > 0.5, [3.0, 1.0])
        prob.add_body_force([0.5, -2.0])
        return prob.solve(method=method, tol=1e-12, progress=False)

    direct = solve("direct")
    with caplog.at_level("INFO", logger="cnem.solvers.linsolve"):
        amg = solve("amg")
    where = "the preconditioner matrix" + (", smoothing with the matrix" if weight == 0 else "")
    assert (re.search(r"pyamg \(nodal block, \d+ enriched dofs by LU\) \+ CG", caplog.text)
            if enrich else f"pyamg (hierarchy on {where}) + CG" in caplog.text)
    assert "building the hierarchy on the matrix itself" not in caplog.text
    scale = np.abs(direct.u).max()
    np.testing.assert_allclose(amg.u, direct.u, atol=1e-9 * scale)


def test_amg_solution_is_the_direct_one_in_3d(caplog):
    """In 3-D the stabilised K is smoothed with itself on the finest level of the P1
    hierarchy (the P1 hierarchy alone needs five times the CG iterations), and pyamg + CG
    gives the direct solution."""
    box = cnem.geometry.box((0.0, 0.0, 0.0), (2.0, 1.0, 1.0))
    model = cnem.discretize(cnem.nodes.irregular(box, 0.25, seed=2))

    def solve(method):
        prob = cnem.Elasticity(model, (E, NU))
        prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
        prob.add_traction(lambda x, nrm: nrm[:, 0] > 0.5, [1.0, -2.0, 3.0])
        return prob.solve(method=method, tol=1e-12, progress=False)

    direct = solve("direct")
    with caplog.at_level("INFO", logger="cnem.solvers.linsolve"):
        amg = solve("amg")
    assert "pyamg (hierarchy on the preconditioner matrix, smoothing with the matrix) + CG" \
        in caplog.text
    np.testing.assert_allclose(amg.u, direct.u, atol=1e-9 * np.abs(direct.u).max())


def _laplacian(n):
    """A 1-D Dirichlet Laplacian ``(n, n)`` (SPD)."""
    return sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1], format="csr")


def test_falls_back_to_the_matrix_when_the_preconditioner_fails(monkeypatch, caplog):
    A, b = _laplacian(300), np.linspace(1.0, 2.0, 300)
    built_on = []
    real = linsolve._amg_cg

    def failing_first(A_, b_, P, modes, tol, smooth_with_A=False):
        built_on.append(P)
        x, rel, its = real(A_, b_, P, modes, tol, smooth_with_A)
        return (x, 1.0, its) if len(built_on) == 1 else (x, rel, its)

    monkeypatch.setattr(linsolve, "_amg_cg", failing_first)
    P = 2.0 * sp.identity(300, format="csr")
    x = linsolve.solve_spd(A, b, method="amg", preconditioner=lambda: P)
    assert built_on[0] is P and built_on[1].matrix() is A         # A itself, not a copy
    assert "building the hierarchy on the matrix itself" in caplog.text
    np.testing.assert_allclose(A @ x, b, atol=1e-8 * np.abs(b).max())


def test_preconditioner_is_built_only_for_the_iterative_path():
    A, b = _laplacian(50), np.ones(50)
    called = []
    x = linsolve.solve_spd(A, b, method="direct", preconditioner=lambda: called.append(1))
    assert not called
    np.testing.assert_allclose(A @ x, b, atol=1e-12)
    with pytest.raises(ValueError, match=r"preconditioner: expected shape \(50, 50\)"):
        linsolve.solve_spd(A, b, method="amg", preconditioner=sp.identity(49))


def test_parts_whose_dofs_do_not_couple_across_components():
    """Two chains of springs acting on each component apart (the x and y dofs of a
    node never couple): the dof graph has four parts, the body two; fixing the first
    chain leaves the second one's three rigid motions, named for its part."""
    chain = sp.diags([-np.ones(4), np.r_[1, 2 * np.ones(3), 1], -np.ones(4)], [-1, 0, 1])
    K = sp.kron(sp.block_diag([chain, chain]), sp.identity(2), format="csr")
    points = np.column_stack([np.tile(np.arange(5.0), 2), np.repeat([0.0, 1.0], 5)])
    free = linsolve.free_rigid_motions(K, points, np.arange(10))
    assert free == [f"{m} of the part holding node 5 (5 nodes)" for m in
                    ("translation in x", "translation in y", "rotation about (2, 1)")]
    assert linsolve.free_rigid_motions(K, points, np.arange(20)) == []


def test_degenerate_triangles_leave_the_hierarchy_on_k(monkeypatch, caplog):
    """A triangulation P1 cannot use (degenerate triangles) costs the cheaper
    preconditioner, not the solve."""
    from cnem.elasticity import linear as elasticity
    _, _, model = cases.model("plate_hole_irregular")

    def degenerate(model, *, vector=False):
        raise ValueError("triangle_basis: 1 of 10 triangles are degenerate or clockwise")

    monkeypatch.setattr(elasticity, "simplex_basis", degenerate)
    prob = cnem.Elasticity(model, (E, NU))
    prob.add_dirichlet(lambda p: p[:, 0] < model.nodes[:, 0].min() + 1e-9, None)
    prob.add_traction(lambda x, nrm: nrm[:, 0] > 0.5, [3.0, 1.0])
    with caplog.at_level("INFO", logger="cnem"):
        amg = prob.solve(method="amg", tol=1e-12, progress=False)
    assert "no P1 preconditioner matrix" in caplog.text
    assert "pyamg (hierarchy on the matrix) + CG" in caplog.text
    direct = prob.solve(method="direct", progress=False)
    np.testing.assert_allclose(amg.u, direct.u, atol=1e-9 * np.abs(direct.u).max())


def test_triangle_basis_rejects_degenerate_triangles():
    from types import SimpleNamespace
    flat = SimpleNamespace(nodes=np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0]]),
                           triangles=np.array([[0, 1, 3], [0, 1, 2]]))
    with pytest.raises(ValueError, match="1 of 2 triangles are degenerate or clockwise"):
        triangle_basis(flat)


def test_a_built_hierarchy_is_used_as_the_preconditioner():
    """`solve_spd` with a `VCycle` (a hierarchy kept by the caller) solves like with the
    matrix it was built on, and does not call it as a matrix factory."""
    import scipy.sparse.linalg as spla
    from test_multigrid import p1_elasticity
    from cnem.solvers.multigrid import hierarchy
    A, b, modes = p1_elasticity(30)
    P = (A + sp.diags(0.1 * A.diagonal())).tocsr()
    exact = spla.spsolve(A.tocsc(), b)
    for smooth in (False, True):
        x = linsolve.solve_spd(A, b, modes=modes, tol=1e-10, method="amg",
                               preconditioner=hierarchy(P, modes), smooth_with_matrix=smooth)
        np.testing.assert_allclose(x, exact, rtol=0, atol=1e-8 * np.abs(exact).max())
