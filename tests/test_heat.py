"""Steady heat conduction (`cnem.HeatConduction`) against exact solutions."""

import pathlib
import runpy

import meshio
import numpy as np
import pytest

import cnem
from cnem.geometry import rectangle


K = 2.0


def _manufactured(x):
    return np.sin(np.pi * x[:, 0]) * np.cos(np.pi * x[:, 1] / 2) + x[:, 0] ** 2


def _manufactured_gradient(x):
    return np.column_stack([
        np.pi * np.cos(np.pi * x[:, 0]) * np.cos(np.pi * x[:, 1] / 2) + 2 * x[:, 0],
        -np.pi / 2 * np.sin(np.pi * x[:, 0]) * np.sin(np.pi * x[:, 1] / 2)])


def _manufactured_source(x):
    """``-k laplace(T)`` of `_manufactured`."""
    return K * (1.25 * np.pi ** 2 * np.sin(np.pi * x[:, 0]) * np.cos(np.pi * x[:, 1] / 2) - 2)


def test_manufactured_solution_on_an_l_shape_converges_at_rate_one_in_h1():
    """T = sin(pi x) cos(pi y / 2) + x^2 on the L-shape (non-convex), its source, T fixed
    on the whole boundary: the H1 error halves with the spacing (slope 1)."""
    dom = cnem.geometry.l_shape()
    errors, nodal = [], []
    for h in (0.1, 0.05):
        model = cnem.discretize(cnem.nodes.irregular(dom, h, seed=1))
        prob = cnem.HeatConduction(model, K)
        prob.add_temperature(model.boundary_nodes(), _manufactured)
        prob.add_source(_manufactured_source)
        sol = prob.solve()
        errors.append(sol.h1_error(_manufactured_gradient))
        nodal.append(np.abs(sol.T - _manufactured(model.nodes)).max())
        norm = sol.h1_error(lambda x: np.zeros_like(x))                 # |T_h|_1
    rate = np.log(errors[0] / errors[1]) / np.log(2.0)
    assert 0.85 < rate < 1.3, (errors, rate)
    assert errors[1] < 0.06 * norm                  # a few per cent of |T|_1 (about 1.5)
    assert nodal[1] < nodal[0]


def test_convection_slab_matches_the_closed_form():
    """A slab 0 < x < L, T0 at x = 0, convection h (T - T_inf) at x = L, the other sides
    insulated: T = T0 + (T_inf - T0) h x / (k + h L), linear, so exact to round-off;
    the heat flux is the same constant in every cell and at any point."""
    L, T0, Tinf, h = 2.0, 100.0, 20.0, 25.0
    model = cnem.discretize(cnem.nodes.irregular(rectangle(L, 1.0), 0.15, seed=3))
    prob = cnem.HeatConduction(model, K)
    prob.add_temperature("left", T0)
    prob.add_convection(lambda x, nrm: nrm[:, 0] > 0.5, h=h, ambient=Tinf)
    sol = prob.solve()
    slope = (Tinf - T0) * h / (K + h * L)
    np.testing.assert_allclose(sol.T, T0 + slope * model.nodes[:, 0], atol=1e-9 * T0)
    np.testing.assert_allclose(sol.flux, np.tile([-K * slope, 0.0], (len(sol.flux), 1)),
                               atol=1e-8 * abs(K * slope))
    pts = np.array([[2.0, 0.3], [0.7, 0.0], [1.1, 0.45]])
    np.testing.assert_allclose(sol.flux_at(pts), np.tile([-K * slope, 0.0], (3, 1)),
                               atol=1e-8 * abs(K * slope))
    np.testing.assert_allclose(sol.temperature(pts), T0 + slope * pts[:, 0], atol=1e-9 * T0)


