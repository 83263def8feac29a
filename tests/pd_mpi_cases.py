"""Small peridynamic problems run serially (in the test process) and under mpiexec.

``python tests/pd_mpi_cases.py OUT.npz CASE...`` (under ``mpiexec -n N``) runs the cases
with `cnem.pd.distributed` and rank 0 saves the gathered results; the tests build
the same problems with `cnem.pd` and compare. ``setup(module, case)`` is the one
definition of each problem for both.
"""

from __future__ import annotations

import os
import sys

import numpy as np

H = 2.5e-3                       # a 40 x 16 cell-centred grid of the 0.1 m x 0.04 m plate
LENGTH, HEIGHT, NOTCH = 0.1, 0.04, 0.05
STEPS = {"bond": 300, "state": 120, "periodic": 300, "cube": 150}   # the serial state-based run re-assembles
                                                          # its stiffness at every breaking step
CHECKPOINT = 200                 # the one checkpoint of a bond-based run
DT = 2.5e-7                      # below the serial stable steps of every case (3.3e-7 and up)
CASES = ("bond", "state", "periodic", "cube", "relax")


def plate():
    """Cell-centred points of the plate (no point on the notch line y = 0)."""
    x = (np.arange(round(LENGTH / H)) + 0.5) * H
    y = (np.arange(round(HEIGHT / H)) + 0.5) * H - 0.5 * HEIGHT
    X, Y = np.meshgrid(x, y, indexing="ij")
    return np.column_stack([X.ravel(), Y.ravel()])


def setup(pd, case, **body_options):
    """The problem of ``case`` built with ``pd`` (`cnem.pd` or `cnem.pd.distributed`).

    * ``bond``, ``state``: a notched glass plate pulled suddenly by tractions on its
      top and bottom rows (the crack-branching set-up, coarse), bonds breaking;
    * ``periodic``: a plate periodic in x and y with a shear velocity field, bonds
      breaking;
    * ``cube``: a bond-based 3-D block of 8^3 points blown apart by a radial velocity,
      bonds breaking;
    * ``relax``: a state-based plate clamped on the left and stretched on the right
      (with every bond across ``x = CUT`` broken: the ``cut`` launch, `cut_forces`).
    """
    pts = plate()
    horizon = 3.015 * H
    if case == "periodic":
        body = pd.Body(pts + [0.0, 0.5 * HEIGHT], H * H, horizon, period=[LENGTH, HEIGHT],
                       **body_options)
        return pd.Problem(body, pd.BondBased(72e9, critical_stretch=4e-4, density=2440.0))
    if case == "cube":
        k = 8
        grid = (np.indices((k,) * 3, dtype=float).reshape(3, -1).T + 0.5) * H
        body = pd.Body(grid, H ** 3, 2.015 * H, **body_options)
        return pd.Problem(body, pd.BondBased(72e9, critical_stretch=3e-4, density=4 * 2440.0))
    if case == "relax":
        body = pd.Body(pts, H * H, horizon, **body_options)
        prob = pd.Problem(body, pd.StateBased(72e9, 0.22))
        prob.add_dirichlet(lambda p: p[:, 0] < H, None)
        prob.add_dirichlet(lambda p: p[:, 0] > LENGTH - H, 0, 1e-6)
        return prob
    body = pd.Body(pts, H * H, horizon, cracks=[[[-horizon, 0.0], [NOTCH, 0.0]]], **body_options)
    material = pd.BondBased(72e9, critical_stretch=6e-4, density=2440.0) if case == "bond" \
        else pd.StateBased(72e9, 0.25, critical_stretch=6e-4, density=2440.0)
    prob = pd.Problem(body, material)
    edge = 0.5 * HEIGHT - H
    prob.add_body_force(lambda p: np.where(p[:, 1:] > edge, [0.0, 12e6 / H],
                                           np.where(p[:, 1:] < -edge, [0.0, -12e6 / H], 0.0)))
    prob.add_dirichlet(lambda p: (p[:, 0] > LENGTH - H) & (np.abs(p[:, 1]) < H), 1)
    return prob


