"""Torsion of a square column (3-D), C-NEM against CPD on the same nodes: the example of
`cnem.demos.cnem_vs_cpd` after the seed paper's §6.3.

A column ``[0, a] x [0, a] x [0, L]`` (a = 1, L = 4: the seed's slenderness 4) has its
bottom face clamped and its top face turned rigidly about the column's axis by the
twist angle ``theta``, its axial displacement held (``u_z = 0``): the grip then carries
the torque ``T`` and the axial force ``N`` of the Poynting effect. The twist is applied
in increments, each a Newton solve from the last state with the top face's exact rigid
rotation (a ramp of the rotation's displacements would not be a rotation).

Both methods use one energy: CPD's one-neighbour Seth-Hill energy with ``n = 2`` (C2 =
C3 = 0) integrated over a full horizon ball is exactly Saint Venant-Kirchhoff with
``lambda = mu = C1 pi delta^4 / 30`` (``E = 5 mu / 2``, ``nu = 1/4``): C-NEM solves
`cnem.material.SaintVenantKirchhoff` with those moduli. C1 is calibrated per horizon by
the lattice sum of an interior point of the cloud's regular lattice (`lattice_factor`),
as the 2-D examples calibrate theirs: no point of a 1 x 1 section at 0.2 spacing has a
whole horizon of 3 or 4 spacings.

At small twist the torque is Saint-Venant's, ``T = k mu a^4 tau`` with ``tau = theta / L``
and ``k = 0.1406`` for a square (Timoshenko & Goodier, §109), less the end zones where
the clamps stop the section's warping.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np

import cnem
import cnem.pd as pd
from cnem.pd.cpd_moduli import moduli_per_constant
from cnem.solvers.newton import newton

from .versus import MAX_ITERATIONS, TOL, Run

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["SAINT_VENANT_SQUARE", "rigid_twist", "lattice_factor", "twist_cnem", "twist_cpd",
           "grip_loads"]

#: ``k`` of Saint-Venant's torque ``T = k mu a^4 tau`` of a square section of side a.
SAINT_VENANT_SQUARE = 0.1406


def rigid_twist(points: np.ndarray, angle: float, center: np.ndarray) -> np.ndarray:
    """Displacements ``(n, 3)`` of ``points (n, 3)`` turned by ``angle`` (radians) about
    the vertical axis through ``center (2,)``, with ``u_z = 0``."""
    x = points[:, :2] - center
    c, s = np.cos(angle), np.sin(angle)
    u = np.zeros_like(points)
    u[:, 0] = (c - 1.0) * x[:, 0] - s * x[:, 1]
    u[:, 1] = s * x[:, 0] + (c - 1.0) * x[:, 1]
    return u


def lattice_factor(spacing: float, horizon: float) -> float:
    """The one-neighbour lattice sum ``sum |Xi| beta V`` of a point of the cubic lattice
    of ``spacing`` (volumes ``spacing^3``) against its continuum value ``pi delta^4``
    (`cnem.demos.cpd.versus.bulk_factor` in 3-D, for a point with a whole horizon)."""
    k = int(np.ceil(horizon / spacing)) + 1
    g = spacing * np.arange(-k, k + 1.0)
    points = np.stack(np.meshgrid(g, g, g, indexing="ij"), -1).reshape(-1, 3)
    body = pd.Body(points, spacing ** 3, horizon)
    centre = int(np.argmin(np.linalg.norm(points, axis=1)))
    own = body.bond_i == centre
    total = (body.length * body.beta * body.volumes[body.bond_j])[own].sum()
    return float(total / (np.pi * horizon ** 4))


def _ends(points, length):
    """The bottom and top faces' nodes (bool ``(n,)`` each) and the section's centre."""
    tol = 1e-9 * length
    centre = 0.5 * (points[:, :2].min(axis=0) + points[:, :2].max(axis=0))
    return points[:, 2] < tol, points[:, 2] > length - tol, centre


def _supports(points, length, angle):
    """Prescribed dofs (node-major, 3 per node) of the clamped bottom and the turned top,
    and their values at ``angle``."""
    bottom, top, centre = _ends(points, length)
    nodes = np.flatnonzero(bottom | top)
    fixed = (3 * nodes[:, None] + np.arange(3)).ravel()
    values = np.where(top[nodes, None], rigid_twist(points[nodes], angle, centre), 0.0).ravel()
    return fixed, values, top, centre


def _twist(evaluate, points, length, angles, pattern=None):
    """Newton at each twist angle (radians) from the last state: ``Run`` with ``u``
    and ``force`` ``(s, n, 3)``, ``history``, ``iterations``, ``seconds``."""
    u = np.zeros(points.size)
    states, forces, history = [], [], []
    start = time.perf_counter()
    for angle in angles:
        fixed, values, top, centre = _supports(points, length, angle)
        u, steps = newton(evaluate, np.zeros(points.size), fixed, values, points=points,
                          pattern=pattern, initial=u, tol=TOL, max_iterations=MAX_ITERATIONS)
        history += steps
        states.append(u.reshape(-1, 3))
        forces.append(evaluate(u, False)[0].reshape(-1, 3))
    return Run(u=np.array(states), force=np.array(forces), history=history,
               iterations=sum(len(h) - 1 for h in history),
               seconds=time.perf_counter() - start, top=top, centre=centre)


def twist_cnem(model: cnem.Model, mu: float, length: float, angles: Sequence[float]) -> Run:
    """C-NEM (`cnem.Hyperelasticity`, Saint Venant-Kirchhoff with ``lambda = mu``) of the
    column ``model`` at the twist ``angles`` (radians): one load step per angle, the top
    face turned rigidly along a Dirichlet ``path`` through them."""
    prob = cnem.Hyperelasticity(model, cnem.material.SaintVenantKirchhoff(2.5 * mu, 0.25))
    points, steps = model.nodes, len(angles)
    bottom, top, centre = _ends(points, length)
    factors = np.arange(1, steps + 1) / steps                  # the load factors k / steps
    prob.add_dirichlet(bottom, None)
    prob.add_dirichlet(top, None,
                       path=lambda p, t: rigid_twist(p, np.interp(t, factors, angles), centre))
    sol = prob.solve(steps=steps, tol=TOL, max_iterations=MAX_ITERATIONS, progress=False)
    return Run(u=np.array([dofs.reshape(-1, 3) for _, dofs in sol.steps]),
               force=np.array([prob.system.evaluate(dofs, False)[0].reshape(-1, 3)
                               for _, dofs in sol.steps]),
               history=sol.residual_history,
               iterations=sum(len(h) - 1 for h in sol.residual_history),
               seconds=sol.timings["newton"], top=top, centre=centre)


def twist_cpd(cloud: cnem.NodeCloud, horizon_factor: float, mu: float, spacing: float,
              length: float, angles: Sequence[float]) -> Run:
    """CPD (`cnem.pd.CPD`, one-neighbour, ``n = 2``) on the nodes of ``cloud``
    (`cnem.pd.Body.from_cloud`, horizon ``horizon_factor`` spacings) with C1 giving the
    lattice of ``spacing`` the shear modulus ``mu`` (`lattice_factor`), at the twist
    ``angles`` (radians). The run also has ``C1``, ``bulk``, ``horizon``, ``setup_seconds``
    and ``pairs``/``triplets``: how many two- and three-neighbour interactions the body
    would have (C2, C3 > 0), counted, not built."""
    start = time.perf_counter()
    body = pd.Body.from_cloud(cloud, horizon_factor)
    bulk = lattice_factor(spacing, body.horizon)
    C1 = mu / (bulk * moduli_per_constant(3, body.horizon)[0, 1])
    prob = pd.Problem(body, pd.CPD(C1, exponent=2.0))
    evaluate, pattern = prob.behaviour.static_system()
    setup = time.perf_counter() - start
    run = _twist(evaluate, body.points, length, angles, pattern)
    family = np.bincount(body.bond_i, minlength=len(body)).astype(float)
    run.update(C1=C1, bulk=bulk, horizon=body.horizon, setup_seconds=setup,
               pairs=float((family * (family - 1) / 2).sum()),
               triplets=float((family * (family - 1) * (family - 2) / 6).sum()))
    return run


def grip_loads(points: np.ndarray, run: Run) -> tuple[np.ndarray, np.ndarray]:
    """Torque about the column's axis and axial force the top grip applies, per twist
    (``(s,)`` each): the internal forces of the top nodes with the lever arms of their
    deformed positions."""
    top = run.top
    arm = points[top, :2] + run.u[:, top, :2] - run.centre
    f = run.force[:, top]
    torque = (arm[..., 0] * f[..., 1] - arm[..., 1] * f[..., 0]).sum(axis=1)
    return torque, f[..., 2].sum(axis=1)
