"""Benchmark: the same problem at other origins and in other units (translation and scale invariance).

Workload
--------
A unit square with a circular hole (a 32-gon of radius 0.15 about (0.7, 0.3)) and a kinked
internal crack, an irregular cloud of spacing ``h`` (``--h``, default 0.03; ``--quick`` 0.06)
built once at the origin, then every point, vertex and length mapped by ``x -> s x + o`` for
the offsets ``o`` in (0, 1e6, 1e8) (both coordinates; 1e8 is UTM-like) and the scales ``s`` in
(1e-6, 1, 1e6), and a UTM-like body 100 m across at 5e6 (``o = 5e6, s = 100``), the cloud
rebuilt with ``cnem.nodes.from_points``. The elastic problem:
``E = 1, nu = 0.3``, plane strain, the bottom edge held vertically, its left corner also
horizontally, a unit traction pulling the top edge up (the traction does not scale, so the
displacements scale with ``s`` and K_I with ``sqrt(s)``).

What is compared (each against the case ``o = 0, s = 1``, mapped back by ``(x - o) / s``)
-------------------------------------------------------------
``cells``   max over cells of the distance between their vertex sets and of the area
            difference, relative to the domain's diameter (its square for areas); ``shape``  max entry difference of the
            Sibson matrices at 2000 random points inside the domain (the same relative points);
``family``  fraction of the reference bonds (horizon 3.1 h) missing or added;
``u``       max displacement difference / (s max |u_ref|); ``K_I``  |K_I / sqrt(s) - K_ref| / K_ref;
``time``    seconds of discretize + shape functions + families + solve + sif.
A case that raises prints the error's name instead of its numbers; ``inf``: a different
number of nodes or cells (so nothing to compare entry by entry).

3-D rows: Lamé's hollow sphere (radii ``0.5 s``, ``s`` about ``o``, E = 1, nu = 0.3, unit
internal pressure, the exact displacement held on the outer surface; 3-D C-NEM) on one
irregular cloud of spacing ``--h3`` (default 0.25) built at the origin and mapped, at the
origin, shifted by 1e6 (1e6, -2e6, 5e5), scaled by 1e-3 and by 1e3: ``energy``  the
energy-norm error over the exact energy norm; ``cavity``  the cavity's mean radial
displacement over the exact one; ``du``  max displacement difference to the origin case /
(s max |u_ref|).

Run ``python benchmarks/invariance.py`` (``--quick`` for the CI smoke size).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import cnem
from cnem.fracture import sif
from cnem.spatial import family_search

from _harness import MachineLoad, load_text

OFFSETS = (0.0, 1e6, 1e8)
SCALES = (1e-6, 1.0, 1e6)
UTM = (5e6, 100.0)                  # offset, scale: a body 100 m across in UTM metres
CRACK = np.array([[0.2, 0.62], [0.45, 0.7], [0.62, 0.66]])
SHELL = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
DIAMETER = np.sqrt(2.0)
_angles = np.linspace(0.0, 2 * np.pi, 32, endpoint=False)
HOLE = np.column_stack([0.7 + 0.15 * np.cos(_angles), 0.3 + 0.15 * np.sin(_angles)])


def _domain(s, o):
    return cnem.Domain([(SHELL * s + o, [HOLE * s + o])], cracks=[CRACK * s + o])


def _run(points, queries, h, s, o):
    """Everything measured on the problem mapped by ``x -> s x + o`` (results mapped back)."""
    t0 = time.perf_counter()
    dom = _domain(s, o)
    cloud = cnem.nodes.from_points(dom, points * s + o)
    model = cnem.discretize(cloud, progress=False)
    phi = model.shape_functions(queries * s + o)
    fam = family_search(cloud.points, 3.1 * h * s)
    prob = cnem.Elasticity(model, (1.0, 0.3), plane="strain")
    tol = 1e-9 * s + 8 * np.finfo(float).eps * abs(o)       # the coordinates' resolution
    bottom = lambda p: np.abs(p[:, 1] - o) <= tol                # noqa: E731
    prob.add_dirichlet(bottom, 1)
    prob.add_dirichlet(lambda p: bottom(p) & (np.abs(p[:, 0] - o) <= tol), 0)
    prob.add_traction(lambda x, n: (np.abs(x[:, 1] - (o + s)) <= tol) & (n[:, 1] > 0.5),
                      np.array([0.0, 1.0]))
    sol = prob.solve(progress=False)
    k1 = sif(sol, CRACK[-1] * s + o).KI
    seconds = time.perf_counter() - t0
    cells = model.cells
    return dict(offsets=cells.offsets, vertices=(cells.vertices - o) / s, area=cells.area / s ** 2,
                phi=phi, fam=fam, u=sol.u / s, K=k1 / np.sqrt(s), time=seconds)


def _vertex_distance(p, q):
    """Hausdorff distance between the vertex sets of two polygons (an extra vertex on an
    edge, or one where the polygon folds back, counts by its distance to the other's)."""
    d = np.hypot(*(p[:, None, :] - q[None, :, :]).transpose(2, 0, 1))
    return max(d.min(axis=0).max(), d.min(axis=1).max())


def _bond_keys(fam, n):
    rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(fam.offsets))
    return set((rows * n + np.asarray(fam.indices, dtype=np.int64)).tolist())


