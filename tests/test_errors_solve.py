"""Solves that do not give up: branch-enriched systems converge with
the nodal-block AMG + enriched-block LU preconditioner, a stalled CG falls back to the
direct solve when its factor fits in memory and otherwise says what to change."""

from __future__ import annotations

import logging

import numpy as np
import pytest
import scipy.sparse.linalg as spla

import cases
import cnem
from cnem import config
from cnem.solvers import linsolve


@pytest.fixture(scope="module")
def small():
    return cases.enriched_centre_crack_system(0.02)          # 2.6k nodes, 6.3k unknowns, 1.3k of them enriched


def _relative_residual(A, x, b):
    return np.linalg.norm(A @ x - b) / np.linalg.norm(b)


def test_enriched_system_converges_with_the_block_preconditioner(small, caplog):
    # a hierarchy built on the whole matrix stalls here (2000 iterations, residual 2.8e-9)
    A, b, nodal, modes = small
    assert 0 < (~nodal).sum() < len(nodal)
    with caplog.at_level(logging.INFO, logger="cnem.solvers.linsolve"):
        x = linsolve.solve_spd(A, b, modes=modes, method="amg", nodal=nodal, tol=1e-10)
    assert _relative_residual(A, x, b) <= 1e-9
    its = [int(r.getMessage().split(": ")[1].split()[0]) for r in caplog.records
           if "enriched dofs by LU" in r.getMessage()]
    assert its and its[0] < 200
    assert not any("solving directly" in r.getMessage() for r in caplog.records)
    direct = spla.spsolve(A.tocsc(), b)
    error = x - direct                       # in the energy norm (the enriched dofs are
    assert error @ (A @ error) <= 1e-10 * (direct @ (A @ direct))      # ill-conditioned)


def test_a_stalled_solve_falls_back_to_direct_when_it_fits(small, monkeypatch, caplog):
    A, b, nodal, modes = small
    monkeypatch.setattr(config, "CG_MAXITER", 2)
    monkeypatch.setattr(config, "DIRECT_MEMORY", 1e12)
    with caplog.at_level(logging.WARNING, logger="cnem.solvers.linsolve"):
        x = linsolve.solve_spd(A, b, modes=modes, method="amg", nodal=nodal)
    assert any("solving directly instead" in r.getMessage() for r in caplog.records)
    assert _relative_residual(A, x, b) <= 1e-12


def test_a_stalled_solve_that_cannot_go_direct_says_what_to_change(small, monkeypatch):
    A, b, nodal, modes = small
    monkeypatch.setattr(config, "CG_MAXITER", 2)
    monkeypatch.setattr(config, "DIRECT_MEMORY", 1e3)
    with pytest.raises(cnem.SolveError, match=r"stopped at relative residual .* after 2 "
                                              r"iterations .*would need about .* GB .*"
                                              r"method='direct'.*enrichment radius"):
        linsolve.solve_spd(A, b, modes=modes, method="amg", nodal=nodal)


def test_factor_estimate_is_an_upper_bound_of_the_measured_one(small):
    A, b, _, _ = small
    lu = spla.splu(A.tocsc())
    assert 12.0 * (lu.L.nnz + lu.U.nnz) <= linsolve.direct_factor_bytes(A) <= \
        3 * 12.0 * (lu.L.nnz + lu.U.nnz)


def test_nodal_mask_of_the_wrong_length_is_named(small):
    A, b, nodal, modes = small
    with pytest.raises(cnem.InputError, match=r"nodal: expected a \(\d+,\) boolean mask"):
        linsolve.solve_spd(A, b, method="amg", nodal=nodal[:-1] | False)


@pytest.mark.slow
def test_enriched_plate_of_16k_nodes_solves_on_the_automatic_path():
    # 15.9k nodes, 39.7k unknowns (8.2k enriched), 3.3M non-zeros: above DIRECT_NNZ, so
    # "auto" takes CG; it stalled before (residual 5.5e-6 after 2000 iterations)
    A, b, nodal, modes = cases.enriched_centre_crack_system(0.008)
    assert A.nnz > config.DIRECT_NNZ and 15_000 < len(nodal) // 2
    x = linsolve.solve_spd(A, b, modes=modes, nodal=nodal, tol=1e-10)
    assert _relative_residual(A, x, b) <= 1e-9


def _problems():
    """One small problem of each class that takes loads: C-NEM, P1 and PD."""
    import cnem.fem
    import cnem.pd as pd
    dom = cnem.geometry.rectangle()
    model = cnem.discretize(cnem.nodes.regular(dom, 0.25))
    g = np.linspace(0.0, 1.0, 6)
    body = pd.Body(np.array([(x, y) for x in g for y in g]), 0.04, 0.6)
    return {"cnem": cnem.Elasticity(model, (1.0, 0.3)),
            "p1": cnem.fem.P1Elasticity(dom, (1.0, 0.3), max_area=0.05),
            "pd": pd.Problem(body, pd.StateBased(1.0, 0.3))}


