"""3-D finite strain against closed forms: the incompressible neo-Hookean thick sphere
inflated by an imposed cavity radius, and Rivlin's torsion (`cnem.exact`). The closed
forms are checked first against the radial equilibrium they come from, integrated
numerically."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

import cnem
from cnem.exact import inflated_sphere_pressure, rivlin_torsion


@pytest.mark.parametrize("la", [1.1, 1.5, 2.0, 3.0])
def test_sphere_pressure_is_the_integral_of_radial_equilibrium(la):
    """``p = int_a^b 2 mu (lambda^2 - lambda^-4) / r dr``, ``lambda = r / R``,
    ``R^3 = r^3 - (a^3 - A^3)``; and the cavitation limit ``5 mu / 2`` of a large body."""
    mu, A, B = 1.7, 0.8, 1.9
    c = (la ** 3 - 1) * A ** 3
    stretch = lambda r: r / np.cbrt(r ** 3 - c)                     # noqa: E731
    b = np.cbrt(B ** 3 + c)
    p, _ = quad(lambda r: 2 * mu * (stretch(r) ** 2 - stretch(r) ** -4) / r, la * A, b,
                epsabs=0, epsrel=1e-12)
    assert np.isclose(inflated_sphere_pressure(la, A, B, mu), p, rtol=1e-10)
    assert np.isclose(inflated_sphere_pressure(1e3, A, 1e6 * A, mu), 2.5 * mu, rtol=1e-3)


def test_rivlin_torque_and_axial_force_are_the_integrals_of_the_stresses():
    """``M = int 2 pi r^2 sigma_thetaz dr``, ``N = int 2 pi r sigma_zz dr`` with
    ``sigma_thetaz = mu tau r`` and ``sigma_zz = int_a^r mu tau^2 s ds``."""
    mu, a = 0.6, 1.3
    tau = np.array([0.2, 0.7])
    M, N = rivlin_torsion(tau, a, mu)
    for t, m, n in zip(tau, M, N):
        szz = lambda r: -quad(lambda s: mu * t * t * s, r, a)[0]   # noqa: E731
        assert np.isclose(m, quad(lambda r: 2 * np.pi * r * r * mu * t * r, 0, a)[0])
        assert np.isclose(n, quad(lambda r: 2 * np.pi * r * szz(r), 0, a)[0])
        assert n < 0


def test_closed_forms_refuse_bad_input():
    with pytest.raises(cnem.errors.InputError, match="inner < outer"):
        inflated_sphere_pressure(1.5, 2.0, 1.0, 1.0)
    with pytest.raises(cnem.errors.InputError, match="mu"):
        rivlin_torsion(0.5, 1.0, -1.0)


def _thick_sphere():
    """Hollow sphere A = 1, B = 2 (icospheres of 2 subdivisions), `nodes.irregular(0.4)`
    (820 nodes): the model, its cavity's nodes, and ``pressure(f, la)``, the
    work-conjugate of the imposed dilation ``p = sum_inner f . X / (3 la^2 V_cavity)``
    (exact for any dead displacement-controlled surface: ``dPi / dla = p dV / dla``),
    with ``exact(la)``, the closed form with the radii of the icospheres' volumes."""
    from cnem.geometry.shapes3d import sphere_surface
    dom = cnem.geometry.hollow_sphere(1.0, 2.0, subdivisions=2)
    model = cnem.discretize(cnem.nodes.irregular(dom, 0.4, seed=1))
    inner = np.flatnonzero(np.linalg.norm(model.nodes, axis=1) < 1 + 1e-9)

    def volume(radius):
        v, f = sphere_surface(radius, subdivisions=2)
        return np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])).sum() / 6

    cavity = volume(1.0)
    A, B = (np.cbrt(3 * volume(r) / (4 * np.pi)) for r in (1.0, 2.0))

    def pressure(f, la):
        f = f.reshape(-1, 3)
        return np.einsum("ij,ij->", f[inner], model.nodes[inner]) / (3 * la ** 2 * cavity)

    return model, inner, pressure, lambda la: inflated_sphere_pressure(la, A, B, 1.0)


@pytest.mark.slow
def test_thick_sphere_inflation_coarse_against_the_closed_form():
    """The thick sphere (`_thick_sphere`), NeoHookean lam / mu = 2000, the cavity's
    nodes moved radially to ``lambda_a X``, outer surface free, default stabilisation.
    Measured at this coarse size (about 2.5 node layers through the wall): +1.4 % at
    1.2, growing to +7 % at 1.5 (docs/finite_strain.md); bound 3 % at 1.2."""
    mu, la = 1.0, 1.2
    model, inner, pressure, exact = _thick_sphere()
    prob = cnem.Hyperelasticity(model, cnem.material.NeoHookean(mu, 2000 * mu))
    prob.add_dirichlet(inner, None, lambda p: (la - 1) * p)
    sol = prob.solve(steps=4, tol=1e-8, max_iterations=30, progress=False)
    p = pressure(prob.system.evaluate(sol.dofs, False)[0], la)
    assert abs(p / exact(la) - 1) < 0.03