def _compare(got, ref, n):
    """Relative differences of one case against the reference (inf where they cannot be
    compared: another number of cells or nodes)."""
    out = {}
    go, ro = got["offsets"], ref["offsets"]
    if len(go) == len(ro):
        far = max(_vertex_distance(got["vertices"][go[c]:go[c + 1]],
                                   ref["vertices"][ro[c]:ro[c + 1]]) for c in range(len(ro) - 1))
        out["cells"] = max(far / DIAMETER, np.abs(got["area"] - ref["area"]).max() / DIAMETER ** 2)
    else:
        out["cells"] = np.inf
    same = got["phi"].shape == ref["phi"].shape
    out["shape"] = abs(got["phi"] - ref["phi"]).max() if same else np.inf
    if len(got["fam"].offsets) == len(ref["fam"].offsets):
        a, b = _bond_keys(got["fam"], n), _bond_keys(ref["fam"], n)
        out["family"] = len(a ^ b) / len(b)
    else:                                       # other nodes: no bond-by-bond comparison
        out["family"] = np.inf
    out["u"] = (np.abs(got["u"] - ref["u"]).max() / np.abs(ref["u"]).max()
                if got["u"].shape == ref["u"].shape else np.inf)
    out["K_I"] = abs(got["K"] - ref["K"]) / abs(ref["K"])
    out["time"] = got["time"]
    return out


SPHERE_CASES = ((0.0, 1.0), (1e6, 1.0), (0.0, 1e-3), (0.0, 1e3))    # offset, scale
SPHERE_SHIFT = np.array([1.0, -2.0, 0.5])


def _sphere_run(points, s, o):
    """The hollow sphere mapped by ``x -> s x + o SPHERE_SHIFT``: relative energy error,
    cavity displacement over the exact one, displacements over ``s``."""
    from cnem.exact import ThickSphere
    centre = o * SPHERE_SHIFT
    dom = cnem.geometry.hollow_sphere(0.5 * s, s, center=centre, subdivisions=2)
    model = cnem.discretize(cnem.nodes.from_points(dom, points * s + centre), progress=False)
    exact = ThickSphere(0.5 * s, s, 1.0, 0.3, pressure=1.0, center=centre)
    u_inner = exact.radial_displacement(np.array([0.5 * s]))[0]
    norm = np.sqrt(u_inner * 4 * np.pi * (0.5 * s) ** 2)
    r = np.linalg.norm(model.nodes - centre, axis=1)
    prob = cnem.Elasticity(model, (1.0, 0.3))
    prob.add_dirichlet(model.boundary_nodes(lambda x: np.linalg.norm(x - centre, axis=1) > 0.75 * s),
                       None, exact.displacement)
    prob.add_traction(lambda x, n: np.linalg.norm(x - centre, axis=1) < 0.75 * s, lambda x, n: -n)
    sol = prob.solve(progress=False)
    cavity = r < 0.5 * s * (1 + 1e-9)
    ur = np.einsum("ij,ij->i", sol.u[cavity], (model.nodes[cavity] - centre) / r[cavity, None])
    return dict(energy=sol.energy_error(exact.stress) / norm, cavity=ur.mean() / u_inner,
                u=sol.u / s)


def sphere_rows(h):
    """Print the 3-D rows (see the module's docstring)."""
    dom = cnem.geometry.hollow_sphere(0.5, 1.0, subdivisions=2)
    points = cnem.nodes.irregular(dom, h, seed=0).points
    print(f"\n3-D hollow sphere: {len(points)} points, h = {h}")
    print(f"{'offset':>8} {'scale':>8} {'energy':>12} {'cavity':>12} {'du':>9} {'time s':>8}")
    ref = None
    for o, s in SPHERE_CASES:
        t0 = time.perf_counter()
        try:
            got = _sphere_run(points, s, o)
        except cnem.CNEMError as exc:
            print(f"{o:8.0e} {s:8.0e} {type(exc).__name__}: {str(exc)[:90]}")
            continue
        ref = got if ref is None else ref
        du = (np.abs(got["u"] - ref["u"]).max() / np.abs(ref["u"]).max()
              if got["u"].shape == ref["u"].shape else np.inf)
        print(f"{o:8.0e} {s:8.0e} {got['energy']:12.10f} {got['cavity']:12.10f} {du:9.1e} "
              f"{time.perf_counter() - t0:8.2f}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h", type=float, default=0.03, help="node spacing at scale 1")
    parser.add_argument("--h3", type=float, default=0.25, help="3-D node spacing (sphere radius 1)")
    parser.add_argument("--quick", action="store_true", help="CI smoke size (h = 0.06)")
    args = parser.parse_args(argv)
    h = 0.06 if args.quick else args.h
    machine = MachineLoad()
    print(f"benchmarks/invariance.py: load average {load_text(machine.before.load)}")
    ref_dom = _domain(1.0, 0.0)
    points = cnem.nodes.irregular(ref_dom, h, seed=1).points
    rng = np.random.default_rng(7)
    queries = rng.random((4000, 2))
    queries = queries[ref_dom.contains(queries)][:2000]
    _run(points, queries[:10], h, 1.0, 0.0)                      # numba warm-up
    ref = _run(points, queries, h, 1.0, 0.0)
    print(f"invariance: {len(points)} points, h = {h}, {len(queries)} query points, "
          f"K_I = {ref['K']:.6f} at the origin")
    cols = ("cells", "shape", "family", "u", "K_I")
    print(f"{'offset':>8} {'scale':>8} " + " ".join(f"{c:>9}" for c in cols) + f" {'time s':>8}")
    for o, s in [(o, 1.0) for o in OFFSETS] + [(0.0, s) for s in SCALES if s != 1.0] + [UTM]:
        try:
            d = _compare(_run(points, queries, h, s, o), ref, len(points))
            row = " ".join(f"{d[c]:9.1e}" for c in cols) + f" {d['time']:8.2f}"
        except cnem.CNEMError as exc:
            row = f"{type(exc).__name__}: {str(exc)[:90]}"
        print(f"{o:8.0e} {s:8.0e} {row}")
    sphere_rows(args.h3)
    print("\n" + machine.stop().report())


if __name__ == "__main__":
    main()