def test_two_conductivities_in_series_match_the_closed_form():
    """Two layers k1 on 0 < x < a and k2 on a < x < L, T fixed at both ends: one flux q
    through both, T piecewise linear with the kink at the interface — exact to
    round-off. With the flux given at x = 0 instead, the same solution."""
    a, L, k1, k2, T0, T1 = 0.4, 1.0, 5.0, 1.0, 10.0, 0.0
    dom = cnem.Domain([[[0, 0], [a, 0], [a, 1], [0, 1]], [[a, 0], [L, 0], [L, 1], [a, 1]]])
    model = cnem.discretize(cnem.nodes.irregular(dom, 0.08, seed=2))
    q = (T0 - T1) / (a / k1 + (L - a) / k2)
    x = model.nodes[:, 0]
    exact = np.where(x <= a, T0 - q * x / k1, T0 - q * a / k1 - q * (x - a) / k2)
    prob = cnem.HeatConduction(model, [k1, k2])
    prob.add_temperature(lambda p: p[:, 0] < 1e-9, T0)
    prob.add_temperature(lambda p: p[:, 0] > L - 1e-9, T1)
    sol = prob.solve()
    np.testing.assert_allclose(sol.T, exact, atol=1e-9 * T0)
    np.testing.assert_allclose(sol.flux[:, 0], q, rtol=1e-8)
    given_flux = cnem.HeatConduction(model, [k1, k2])
    given_flux.add_flux(lambda c, nrm: nrm[:, 0] < -0.5, q)
    given_flux.add_temperature(lambda p: p[:, 0] > L - 1e-9, T1)
    np.testing.assert_allclose(given_flux.solve().T, exact, atol=1e-9 * T0)


def test_a_source_with_convection_on_all_sides_balances():
    """Global balance: the heat the source makes leaves by convection, to round-off."""
    model = cnem.discretize(cnem.nodes.irregular(rectangle(1.0, 0.5), 0.1, seed=0))
    prob = cnem.HeatConduction(model, 3.0)
    prob.add_source(7.0)
    prob.add_convection(lambda x, nrm: np.ones(len(x), bool), h=4.0, ambient=1.0)
    sol = prob.solve()
    edges, _ = prob.boundary_edges()
    ends = model.nodes[edges]
    length = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
    out = 4.0 * (length * (sol.T[edges].mean(axis=1) - 1.0)).sum()
    assert out == pytest.approx(7.0 * 0.5, rel=1e-10)


def test_bad_inputs_are_refused_with_the_fix():
    model = cnem.discretize(cnem.nodes.regular(rectangle(), 0.25))
    with pytest.raises(cnem.InputError, match="conductivity"):
        cnem.HeatConduction(model, -1.0)
    with pytest.raises(cnem.InputError, match="one per region"):
        cnem.HeatConduction(model, [1.0, 2.0])
    prob = cnem.HeatConduction(model, 1.0)
    with pytest.raises(cnem.ConditionError, match="positive"):
        prob.add_convection("right", h=-1.0, ambient=0.0)
    with pytest.raises(cnem.ConditionError, match="a number or a callable"):
        prob.add_flux("right", [1.0, 0.0])
    with pytest.raises(cnem.ConditionError, match="known names|unknown|boundar"):
        prob.add_temperature("nowhere", 1.0)
    prob.add_flux("right", 1.0)
    with pytest.raises(cnem.SolveError, match="up to a constant"):
        prob.solve()


def test_file_and_picture(tmp_path):
    model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.plate_with_hole(2.0, 1.0, 0.25),
                                                 0.08, seed=0))
    prob = cnem.HeatConduction(model, 1.0)
    prob.add_temperature("left", 0.0)
    prob.add_temperature("hole0", 100.0)
    prob.add_convection("right", h=2.0, ambient=20.0)
    sol = prob.solve()
    mesh = meshio.read(sol.write(tmp_path / "heat.vtu"))
    assert np.nanmax(mesh.point_data["T"]) == pytest.approx(100.0)
    pytest.importorskip("pyvista")
    sol.plot(tmp_path / "T.png", title="T (°C)").close()
    assert (tmp_path / "T.png").stat().st_size > 0


def test_the_docs_insulated_pipe_matches_its_exact_solution():
    """docs/examples/heat_pipe.py (two layers, a fixed temperature and convection by
    boundary names) at a coarse spacing: temperatures, H1 error and the heat lost."""
    example = runpy.run_path(str(pathlib.Path(__file__).parents[1] / "docs" / "examples"
                                 / "heat_pipe.py"))
    out = example["main"](h=0.012, plot=False)
    assert out["T_error_max"] < 0.005 * (150.0 - 20.0)
    assert out["h1_error_relative"] < 0.05
    assert out["Q"] == pytest.approx(out["Q_exact"], rel=5e-3)
    assert out["T_surface"] == pytest.approx(out["T_surface_exact"], abs=0.5)
