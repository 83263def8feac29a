"""`cnem.solvers.newton`: the one Newton solver, on a chain of nonlinear springs.

Springs of force ``k (s + s^3)`` (``s`` the elongation) join the nodes ``0..m`` of a
line; node 0 is held and node ``m`` is pulled. Every spring carries the same force, so
the exact equilibrium under a force ``F`` at node ``m`` (or under a displacement ``U`` of
node ``m``) follows from one cubic.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import cnem
from cnem.solvers.newton import newton


def chain(m, k=1.0):
    """``evaluate(u, tangent)`` of ``m`` springs ``k (s + s^3)`` between nodes ``0..m``."""
    incidence = sp.diags([-np.ones(m), np.ones(m)], [0, 1], shape=(m, m + 1)).tocsr()

    def evaluate(u, tangent):
        s = incidence @ u
        force = incidence.T @ (k * (s + s ** 3))
        if not tangent:
            return force, None
        return force, (incidence.T @ sp.diags(k * (1 + 3 * s ** 2)) @ incidence).tocsr()
    return evaluate


def spring_elongation(force, k=1.0):
    """The real root ``s`` of ``k (s + s^3) = force``."""
    roots = np.roots([k, 0.0, k, -force])
    return float(roots[np.argmin(abs(roots.imag))].real)


def pulled(m, force):
    load = np.zeros(m + 1)
    load[-1] = force
    return load


def test_force_controlled_chain_reaches_the_exact_equilibrium():
    m, F = 5, 3.0
    u, history = newton(chain(m), pulled(m, F), [0], [0.0], points=None, tol=1e-12)
    s = spring_elongation(F)
    np.testing.assert_allclose(u, s * np.arange(m + 1), rtol=1e-12, atol=1e-14)
    assert len(history) == 1 and history[0][-1] <= 1e-12 * F


def test_convergence_is_quadratic():
    _, (res,) = newton(chain(4), pulled(4, 2.0), [0], [0.0], points=None, tol=1e-14)
    # once in the basin, each residual is about the square of the last (relative)
    rel = np.array(res) / res[0]
    tail = [i for i in range(1, len(rel) - 1) if rel[i] < 1e-2 and rel[i + 1] > 1e-13]
    assert tail, res
    for i in tail:
        assert rel[i + 1] <= 10 * rel[i] ** 2, res


def test_displacement_controlled_load_steps_follow_the_ramp():
    m, U, steps = 3, 1.5, 4
    u, history = newton(chain(m), np.zeros(m + 1), [0, m], [0.0, U], points=None,
                        steps=steps)
    np.testing.assert_allclose(u, U / m * np.arange(m + 1), rtol=1e-12, atol=1e-14)
    assert len(history) == steps
    # every step starts from the tangent predictor of its increment: a residual left
    assert all(r[0] > 0 for r in history)


def test_more_load_steps_give_the_same_solution():
    one, _ = newton(chain(6), pulled(6, 4.0), [0], [0.0], points=None, tol=1e-13)
    five, history = newton(chain(6), pulled(6, 4.0), [0], [0.0], points=None, tol=1e-13,
                           steps=5)
    np.testing.assert_allclose(five, one, rtol=1e-11)
    assert len(history) == 5


@pytest.mark.filterwarnings("ignore")                # plain Newton overflows on purpose
def test_line_search_damps_an_overshooting_step():
    """``f(u) = atan(u)``: plain Newton from far out diverges (each step overshoots
    further), the halving line search converges to the root."""
    def evaluate(u, tangent):
        return np.arctan(u), sp.csr_matrix(1.0 / (1.0 + u[None, :] ** 2)) if tangent else None
    with pytest.raises(cnem.ConvergenceError):
        newton(evaluate, np.zeros(1), [], [], points=None, initial=[3.0])
    u, (res,) = newton(evaluate, np.zeros(1), [], [], points=None, initial=[3.0],
                       line_search=True, tol=1e-12)
    assert abs(u[0]) < 1e-12
    assert all(b < a for a, b in zip(res, res[1:]))        # every accepted step decreases it


def test_linear_system_is_solved_by_the_first_correction():
    K = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(5, 5)).tocsr()
    u, (res,) = newton(lambda u, tangent: (K @ u, K), np.ones(5), [0, 4], [0.0, 1.0],
                       points=None, linear=True)
    np.testing.assert_allclose(K[1:4, 1:4] @ u[1:4] - np.array([1.0, 1.0, 2.0]), 0,
                               atol=1e-12)
    assert len(res) == 2


def test_a_problem_that_cannot_converge_raises_with_its_history():
    """No equilibrium: springs ``atan`` can carry at most pi / 2, the load is 2."""
    def evaluate(u, tangent):
        return np.arctan(u), sp.csr_matrix(1.0 / (1.0 + u[None, :] ** 2)) if tangent else None
    with pytest.raises(cnem.ConvergenceError, match="load step 2 of 2") as err:
        newton(evaluate, np.array([2.0]), [], [], points=None, steps=2, max_iterations=6,
               line_search=True)
    history = err.value.history
    assert isinstance(err.value, cnem.SolveError)
    assert len(history) == 2 and len(history[1]) == 7 and np.isfinite(history[1]).all()


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_non_finite_forces_are_named():
    def evaluate(u, tangent):
        return np.log(u), sp.csr_matrix(1.0 / u[None, :]) if tangent else None
    with pytest.raises(cnem.ConvergenceError, match="not finite") as err:
        newton(evaluate, np.array([-5.0]), [], [], points=None, initial=[0.5])
    assert not np.isfinite(err.value.history[-1][-1])


def test_free_rigid_motions_are_refused_up_front():
    points = np.array([[0.0, 0.0], [1.0, 0.0]])
    K = sp.csr_matrix(np.array([[1.0, 0, -1, 0], [0, 0, 0, 0], [-1, 0, 1, 0], [0, 0, 0, 0]]))
    with pytest.raises(cnem.SolveError, match="singular"):
        newton(lambda u, tangent: (K @ u, K), np.zeros(4), [0], [0.0], points=points)


def test_bad_counts_are_refused():
    with pytest.raises(cnem.InputError, match="steps: expected a whole number >= 1"):
        newton(chain(2), np.zeros(3), [0], [0.0], points=None, steps=0)


def test_values_at_replaces_the_linear_ramp():
    """A linear chain with its end held along ``values_at(t) = sin(pi t / 2)``: after each
    load step the end sits at the path's value, the chain on the line to it."""
    K = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(5, 5)).tocsr()
    path = lambda t: np.array([0.0, np.sin(np.pi * t / 2)])     # noqa: E731
    states = []
    newton(lambda u, tangent: (K @ u, K), np.zeros(5), [0, 4], path(1.0), points=None,
           linear=True, steps=3, values_at=path, on_step=lambda k, u: states.append(u))
    for k, u in enumerate(states, 1):
        np.testing.assert_allclose(u, path(k / 3)[1] * np.arange(5) / 4, atol=1e-12)


def test_values_at_of_the_wrong_shape_is_named():
    with pytest.raises(cnem.InputError, match=r"values_at\(0.5\): expected 2 finite values"):
        newton(chain(3), np.zeros(4), [0, 3], [0.0, 1.0], points=None, steps=2,
               values_at=lambda t: np.array([0.0, t, 1.0]))
    with pytest.raises(cnem.InputError, match="NaN or inf"):
        newton(chain(3), np.zeros(4), [0, 3], [0.0, 1.0], points=None,
               values_at=lambda t: np.array([0.0, np.nan]))
