"""One protocol for problems and solutions: C-NEM (`cnem.Elasticity`), the P1 anchor
(`cnem.fem.P1Elasticity`) and peridynamics (`cnem.pd.Problem`) take the same
conditions, solve by `solve`, and return solutions with the same fields and shapes;
the three agree on a patch test (uniform strain)."""

from __future__ import annotations

import dataclasses

import meshio
import numpy as np
import pytest

import cnem
import cnem.fem as fem
import cnem.pd as pd
from cnem.errors import ConditionError
from cnem.solvers.conditions import Conditions
from cnem.solvers.solution import Solution
from cnem.material import stiffness_matrix

E, NU = 1.0, 0.3
#: the uniform strain of the patch test, and the linear displacement it comes from
GRAD = np.array([[1e-3, 3e-4], [1e-4, -5e-4]])
STRAIN = np.array([GRAD[0, 0], GRAD[1, 1], GRAD[0, 1] + GRAD[1, 0]])


def _linear(points):
    return points @ GRAD.T


def _on_boundary(p, width=1e-9):
    return (np.minimum(p, 1.0 - p) < width).any(axis=1)


def _cnem():
    model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(), 0.1, seed=2),
                            progress=False)
    return cnem.Elasticity(model, (E, NU))


def _p1():
    return fem.P1Elasticity(cnem.geometry.rectangle(), (E, NU), nodes=150)


#: PD point spacing
H = 0.025


def _pd(h=H):
    g = np.arange(0.0, 1.0 + 1e-9, h)
    pts = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)
    return pd.Problem(pd.Body(pts, h * h, 3.015 * h), pd.StateBased(E, NU))


PROBLEMS = {"C-NEM": _cnem, "P1": _p1, "PD": _pd}
#: where each solver's stresses live, and how many places there are
PLACES = {"C-NEM": ("cells", lambda prob: len(prob.cells.area)),
          "P1": ("triangles", lambda prob: prob.mesh.t.shape[1]),
          "PD": ("points", lambda prob: len(prob.body.points))}


@pytest.fixture(scope="module", params=list(PROBLEMS))
def solved(request):
    """A small problem of each class, clamped on the left and stretched by a body force."""
    name = request.param
    prob = PROBLEMS[name]()
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_body_force([1e-2, -1e-3])
    return name, prob, prob.solve()


@pytest.mark.parametrize("name", list(PROBLEMS))
def test_every_problem_offers_the_conditions_and_solve(name):
    prob = PROBLEMS[name]()
    assert isinstance(prob, Conditions)
    for method in ("add_dirichlet", "add_traction", "add_body_force", "solve", "prescribed"):
        assert callable(getattr(prob, method)), method
    points = prob.condition_points
    assert points.shape[1] == 2
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, 0, 0.5)
    # the corner again, agreeing on component 0: one dof, one value
    prob.add_dirichlet(lambda p: (p[:, 0] < 1e-9) & (p[:, 1] < 1e-9), None,
                       lambda p: np.column_stack([np.full(len(p), 0.5), 2 * p[:, 1] + 1]))
    dofs, values = prob.prescribed()
    left = np.flatnonzero(points[:, 0] < 1e-9)
    corner = np.flatnonzero((points[:, 0] < 1e-9) & (points[:, 1] < 1e-9))
    expected = {2 * i: 0.5 for i in left}
    expected.update({2 * i + 1: 2 * points[i, 1] + 1 for i in corner})
    assert dofs.tolist() == sorted(expected)
    np.testing.assert_array_equal(values, [expected[k] for k in sorted(expected)])
    # the corner with another value on component 0: a conflict, named
    prob.add_dirichlet(lambda p: (p[:, 0] < 1e-9) & (p[:, 1] < 1e-9), 0, 1.0)
    with pytest.raises(ConditionError, match=r"conflicting values on 1 dof.*0\.5 and 1"):
        prob.prescribed()
    if name == "PD":
        # a lattice knows no boundary edges: it takes a traction on points with the area
        # each carries (`cnem.pd.tractions`), and refuses one without it
        with pytest.raises(NotImplementedError, match="plain Body has no boundary edges"):
            prob.boundary_edges()
        with pytest.raises(ConditionError, match="exactly one of area= .* or spacing="):
            prob.add_traction(lambda x: x[:, 0] > 1.0 - 1e-9, [1.0, 0.0])
        prob.add_traction(lambda x: x[:, 0] > 1.0 - 1e-9, [1.0, 0.0], spacing=H)
        assert len(prob.tractions) == 1
        return
    edges, normal = prob.boundary_edges()
    assert edges.shape[1] == 2 and normal.shape == (len(edges), 2)
    # the body lies on the left of every edge: the normal points to its right
    d = points[edges[:, 1]] - points[edges[:, 0]]
    np.testing.assert_allclose(normal * np.hypot(*d.T)[:, None], np.column_stack([d[:, 1], -d[:, 0]]),
                               atol=1e-12)
    right = normal[:, 0] > 0.5
    assert np.isclose(np.hypot(*d[right].T).sum(), 1.0)         # the right edge, length 1
    prob.add_traction(lambda x, n: n[:, 0] > 0.5, [1.0, 0.0])
    assert len(prob.tractions) == 1


