"""Stress intensity factors (`cnem.fracture.sif`) against exact near-tip fields.

The Williams field of given K_I, K_II is imposed as Dirichlet data on every
boundary node (crack faces on their own side), so the exact SIFs are known;
`sif` must find them within 2 % at modest node counts, converge with
refinement and not depend on the radius of its integration disc.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

import cnem
from cnem.fracture import nodal_williams, polar, sif, tip_frame, williams

E, NU = 1.0, 0.3


@functools.lru_cache(maxsize=None)
def _model(angle_deg, h, irregular):
    """A square of side 2 about a tip at the origin, the crack coming in along -d."""
    a = np.deg2rad(angle_deg)
    d = np.array([np.cos(a), np.sin(a)])
    start = -d / np.abs(d).max()
    dom = cnem.geometry.rectangle(2.0, 2.0, origin=(-1.0, -1.0), cracks=[[start, [0.0, 0.0]]])
    cloud = cnem.nodes.irregular(dom, h, seed=1) if irregular else cnem.nodes.regular(dom, h)
    return cnem.discretize(cloud, progress=False)


def _solve(model, KI, KII, plane):
    exact = nodal_williams(model, (0.0, 0.0), KI, KII, E, NU, plane)
    boundary = np.unique(model.segments[model.segment_kind != 1])
    prob = cnem.Elasticity(model, (E, NU), plane=plane)
    prob.add_dirichlet(boundary, None, lambda p: exact[boundary])
    return prob.solve(progress=False)


CASES = [(0.0, 1.0, 0.0, "strain"), (0.0, 0.0, 1.0, "stress"), (30.0, 1.0, 0.5, "stress"),
         (135.0, 0.3, 1.0, "strain"), (-60.0, 1.0, -1.0, "stress")]


@pytest.mark.parametrize("irregular", [False, True])
@pytest.mark.parametrize("angle, KI, KII, plane", CASES)
def test_sif_of_imposed_williams_fields(angle, KI, KII, plane, irregular):
    sol = _solve(_model(angle, 0.1, irregular), KI, KII, plane)
    out = sif(sol, (0.0, 0.0), radius=0.6)
    np.testing.assert_allclose(out, [KI, KII], atol=0.02 * max(abs(KI), abs(KII)))
    np.testing.assert_allclose(out.direction, [np.cos(np.deg2rad(angle)), np.sin(np.deg2rad(angle))],
                               atol=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("angle, KI, KII, plane", CASES[1:3])
def test_sif_converges_with_refinement(angle, KI, KII, plane):
    errors = []
    for h in (0.2, 0.1, 0.05):
        out = sif(_solve(_model(angle, h, False), KI, KII, plane), (0.0, 0.0), radius=0.6)
        errors.append(np.hypot(out[0] - KI, out[1] - KII))
    assert errors[1] < errors[0] and errors[2] < 0.5 * errors[0], errors


def test_path_independence():
    sol = _solve(_model(30.0, 0.05, True), 1.0, 0.5, "stress")
    values = np.array([sif(sol, (0.0, 0.0), radius=R) for R in (0.4, 0.55, 0.7)])
    assert np.ptp(values[:, 0]) < 0.02 and np.ptp(values[:, 1]) < 0.02 * 0.5, values


def test_a_disc_below_a_few_spacings_warns():
    """A user's disc that holds less than ``SIF_SPACINGS`` node spacings cannot resolve
    the field (K_I about half the exact 1 on an edge-crack model): it warns, naming the
    smallest radius to use; a disc of several spacings gives K_I and does not warn."""
    sol = _solve(_model(0.0, 0.05, True), 1.0, 0.0, "strain")
    with pytest.warns(cnem.SIFWarning, match="local node spacings"):
        sif(sol, (0.0, 0.0), radius=0.02)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error", cnem.SIFWarning)
        assert abs(sif(sol, (0.0, 0.0), radius=0.4).KI - 1.0) < 0.03


def test_default_radius_is_a_few_spacings():
    sol = _solve(_model(0.0, 0.1, False), 1.0, 0.0, "strain")
    out = sif(sol, (0.05, 0.02))               # the nearest tip is taken
    assert 0.3 <= out.radius <= 1.0
    np.testing.assert_allclose(out.tip, [0.0, 0.0], atol=1e-15)
    assert abs(out.KI - 1.0) < 0.03


def test_internal_crack_both_tips_agree_in_sign_and_size():
    """An inclined central crack under remote tension: by symmetry both tips have the
    same K_I and K_II in their own frames, with K_II > 0 for 0 < gamma < 90 degrees."""
    g = np.deg2rad(30.0)
    a = 0.2
    d = a * np.array([np.cos(g), np.sin(g)])
    dom = cnem.geometry.rectangle(2.0, 2.0, origin=(-1.0, -1.0), cracks=[[-d, d]])
    cloud = cnem.nodes.graded(dom, 0.1, near=dom.tips, h_min=0.01, growth=0.15, seed=0)
    model = cnem.discretize(cloud, progress=False)
    prob = cnem.Elasticity(model, (E, NU))
    on_top_bottom = lambda x, n: np.abs(np.abs(x[:, 1]) - 1.0) < 1e-9     # not the crack faces
    prob.add_traction(on_top_bottom, lambda x, n: n * [0.0, 1.0])
    prob.add_dirichlet(lambda p: np.hypot(*(p - [-1.0, -1.0]).T) < 1e-12, None)
    prob.add_dirichlet(lambda p: np.hypot(*(p - [1.0, -1.0]).T) < 1e-12, 1)
    sol = prob.solve(progress=False)
    right, left = sif(sol, d), sif(sol, -d)
    np.testing.assert_allclose(right, left, rtol=0.02)
    assert right.KII > 0 and left.KII > 0
    exact = np.sqrt(np.pi * a) * np.array([np.cos(g) ** 2, np.sin(g) * np.cos(g)])
    # a finite square plate (a / W = 0.2) raises K_I by a few % (the strip alone by
    # sqrt(sec(pi a / 2 W)) = 1.025)
    ratio = np.array(right) / exact
    assert ((ratio > 0.97) & (ratio < 1.08)).all(), ratio


def test_williams_derivatives_and_hooke():
    rng = np.random.default_rng(0)
    r, th = rng.uniform(0.1, 1.0, 40), rng.uniform(-3.1, 3.1, 40)
    for plane in ("stress", "strain"):
        u, s, du = williams(r, th, 1.3, -0.7, 2.0, NU, plane)
        x1, x2 = r * np.cos(th), r * np.sin(th)
        h = 1e-6

        def disp(a, b):
            return williams(np.hypot(a, b), np.arctan2(b, a), 1.3, -0.7, 2.0, NU, plane)[0]
        fd1 = (disp(x1 + h, x2) - disp(x1 - h, x2)) / (2 * h)
        fd2 = (disp(x1, x2 + h) - disp(x1, x2 - h)) / (2 * h)
        np.testing.assert_allclose(du, fd1, atol=1e-8 * np.abs(du).max())
        C = cnem.elasticity.stiffness_matrix(2.0, NU, plane)
        strain = np.stack([fd1[:, 0], fd2[:, 1], fd1[:, 1] + fd2[:, 0]], axis=-1)
        np.testing.assert_allclose(strain @ C.T, s, atol=1e-8 * np.abs(s).max())


def test_polar_and_tip_frame():
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.3, 0.5], [0.5, 0.7]]])
    tip, d = tip_frame(dom, (0.9, 0.9))
    np.testing.assert_allclose(tip, [0.5, 0.7])
    np.testing.assert_allclose(d, np.array([1.0, 1.0]) / np.sqrt(2))
    r, theta = polar(np.array([[0.5, 0.7 + 0.1]]), tip, d)
    np.testing.assert_allclose([r[0], theta[0]], [0.1, np.pi / 4])


def test_errors():
    sol = _solve(_model(0.0, 0.2, False), 1.0, 0.0, "strain")
    with pytest.raises(ValueError, match="positive"):
        sif(sol, (0.0, 0.0), radius=-1.0)
    with pytest.raises(ValueError, match="tip"):
        sif(sol, (0.0, 0.0, 0.0))
    dom = cnem.geometry.rectangle()
    model = cnem.discretize(cnem.nodes.regular(dom, 0.25))
    prob = cnem.Elasticity(model, (E, NU))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-12, None)
    with pytest.raises(ValueError, match="no crack tip"):
        sif(prob.solve(progress=False), (0.5, 0.5))


@pytest.mark.parametrize("functions", ["sqrt", "branch"])
@pytest.mark.parametrize("name", ["edge_crack_regular", "kinked_crack_irregular"])
def test_patch_test_with_enrichment(name, functions):
    """A linear field on every boundary node (crack faces included) is reproduced
    with the enrichment on: enriched coefficients vanish, strains are exact."""
    import cases
    _, _, model = cases.model(name)
    prob = cnem.Elasticity(model, (E, NU), enrich=dict(radius=0.2, functions=functions))
    assert len(prob.enrichment) > 0
    field = lambda p: np.column_stack([1e-3 * (1 + 2 * p[:, 0] - p[:, 1]), 1e-3 * (0.5 * p[:, 0] + p[:, 1])])
    boundary = np.unique(model.segments[model.segment_kind != 1])
    prob.add_dirichlet(boundary, None, field)
    sol = prob.solve(progress=False)
    np.testing.assert_allclose(sol.u, field(model.nodes), atol=1e-12)
    # the enriched system is less well conditioned: round-off is amplified ~1e4 times
    np.testing.assert_allclose(sol.enriched, 0.0, atol=1e-8)
    np.testing.assert_allclose(sol.strain, np.broadcast_to(1e-3 * np.array([2.0, 1.0, -0.5]), sol.strain.shape),
                               atol=1e-8)


@pytest.mark.parametrize("functions", ["sqrt", "branch"])
def test_enrichment_gradients_match_finite_differences(functions):
    """The gradients of the enrichment functions psi_jk (and so of an enriched
    displacement field) equal central differences of their values at random
    points (generic points: off the circumcircles where Sibson gradients jump)."""
    model = _model(30.0, 0.2, True)
    enr = cnem.fracture.Enrichment(model, [(0.0, 0.0)], 0.5, functions=functions)
    rng = np.random.default_rng(3)
    pts = rng.uniform(-0.6, 0.6, (40, 2))
    pts = pts[np.hypot(*pts.T) > 0.05]
    phi, dx, dy = model.shape_functions(pts, gradient=True)
    psi, gx, gy = enr.values(pts, phi, gradient=(dx, dy))
    step = 1e-7
    for axis, grad in enumerate((gx, gy)):
        e = np.zeros(2)
        e[axis] = step
        plus = enr.values(pts + e, model.shape_functions(pts + e)).toarray()
        minus = enr.values(pts - e, model.shape_functions(pts - e)).toarray()
        np.testing.assert_allclose(grad.toarray(), (plus - minus) / (2 * step), atol=2e-5)
    assert abs(psi).max() > 0 and abs(gx).max() > 0


def test_pointwise_energy_error_of_an_enriched_solution_vanishes_on_a_linear_field():
    """The displacement gradient at points (Sibson + enrichment gradients) is exact
    for a linear field: the pointwise energy error vanishes to round-off."""
    import cases
    _, _, model = cases.model("edge_crack_regular")
    prob = cnem.Elasticity(model, (E, NU), enrich=dict(radius=0.2, functions="branch"))
    field = lambda p: np.column_stack([1e-3 * (1 + 2 * p[:, 0] - p[:, 1]), 1e-3 * (0.5 * p[:, 0] + p[:, 1])])
    boundary = np.unique(model.segments[model.segment_kind != 1])
    prob.add_dirichlet(boundary, None, field)
    sol = prob.solve(progress=False)
    D = E / (1 - NU ** 2) * np.array([[1, NU, 0], [NU, 1, 0], [0, 0, (1 - NU) / 2]])
    sigma = D @ (1e-3 * np.array([2.0, 1.0, -0.5]))
    exact = lambda x: np.tile(sigma, (len(x), 1))
    assert sol.energy_error(exact, strain="pointwise") < 1e-7 * np.linalg.norm(sigma)
    with pytest.raises(ValueError, match="pointwise"):
        sol.energy_error(exact, strain="nodal")


@pytest.mark.slow
def test_enrichment_improves_an_imposed_singular_field():
    """The mode-I Williams field imposed on the boundary: the enriched solutions are
    closer to it (energy norm) than plain C-NEM on the same nodes."""
    model = _model(0.0, 0.1, False)
    errors, pointwise = {}, {}
    for enrich in (None, dict(radius=0.3), dict(radius=0.3, functions="branch")):
        exact = nodal_williams(model, (0.0, 0.0), 1.0, 0.0, E, NU, "strain")
        boundary = np.unique(model.segments[model.segment_kind != 1])
        prob = cnem.Elasticity(model, (E, NU), plane="strain", enrich=enrich)
        prob.add_dirichlet(boundary, None, lambda p: exact[boundary])
        sol = prob.solve(progress=False)

        def stress(x):
            r, theta = polar(x, np.zeros(2), np.array([1.0, 0.0]))
            return williams(r, theta, 1.0, 0.0, E, NU, "strain")[1]
        key = enrich and enrich.get("functions", "sqrt")
        errors[key] = sol.energy_error(stress)
        pointwise[key] = sol.energy_error(stress, strain="pointwise")
    assert errors["sqrt"] < 0.95 * errors[None], errors
    # the branch functions span the near-tip field: the error of u - u_h itself drops
    assert pointwise["branch"] < 0.9 * pointwise[None], pointwise      # measured ratio 0.81


def test_bad_enrichment():
    model = _model(0.0, 0.2, False)
    with pytest.raises(ValueError, match="positive"):
        cnem.Elasticity(model, (E, NU), enrich=dict(radius=-1.0))
    with pytest.raises(ValueError, match="functions"):
        cnem.Elasticity(model, (E, NU), enrich=dict(radius=0.3, functions="cubic"))
    with pytest.raises(ValueError, match="enrich"):
        cnem.Elasticity(model, (E, NU), enrich=0.3)
