"""Pointwise stress `sol.stress_at(points)`: patch recovery of the cell stresses at the
nodes, interpolated by the shape functions (`cnem.assembly.recovery`)."""

import numpy as np
import pytest

import cnem
from cnem.assembly.recovery import recover_at_nodes, values_at
from cnem.geometry import plate_with_hole

from cases import model as case_model


def _random_points(model, count, seed):
    """Points of the domain: random ones inside and some on the boundary segments."""
    rng = np.random.default_rng(seed)
    lo, hi = np.reshape(model.domain.bounds, (2, 2))
    pts = rng.uniform(lo, hi, (4 * count, 2))
    inside = pts[model.domain.contains(pts)][:count]
    seg = np.asarray(model.segments)[rng.integers(0, len(model.segments), 20)]
    s = rng.uniform(0.0, 1.0, (20, 1))
    on_boundary = model.nodes[seg[:, 0]] * (1 - s) + model.nodes[seg[:, 1]] * s
    return np.concatenate([inside, on_boundary])


@pytest.mark.parametrize("name", ["lshape_irregular", "plate_hole_irregular",
                                  "three_rectangles_irregular"])
def test_linear_displacement_gives_the_cell_stress_everywhere(name):
    """Patch test: a linear displacement imposed on the whole boundary gives one
    stress; stress_at returns it at random points, inside and on the boundary."""
    _, _, model = case_model(name)
    prob = cnem.Elasticity(model, (100.0, 0.25))
    grad = np.array([[1e-3, 2e-3], [-5e-4, 3e-3]])
    prob.add_dirichlet(model.boundary_nodes(), None, lambda p: p @ grad.T)
    sol = prob.solve(progress=False)
    pts = _random_points(model, 200, seed=3)
    np.testing.assert_allclose(sol.stress_at(pts), np.broadcast_to(sol.stress[0], (len(pts), 3)),
                               atol=1e-10 * np.abs(sol.stress).max())


@pytest.mark.parametrize("name", ["lshape_irregular", "three_rectangles_irregular"])
def test_recovery_is_exact_for_linear_cell_fields_per_region(name):
    """A cell field linear in the centroids, another linear function in each region,
    comes back exactly at any point, with the point's region's function (sharp at
    the interfaces)."""
    _, _, model = case_model(name)
    rng = np.random.default_rng(1)
    regions = model.domain.n_regions
    coef = rng.normal(size=(regions, 2, 3))
    const = rng.normal(size=(regions, 3))
    r = model.cells.region
    field = np.einsum("ki,kij->kj", model.cells.centroid(), coef[r]) + const[r]
    nodal = recover_at_nodes(model, model.cells, field)
    pts = _random_points(model, 200, seed=5)
    pr = model.domain.region_of(pts)
    pts, pr = pts[pr >= 0], pr[pr >= 0]          # (round-off puts some just outside)
    want = np.einsum("ki,kij->kj", pts, coef[pr]) + const[pr]
    np.testing.assert_allclose(values_at(model, nodal, pts), want, atol=1e-9)


def test_points_outside_are_refused_with_the_fix():
    _, _, model = case_model("square_irregular")
    prob = cnem.Elasticity(model, (1.0, 0.3))
    prob.add_dirichlet(model.boundary_nodes(), None, lambda p: 1e-3 * p)
    sol = prob.solve(progress=False)
    with pytest.raises(cnem.GeometryError, match="1 of 2 outside.*domain.contains"):
        sol.stress_at([[0.5, 0.5], [2.0, 0.5]])


def _kirsch(center, a, s0):
    """The exact stress of an infinite plate with a hole of radius ``a`` under uniaxial
    tension ``s0`` along x (Kirsch), ``[sxx, syy, sxy]`` at points."""
    def stress(x):
        d = x - center
        r, t = np.hypot(d[:, 0], d[:, 1]), np.arctan2(d[:, 1], d[:, 0])
        q = a * a / r ** 2
        srr = s0 / 2 * (1 - q) + s0 / 2 * (1 - 4 * q + 3 * q * q) * np.cos(2 * t)
        stt = s0 / 2 * (1 + q) - s0 / 2 * (1 + 3 * q * q) * np.cos(2 * t)
        srt = -s0 / 2 * (1 + 2 * q - 3 * q * q) * np.sin(2 * t)
        c, s = np.cos(t), np.sin(t)
        return np.column_stack([srr * c * c + stt * s * s - 2 * srt * s * c,
                                srr * s * s + stt * c * c + 2 * srt * s * c,
                                (srr - stt) * s * c + srt * (c * c - s * s)])
    return stress