def test_p1_boundary_facets_is_boundary_edges():
    prob = _p1()
    facets, midpoint, normal = prob.boundary_facets()
    edges, normal2 = prob.boundary_edges()
    np.testing.assert_array_equal(normal, normal2)
    np.testing.assert_allclose(midpoint, prob.nodes[edges].mean(axis=1), atol=1e-15)
    np.testing.assert_array_equal(np.sort(prob.mesh.facets[:, facets].T, axis=1),
                                  np.sort(edges, axis=1))


def test_pd_solve_static_is_solve():
    prob = _pd(0.1)
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_body_force([1.0, 0.0])
    np.testing.assert_array_equal(prob.solve_static(steps=2).u, prob.solve(steps=2).u)


def test_pd_results_are_declared_dataclasses(tmp_path):
    """Dynamics and relaxation return `Solution` dataclasses with only declared fields."""
    prob = _pd(0.1)
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_body_force([1e-3, 0.0])
    n = len(prob.body.points)
    for result in (prob.run_dynamic(0.2 * prob.stable_time_step(), 5, progress=False),
                   prob.relax(tol=1e-6, progress=False)):
        assert isinstance(result, Solution) and dataclasses.is_dataclass(result)
        declared = {f.name for f in dataclasses.fields(result)}
        assert set(vars(result)) <= declared, set(vars(result)) - declared
        assert result.stress.shape == result.strain.shape == (n, 3)
        np.testing.assert_array_equal(result.stress, result.stress_tensor()[:, [0, 1, 0], [0, 1, 1]])
        point_data = meshio.read(result.write(tmp_path / "pd.vtu")).point_data
        np.testing.assert_array_equal(point_data["damage"], result.damage)


def test_cpd_solutions_write_without_stress(tmp_path):
    g = np.arange(0.0, 1.0 + 1e-9, 0.25)
    pts = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)
    prob = pd.Problem(pd.Body(pts, 0.0625, 0.4), pd.CPD(1.0))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_dirichlet(lambda p: p[:, 0] > 1 - 1e-9, 0, 0.01)
    sol = prob.solve()
    with pytest.raises(NotImplementedError, match="CPD"):
        sol.stress
    assert sol.strain.shape == (len(pts), 3)
    components = {f"strain_{c}" for c in ("xx", "yy", "zz", "yz", "xz", "xy")}
    assert set(meshio.read(sol.write(tmp_path / "cpd.vtu")).point_data) == {"displacement",
                                                                          "strain"} | components