@pytest.mark.slow
def test_thick_sphere_inflation_with_fbar():
    """The same sphere with ``volumetric="fbar"`` (and the default stabilisation), to
    ``lambda_a = 1.5`` in 10 load steps with a line search (the increments of the 20
    steps to 2 of docs/finite_strain.md, where 10 steps to 2 stall in the second; the
    whole curve to 2 takes two minutes, too long for the suite). Measured: -2.2 % at
    1.1, -0.9 % at 1.5; to 2: crossing zero near 1.7, +2.2 % at 2.0 (the default ends
    +9 % high at 1.6 and does not converge past 1.65); bound 3 % at every step."""
    la_end, steps = 1.5, 10
    model, inner, pressure, exact = _thick_sphere()
    prob = cnem.Hyperelasticity(model, cnem.material.NeoHookean(1.0, 2000.0),
                                volumetric="fbar")
    prob.add_dirichlet(inner, None, lambda p: (la_end - 1) * p)
    sol = prob.solve(steps=steps, tol=1e-8, max_iterations=30, line_search=True,
                     progress=False)
    assert len(sol.steps) == steps
    for factor, dofs in sol.steps:
        la = 1 + (la_end - 1) * factor
        p = pressure(prob.system.evaluate(dofs, False)[0], la)
        assert abs(p / exact(la) - 1) < 0.03, la


def _polygon_radius(segments):
    """The radius of the circle with the polar moment of the regular ``segments``-gon
    inscribed in the unit circle: ``(2 J / pi)^(1/4)``."""
    t = 2 * np.pi * np.arange(segments) / segments
    v = np.column_stack([np.cos(t), np.sin(t)])
    w = np.roll(v, -1, axis=0)
    area = 0.5 * (v[:, 0] * w[:, 1] - v[:, 1] * w[:, 0])
    J = (area / 6 * ((v * v).sum(1) + (w * w).sum(1) + (v * w).sum(1))).sum()
    return (2 * J / np.pi) ** 0.25


@pytest.mark.slow
def test_rivlin_torsion_in_load_steps_of_a_rotation_path():
    """Cylinder a = 1, L = 2 (`cylinder(segments=32)`, 332 nodes), NeoHookean lam / mu =
    2000 with F-bar, bottom clamped, top turned rigidly by ``t tau L`` (``u_z = 0``) along
    a Dirichlet path in 4 load steps to tau = 0.1: torque ``M = sum_top (x x f)_z`` (deformed
    lever arms) and axial force ``N = sum_top f_z`` against Rivlin's, with the polygon's
    polar-moment radius. Measured: M -0.48 % to -0.50 %, N +2.5 % to +1.8 %
    (docs/finite_strain.md, "Rivlin torsion through a rotation path"); bounds 1 % and 4 %."""
    a, L, tau = 1.0, 2.0, 0.1
    model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.cylinder(a, L, segments=32),
                                                 0.35, seed=1), progress=False)
    top = model.nodes[:, 2] > L * (1 - 1e-9)

    def turned(p, t):
        c, s = np.cos(t * tau * L), np.sin(t * tau * L)
        return np.column_stack([(c - 1) * p[:, 0] - s * p[:, 1], s * p[:, 0] + (c - 1) * p[:, 1],
                                np.zeros(len(p))])

    prob = cnem.Hyperelasticity(model, cnem.material.NeoHookean(1.0, 2000.0), volumetric="fbar")
    prob.add_dirichlet(lambda p: p[:, 2] < 1e-9 * L, None)
    prob.add_dirichlet(top, None, path=turned)
    sol = prob.solve(steps=4, tol=1e-8, max_iterations=30, line_search=True, progress=False)
    for t, dofs in sol.steps:
        f = prob.system.evaluate(dofs, False)[0].reshape(-1, 3)[top]
        x = (model.nodes + dofs.reshape(-1, 3))[top]
        M, N = (x[:, 0] * f[:, 1] - x[:, 1] * f[:, 0]).sum(), f[:, 2].sum()
        M_exact, N_exact = rivlin_torsion(t * tau, _polygon_radius(32) * a, 1.0)
        assert abs(M / M_exact - 1) < 0.01, t
        assert abs(N / N_exact - 1) < 0.04, t