@pytest.mark.parametrize("along", [0, 1])
def test_stress_concentration_of_a_hole_with_the_default_graded_cloud(along):
    """Kirsch: a square plate of side 20 a with a hole of radius a, the exact traction of
    the infinite plate under tension along x (``along=0``) or y on its outer sides;
    `plate_with_hole` and `cnem.nodes.graded` with their defaults (spacing a towards
    a / 50 at the hole). The stress along the load at the hole's edge, across the load
    (at 90 degrees from it; for tension along y, 0 degrees is a corner of the hole's
    polygon), is 3 s0 within 1 %, read by stress_at at the edge itself (no extrapolation
    by the user)."""
    a, s0, L = 1.0, 1.0, 10.0
    center = np.array([L, L])
    along_x = _kirsch(center, a, s0)
    turn = np.array([[0.0, -1.0], [1.0, 0.0]]) if along else np.eye(2)   # tension along y

    def exact(x):
        s = along_x(center + (x - center) @ turn)
        return s[:, [1, 0, 2]] * [1, 1, -1] if along else s

    dom = plate_with_hole(2 * L, 2 * L, a)
    angle = np.linspace(0.0, 2 * np.pi, 200, endpoint=False)
    ring = center + a * np.column_stack([np.cos(angle), np.sin(angle)])
    model = cnem.discretize(cnem.nodes.graded(dom, a, near=ring, h_min=a / 50))
    prob = cnem.Elasticity(model, (1.0, 0.3))

    def traction(x, nrm):
        s = exact(x)
        return np.column_stack([s[:, 0] * nrm[:, 0] + s[:, 2] * nrm[:, 1],
                                s[:, 2] * nrm[:, 0] + s[:, 1] * nrm[:, 1]])

    for side in ("left", "right", "bottom", "top"):
        prob.add_traction(side, traction)
    left = np.argmin(np.hypot(*(model.nodes - [0.0, L]).T))
    right = np.argmin(np.hypot(*(model.nodes - [2 * L, L]).T))
    prob.add_dirichlet([left], None)
    prob.add_dirichlet([right], 1)
    sol = prob.solve(progress=False)
    across = np.array([[0.0, 1.0], [0.0, -1.0]]) if along == 0 else np.array([[1.0, 0.0],
                                                                              [-1.0, 0.0]])
    edge = center + a * across
    np.testing.assert_allclose(exact(edge)[:, along], 3.0 * s0, rtol=1e-12)
    scf = sol.stress_at(edge)[:, along] / s0
    np.testing.assert_allclose(scf, 3.0, rtol=0.01)
    # and the von Mises stress around the hole follows Kirsch within 2 % of the peak
    theta = np.deg2rad(np.arange(0.0, 181.0, 15.0))
    around = center + a * np.column_stack([np.cos(theta), np.sin(theta)])
    got = cnem.solvers.solution.von_mises(sol.stress_at(around))
    want = cnem.solvers.solution.von_mises(exact(around))
    assert np.abs(got - want).max() < 0.02 * 3.0 * s0


def test_solutions_without_pointwise_stress_say_so():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    prob = cnem.pd.Problem(cnem.pd.Body(pts, 0.25, 1.5), cnem.pd.BondBased(1.0))
    prob.add_dirichlet(lambda p: p[:, 0] < 0.5, None)
    prob.add_dirichlet(lambda p: p[:, 0] > 0.5, 0, 0.01)
    sol = prob.solve()
    with pytest.raises(cnem.UnsupportedError, match="stress_at.*points"):
        sol.stress_at(pts)


def test_plot_zooms_to_bounds(tmp_path):
    pytest.importorskip("pyvista")
    _, _, model = case_model("plate_hole_irregular")
    prob = cnem.Elasticity(model, (1.0, 0.3))
    prob.add_dirichlet("left", None)
    prob.add_traction("right", [1.0, 0.0])
    sol = prob.solve(progress=False)
    whole = sol.plot()
    zoom = sol.plot(tmp_path / "zoom.png", bounds=(0.2, 0.3, 0.5, 0.6))
    assert zoom.camera.parallel_scale < 0.5 * whole.camera.parallel_scale
    assert 0.2 < zoom.camera.focal_point[0] < 0.6 and 0.3 < zoom.camera.focal_point[1] < 0.6
    assert (tmp_path / "zoom.png").stat().st_size > 0
    whole.close()
    zoom.close()
    with pytest.raises(cnem.PlotInputError, match="bounds"):
        sol.plot(bounds=(1.0, 0.0, 0.0, 1.0))


def test_linear_displacement_in_3d():
    """The same recovery serves a 3-D model: the patch test at points inside and on
    faces, Voigt (p, 6)."""
    model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.box((0, 0, 0), (1, 1, 1)),
                                                 0.34, seed=0))
    prob = cnem.Elasticity(model, (1.0, 0.3))
    grad = np.array([[1e-3, 2e-3, 0.0], [-5e-4, 3e-3, 1e-3], [0.0, 1e-3, -2e-3]])
    prob.add_dirichlet(model.boundary_nodes(), None, lambda p: p @ grad.T)
    sol = prob.solve(progress=False)
    pts = np.random.default_rng(0).uniform(0.05, 0.95, (50, 3))
    pts = np.vstack([pts, [[0.5, 0.5, 0.0], [1.0, 0.3, 0.6]]])
    got = sol.stress_at(pts)
    assert got.shape == (52, 6)
    np.testing.assert_allclose(got, np.broadcast_to(sol.stress[0], got.shape),
                               atol=1e-10 * np.abs(sol.stress).max())