def test_every_solution_has_the_same_fields(solved, tmp_path):
    name, prob, sol = solved
    n = len(prob.condition_points)
    where, count = PLACES[name]
    k = count(prob)
    assert isinstance(sol, Solution) and dataclasses.is_dataclass(sol)
    assert sol.stress_places == where
    assert sol.u.shape == (n, 2)
    assert sol.stress.shape == (k, 3) and sol.strain.shape == (k, 3)
    assert sol.von_mises.shape == (k,)
    sxx, syy, sxy = sol.stress.T
    np.testing.assert_allclose(sol.von_mises, np.sqrt(sxx ** 2 - sxx * syy + syy ** 2 + 3 * sxy ** 2))
    # the displacement at the nodes (points) is u there
    some = np.linspace(0, n - 1, 7).astype(int)
    np.testing.assert_allclose(sol.displacement(prob.condition_points[some]), sol.u[some],
                               atol=1e-12 * np.abs(sol.u).max())
    assert np.abs(sol.u).max() > 0
    path = sol.write(tmp_path / f"{name}.vtu")
    mesh = meshio.read(path)
    np.testing.assert_array_equal(mesh.points[:n, :2], prob.condition_points)
    # ParaView's form (issue 39): a 3-component displacement, 9-component tensors
    np.testing.assert_array_equal(mesh.point_data["displacement"][:n, :2], sol.u)
    assert (mesh.point_data["displacement"][:, 2] == 0).all()
    stored = mesh.point_data if where == "points" else {
        key: np.concatenate(blocks) for key, blocks in mesh.cell_data.items()}
    for field in ("stress", "strain"):
        values = stored[field]
        assert values.shape[1:] == (9,) and len(values) >= k and np.isfinite(values).any(), field
        xx, yy, xy = getattr(sol, field).T
        if field == "strain":
            xy = xy / 2                                     # tensor, not engineering, shears
        for column, entry in ((0, xx), (4, yy), (1, xy), (3, xy)):
            assert np.isin(entry, values[:, column]).all(), (field, column)
    assert np.isin(sol.von_mises, stored["von_mises"]).all()


def test_every_solution_plots(solved, tmp_path):
    pytest.importorskip("pyvista")
    name, _, sol = solved
    path = tmp_path / f"{name}.png"
    sol.plot(path, window_size=(300, 300)).close()
    assert path.stat().st_size > 1000


@pytest.mark.parametrize("name", list(PROBLEMS))
def test_patch_test_uniform_strain(name):
    """A linear displacement on the boundary (for PD on a layer of two horizons and two
    spacings, so that every free point and its family's points have whole families): every solver gives the linear field
    and the uniform stress ``C eps`` to round-off (SCNI passes the patch test, P1 is
    exact for linear fields, and the surface-corrected LPS stores the classical
    energy of a uniform strain at every point of a lattice)."""
    prob = PROBLEMS[name]()
    width = 2 * (prob.body.horizon + H) if name == "PD" else 1e-9
    fixed = _on_boundary(prob.condition_points, width)
    prob.add_dirichlet(fixed, None, _linear)
    sol = prob.solve()
    points = prob.condition_points
    exact = _linear(points)
    np.testing.assert_allclose(sol.u, exact, atol=1e-9 * np.abs(exact).max())
    stress = stiffness_matrix(E, NU, "stress") @ STRAIN
    # PD: the points with whole families (C-NEM and P1: every cell and triangle)
    places = ~fixed if name == "PD" else slice(None)
    strain_found, stress_found = sol.strain[places], sol.stress[places]
    assert len(stress_found) > 100
    np.testing.assert_allclose(strain_found, np.broadcast_to(STRAIN, strain_found.shape),
                               atol=1e-9 * np.abs(STRAIN).max())
    np.testing.assert_allclose(stress_found, np.broadcast_to(stress, stress_found.shape),
                               atol=1e-9 * np.abs(stress).max())
