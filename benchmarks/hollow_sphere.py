"""Convergence study: Lamé's hollow sphere by 3-D C-NEM and by P1 tetrahedra on the same nodes.

Workload
--------
The hollow sphere ``inner = 0.5 <= r <= outer = 1`` (``cnem.geometry.hollow_sphere``, its
surfaces as icospheres of ``--subdivisions`` levels, by default the fewest whose edges on
the cavity are at most ``h``), E = 1, nu = 0.3, an internal pressure
p = 1 (the traction ``-p n`` on the cavity) and the exact displacement of
`cnem.exact.ThickSphere` held on the outer surface, so that the discrete problem has no rigid
motion and its exact solution is Lamé's. For each spacing ``h`` one irregular cloud
``cnem.nodes.irregular(dom, h, seed=0)``, one model, and on it:

* **C-NEM**: ``cnem.Elasticity(model, (E, nu))`` (default stabilisation);
* **P1**: ``cnem.fem.P1Elasticity.from_model(model, (E, nu))`` on the model's tetrahedra.

What is measured
----------------
The energy-norm error ``sol.energy_error(exact.stress)`` of each side, relative to the exact
solution's energy norm (``sqrt(2 U)``, ``2 U = p u_r(a) 4 pi a^2``), its rate between
successive rows against the nominal ``h`` (``log(e1/e2) / log(h1/h2)``) and against the mean
node spacing ``N^(-1/3)`` (the surfaces hold more nodes than ``h`` alone gives, and the
icosphere levels change in steps), the same from the first row to the last, the
discretisation and solve times.

The surfaces are polyhedral: the body is the icosphere shell, not the sphere, so the error
measured against the smooth solution would stop falling if the facets stayed fixed while
``h`` shrinks; by default they shrink with ``h`` (every surface vertex is a node).

How to run
----------
::

    python benchmarks/hollow_sphere.py                      # h = 0.27 0.135 0.0675 (~2 min)
    python benchmarks/hollow_sphere.py --h 0.3 0.2 --subdivisions 3
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import cnem  # noqa: E402
from cnem.exact import ThickSphere  # noqa: E402

INNER, OUTER, E, NU, P = 0.5, 1.0, 1.0, 0.3, 1.0


def conditions(prob, model, exact):
    """Exact displacement on the outer surface's nodes, the pressure on the cavity's facets
    (told apart by the mid radius: the facets' points lie inside the sphere by their
    sagitta)."""
    r = lambda x: np.linalg.norm(x, axis=1)                       # noqa: E731
    middle = 0.5 * (INNER + OUTER)
    outer = np.zeros(len(model.nodes), dtype=bool)
    outer[model.boundary_nodes(lambda x: r(x) > middle)] = True
    for k in range(3):
        prob.add_dirichlet(outer, k, lambda x, k=k: exact.displacement(x)[:, k])
    prob.add_traction(lambda x, n: r(x) < middle, lambda x, n: -P * n)


def one(h, subdivisions, seed=0):
    dom = cnem.geometry.hollow_sphere(INNER, OUTER, subdivisions=subdivisions)
    exact = ThickSphere(INNER, OUTER, E, NU, pressure=P)
    t0 = time.perf_counter()
    model = cnem.discretize(cnem.nodes.irregular(dom, h, seed=seed))
    t1 = time.perf_counter()
    row = dict(h=h, levels=subdivisions, nodes=len(model.nodes), discretize=t1 - t0)
    # the exact energy norm: 2 U = the pressure's work p u_r(a) 4 pi a^2 (no work on the
    # outer surface, where the traction vanishes)
    norm = np.sqrt(P * exact.radial_displacement(np.array([INNER]))[0] * 4 * np.pi * INNER ** 2)
    for name, prob in (("cnem", cnem.Elasticity(model, (E, NU))),
                       ("p1", cnem.fem.P1Elasticity.from_model(model, (E, NU)))):
        conditions(prob, model, exact)
        t = time.perf_counter()
        sol = prob.solve()
        row[name + "_time"] = time.perf_counter() - t
        row[name] = sol.energy_error(exact.stress) / norm
    return row


def _rate(rows, i, key, against):
    """``log(e_{i-1} / e_i) / log(a_{i-1} / a_i)`` for the spacing measure ``against``."""
    a0, a1 = against(rows[i - 1]), against(rows[i])
    return np.log(rows[i - 1][key] / rows[i][key]) / np.log(a0 / a1)


def _nominal(row):
    return row["h"]


def _effective(row):
    """The mean node spacing ``N^(-1/3)`` (up to the body's volume, which cancels)."""
    return row["nodes"] ** (-1.0 / 3.0)


def table(rows):
    lines = [f"{'h':>6} {'nodes':>7} {'discretize s':>12} | {'C-NEM error':>11} {'rate':>5} "
             f"{'rateN':>5} {'solve s':>8} | {'P1 error':>9} {'rate':>5} {'rateN':>5} "
             f"{'solve s':>8} | {'P1/C-NEM':>8}"]
    for i, r in enumerate(rows):
        fmt = {k: (f"{_rate(rows, i, k, _nominal):5.2f} {_rate(rows, i, k, _effective):5.2f}"
                   if i else f"{'-':>5} {'-':>5}") for k in ("cnem", "p1")}
        lines.append(f"{r['h']:6.3f} {r['nodes']:7d} {r['discretize']:12.1f} | {r['cnem']:11.3e} "
                     f"{fmt['cnem']} {r['cnem_time']:8.1f} | {r['p1']:9.3e} {fmt['p1']} "
                     f"{r['p1_time']:8.1f} | {r['p1'] / r['cnem']:8.2f}")
    if len(rows) > 2:
        whole = {k: (_rate([rows[0], rows[-1]], 1, k, _nominal),
                     _rate([rows[0], rows[-1]], 1, k, _effective)) for k in ("cnem", "p1")}
        lines.append(f"first to last row: C-NEM rate {whole['cnem'][0]:.2f} (h), "
                     f"{whole['cnem'][1]:.2f} (N^-1/3); P1 {whole['p1'][0]:.2f}, "
                     f"{whole['p1'][1]:.2f}")
    lines.append("errors: energy_error against Lamé over the exact energy norm; rate against the "
                 "nominal h, rateN against the mean spacing N^(-1/3)")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--h", type=float, nargs="+", default=[0.27, 0.135, 0.0675],
                        help="node spacings (default: %(default)s)")
    parser.add_argument("--subdivisions", type=int, default=None,
                        help="icosphere levels of the two surfaces (default: per h, the fewest "
                             "whose edges on the cavity are at most h)")
    args = parser.parse_args(argv)
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores", flush=True)
    rows = []
    for h in args.h:
        levels = args.subdivisions
        if levels is None:              # an icosphere's edge is about 1.05 radius / 2^levels
            levels = max(1, int(np.ceil(np.log2(1.05 * INNER / h))))
        rows.append(one(h, levels))
        print(table(rows).splitlines()[-2], flush=True)
    print(table(rows))
    return rows


if __name__ == "__main__":
    main()