@pytest.mark.parametrize("kind", ["cnem", "p1", "pd"])
@pytest.mark.parametrize("bad", [5.0, [1.0, 2.0, 3.0], [[1.0, 2.0]]])
def test_an_ambiguous_constant_load_is_refused(kind, bad):
    """A bare number where a vector is meant (t = 5 became (5, 5)) and a constant of the
    wrong shape are refused, with the fix named; tractions and body forces alike."""
    prob = _problems()[kind]
    with pytest.raises(cnem.ConditionError, match="vector of 2 components"):
        prob.add_body_force(bad)
    with pytest.raises(cnem.ConditionError, match="pressure p along the outward normal"):
        prob.add_traction(lambda x, nrm: x[:, 0] > 1.0 - 1e-9, bad)


@pytest.mark.parametrize("kind", ["cnem", "p1", "pd"])
@pytest.mark.parametrize("tol", [-1.0, 0.0, float("nan")])
def test_a_tolerance_that_is_no_relative_residual_is_refused(kind, tol):
    """solve(tol=-1) ran (and PD advised more load steps): refused, with a value to use."""
    prob = _problems()[kind]
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_body_force([1.0, 0.0])
    with pytest.raises(cnem.InputError, match="tol: expected a positive relative residual"):
        prob.solve(tol=tol)


@pytest.mark.parametrize("steps", [2.5, 2.0, True, "3"])
def test_counts_that_are_not_whole_numbers_are_refused(steps):
    """Float load steps and time steps were truncated silently (2.5 ran 2 steps)."""
    prob = _problems()["pd"]
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_body_force([1.0, 0.0])
    with pytest.raises(cnem.InputError, match="steps: expected a whole number"):
        prob.solve(steps=steps)
    with pytest.raises(cnem.InputError, match="steps: expected a whole number"):
        prob.run_dynamic(1e-3, steps, progress=False)


@pytest.mark.parametrize("order", [0, -1, 2.5, 30])
def test_a_quadrature_order_that_does_not_exist_is_refused(order):
    """energy_error(order=0 or -1) integrated with some rule silently; 2.5 and 30 failed
    deep in scikit-fem: each is named."""
    prob = _problems()["cnem"]
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_body_force([1.0, 0.0])
    sol = prob.solve(progress=False)
    with pytest.raises(cnem.InputError, match="order: expected"):
        sol.energy_error(lambda x: np.zeros((len(x), 3)), order=order)


def test_the_wrong_object_is_named_with_the_call_that_makes_the_right_one():
    """A NodeCloud, a Model or None where something else is expected, and a misleading
    message on a NaN Poisson ratio, gave AttributeErrors or wrong names before."""
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.5, 0.5]]])
    cloud = cnem.nodes.regular(dom, 0.1)
    model = cnem.discretize(cloud)
    prob = cnem.Elasticity(model, (1.0, 0.3))
    prob.add_dirichlet(lambda x: x[:, 1] < 1e-9, None)
    prob.add_traction(lambda x, n: x[:, 1] > 1 - 1e-9, [0.0, 1.0])
    sol = prob.solve(progress=False)
    with pytest.raises(cnem.InputError, match="expects a Model, received NodeCloud; discretize"):
        cnem.Elasticity(cloud, (1.0, 0.3))
    with pytest.raises(cnem.MaterialError, match=r"Poisson ratios .* received \[nan\]"):
        cnem.Elasticity(model, (1.0, float("nan")))
    with pytest.raises(cnem.FractureError, match="received Model; solve the problem first"):
        cnem.fracture.sif(model, (0.5, 0.5))
    with pytest.raises(cnem.FractureError, match="received 'auto'"):
        cnem.fracture.sif(sol, (0.5, 0.5), radius="auto")
    with pytest.raises(cnem.FractureError, match=r"one point \(x, y\), received shape \(2, 2\)"):
        cnem.fracture.sif(sol, [[0.5, 0.5], [0.0, 0.5]])


def test_a_predicate_of_the_wrong_arity_and_a_setup_without_return_are_named():
    """A `where` taking the wrong arguments failed with a bare TypeError from inside it, and
    a grow setup that forgot `return prob` with an AttributeError on None."""
    prob = _problems()["cnem"]
    with pytest.raises(cnem.ConditionError, match=r"predicate where\(x\) of 1 argument"):
        prob.add_dirichlet(lambda x, nrm: x[:, 0] < 1e-9, None)
    with pytest.raises(cnem.ConditionError, match=r"predicate where\(x, nrm\) of 2 arguments"):
        prob.add_traction(lambda x: x[:, 0] > 1.0 - 1e-9, [1.0, 0.0])
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.3, 0.5]]])

    def setup(model):
        cnem.Elasticity(model, (1.0, 0.3))          # no return

    with pytest.raises(cnem.GrowthError, match="must return the problem it builds"):
        cnem.fracture.grow(dom, 0.1, setup, increment=0.05, steps=1, progress=False)