def cut(prob, points_i, points_j):
    """Break every bond of ``prob`` from one side of ``x = CUT`` to the other (``points_i``,
    ``points_j`` the two ends of its bonds); returns the number broken."""
    crossing = (points_i[:, 0] < CUT) != (points_j[:, 0] < CUT)
    prob.alive[crossing] = 0
    if hasattr(prob, "alive_reverse"):
        prob.alive_reverse[crossing] = 0
    return int(crossing.sum())


CUT = 0.5 * LENGTH + 0.3 * H     # the line of the ``cut`` case (between two columns of points)


def cut_field(p):
    """A displacement field of the ``cut`` case, different on the two sides, m."""
    x, y = p[:, 0] / LENGTH, p[:, 1] / LENGTH
    left = (p[:, 0] < CUT)[:, None]
    return 1e-5 * np.where(left, np.column_stack([np.sin(3 * x + y), x * y]),
                           np.column_stack([y * y - x, np.cos(2 * y - 5 * x)]))


def blast(p):
    """Initial velocity of the cube: radial from its centre, m/s."""
    return 0.4 * (p - 4.0 * H) / H                 # the centre of the 8^3 block


def shear(p):
    """Initial velocity of the periodic case: a sine shear, m/s."""
    return np.column_stack([3.0 * np.sin(2 * np.pi * p[:, 1] / HEIGHT), np.zeros(len(p))])


def run(prob, case, **options):
    """Run ``case`` on ``prob``: a dynamic run or a relaxation."""
    if case == "relax":
        return prob.relax(tol=1e-9, progress=False)
    velocity = {"periodic": shear, "cube": blast}.get(case)
    return prob.run_dynamic(DT, STEPS[case], velocity=velocity, progress=False, **options)


def main(out, cases):
    """The ``cases`` with `cnem.pd.distributed` (``"restart"``: a checkpointed and a resumed
    bond-based run, with VTU frames; ``"cut"``: `cut_forces`); rank 0 saves the results to
    ``out``."""
    import cnem.pd.distributed as dpd
    results = {}
    for case in (c for c in cases if c not in ("restart", "cut")):
        prob = setup(dpd, case)
        res = run(prob, case)
        results[f"{case}_u"] = res.u
        if case != "relax":
            results[f"{case}_broken"] = res.broken_bonds
            results[f"{case}_energy"] = res.energy
    if "restart" in cases:
        results.update(restart(dpd, os.path.dirname(out)))
    if "cut" in cases:
        results.update(cut_forces(dpd))
    from mpi4py import MPI
    if MPI.COMM_WORLD.rank == 0:
        np.savez(out, **results)


def cut_forces(dpd):
    """The ``relax`` plate with every bond across ``x = CUT`` broken: its internal force
    (per unit volume) and dilatation at `cut_field`, gathered."""
    prob = setup(dpd, "relax")
    b = prob.body
    cut(prob, b.points[b.bond_i], b.points[b.bond_j])
    prob.ops.follow_breaking(prob.alive)
    u = np.ascontiguousarray(cut_field(b.points))
    force, _ = prob.internal_force(u, np.inf)
    return {"cut_force": prob.gather(force),
            "cut_theta": prob.gather(prob.ops.dilatation(u, prob.alive))}


def restart(dpd, folder):
    """A run checkpointed at step `CHECKPOINT` and one resumed from it (VTU frames)."""
    results = {}
    stem = os.path.join(folder, "checkpoint", "run")
    run(setup(dpd, "bond"), "bond", checkpoint=stem, checkpoint_every=CHECKPOINT)
    resumed = run(setup(dpd, "bond"), "bond", restart=stem,
                  output=os.path.join(folder, "frames", "run"), every=50)
    results["resumed_first"] = resumed.times[0] / DT
    results["resumed_u"] = resumed.u
    results["resumed_broken"] = resumed.broken_bonds
    results["frames"] = np.array([str(f) for f in resumed.files])
    return results


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
