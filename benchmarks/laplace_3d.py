"""Benchmark: 3-D constrained Laplace coordinates against CGAL's, same nodes, same points.

Workload
--------
For each size n (default 10k and 100k nodes; ``--sizes``): one irregular cloud
``cnem.nodes.irregular(cnem.geometry.box(), h, seed=0)`` of the unit cube (``h`` for about
n nodes), its boundary-conforming tetrahedrisation (``conforming_tetrahedra``, what
``cnem.discretize`` does first; in a box it is the Delaunay tetrahedrisation of the nodes)
and ``q`` random points in the cube (``--queries``, default 200k).

* **cnem**: ``cnem.shape.natural3d.shape_functions_3d`` (what ``Model3D.shape_functions``
  calls) on the prepared mesh (``tet_mesh``, the faces of the box as constraints), with
  numba on 1 thread and on 2 (``numba.set_num_threads``), in one fresh child process;
  warmed up on 1000 points first.
* **CGAL** (the compiled anchor, when g++ and CGAL's headers are found: Debian
  ``apt-get install libcgal-dev``; a benchmark-time tool, never a dependency):
  ``laplace_natural_neighbor_coordinates_3`` on CGAL's Delaunay tetrahedrisation of the
  same nodes, single-threaded, the points Hilbert-sorted (counted) and each location
  started from the previous one's cell, the values gathered into a CSR matrix in the
  points' order (``tests/cgal_laplace3.cpp``, built by ``tests/cgal_coordinates.py``, run
  as its own process). Otherwise the column says why it was skipped.

What is measured
----------------
Points per second, the median of ``--repeat`` timed runs (wall clock), and per CPU second
(process CPU time: less sensitive to a busy machine) for cnem on 1 thread and CGAL;
``1T/CGAL`` is cnem's one-thread rate over CGAL's (wall, and CPU). The setup times
(cnem: tetrahedrisation + ``tet_mesh``; CGAL: its Delaunay build) are printed apart. The
values: max ``|cnem - CGAL|`` over the points CGAL answers (it declines a point whose
conflict zone reaches the hull: its Voronoi cell is unbounded), checked against 1e-12.

How to run
----------
::

    python benchmarks/laplace_3d.py                     # 10k and 100k nodes (~3 min)
    python benchmarks/laplace_3d.py --sizes 1000000     # needs ~6 GB
"""
import argparse
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "tests"))

from _harness import MachineLoad, fmt_n, in_child, load_text, median  # noqa: E402
import cgal_coordinates  # noqa: E402

VALUE_TOLERANCE = 1e-12


def cloud_of_size(n, seed=0):
    """An irregular cloud of the unit cube with about ``n`` nodes (one correction of ``h``
    from a first, coarser cloud)."""
    import cnem
    box = cnem.geometry.box()
    h = 0.1
    for _ in range(2):
        cloud = cnem.nodes.irregular(box, h, seed=seed)
        h *= (len(cloud.points) / n) ** (1.0 / 3.0)
    return cnem.nodes.irregular(box, h, seed=seed), h


def cnem_side(n, queries, repeat, nodes_file, phi_file):
    """In a child process: the cloud, the tetrahedrisation, ``tet_mesh``, then the rates
    on 1 and 2 threads; the nodes and the one-thread values are saved for CGAL."""
    import numba
    import scipy.sparse as sp
    from cnem.geometry.tetrahedra import conforming_tetrahedra
    from cnem.shape.natural3d import shape_functions_3d, tet_mesh

    cloud, h = cloud_of_size(n)
    t0 = time.perf_counter()
    tets = conforming_tetrahedra(cloud.points, cloud.boundary_faces,
                                 cloud.boundary_face_regions)
    mesh = tet_mesh(tets.points, tets.tetrahedra, tet_region=tets.tet_region,
                    constraint_faces=cloud.boundary_faces)
    setup = time.perf_counter() - t0
    points = np.random.default_rng(1).random((queries, 3))
    out = dict(nodes=len(tets.points), h=h, setup=setup)
    for threads in (1, 2):
        numba.set_num_threads(threads)
        shape_functions_3d(mesh, points[:1000])
        wall, cpu = [], []
        for _ in range(repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            phi = shape_functions_3d(mesh, points)
            wall.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        out[f"{threads}T"] = dict(wall=median(wall), cpu=median(cpu))
        if threads == 1:
            np.save(nodes_file, tets.points)
            sp.save_npz(phi_file, phi)
    return out


def cgal_side(exe, nodes_file, phi_file, points, repeat, tmp):
    """CGAL on the same nodes and points; its values against cnem's."""
    import scipy.sparse as sp
    out = cgal_coordinates.run(exe, np.load(nodes_file), points, repeat, tmp)
    if "error" in out:
        return out
    answered = np.diff(out["phi"].indptr) > 0
    ours = sp.load_npz(phi_file)
    diff = abs(ours[answered] - out["phi"][answered])
    return dict(build=out["build"], wall=median(out["runs"]), cpu=median(out["cpu_runs"]),
                declined=int(out["outside"]), max_diff=float(diff.max()) if diff.nnz else 0.0)


def table(rows, queries):
    lines = [f"{'n':>6} {'nodes':>8} | {'cnem 1T':>9} {'cnem 2T':>9} {'CGAL 1T':>9} "
             f"{'1T/CGAL':>7} | {'per CPU s: cnem 1T':>18} {'CGAL':>9} {'1T/CGAL':>7} | "
             f"{'setup s cnem':>12} {'CGAL':>6} | max |cnem-CGAL|"]
    for r in rows:
        if "error" in r["cnem"]:
            lines.append(f"{fmt_n(r['n']):>6}  cnem failed: {r['cnem']['error']}")
            continue
        c, g = r["cnem"], r["cgal"]
        rate = lambda s: queries / s                                     # noqa: E731
        head = (f"{fmt_n(r['n']):>6} {c['nodes']:>8} | {rate(c['1T']['wall']):>9.3g} "
                f"{rate(c['2T']['wall']):>9.3g} ")
        if "wall" not in g:
            lines.append(head + f"CGAL: {g.get('skipped') or g.get('error')}")
            continue
        good = "ok" if g["max_diff"] <= VALUE_TOLERANCE else f"> {VALUE_TOLERANCE:g}"
        lines.append(head + f"{rate(g['wall']):>9.3g} {g['wall'] / c['1T']['wall']:>7.2f} | "
                     f"{rate(c['1T']['cpu']):>18.3g} {rate(g['cpu']):>9.3g} "
                     f"{g['cpu'] / c['1T']['cpu']:>7.2f} | {c['setup']:>12.2f} "
                     f"{g['build']:>6.2f} | {g['max_diff']:.1e} ({good}; "
                     f"{g['declined']} points declined by CGAL)")
    lines.append(f"rates in points per second ({queries} random points in the cube); "
                 "1T/CGAL > 1: cnem on one thread is faster")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000],
                        metavar="N", help="node counts (default: %(default)s)")
    parser.add_argument("--queries", type=int, default=200_000,
                        help="random points per run (default: %(default)s)")
    parser.add_argument("--repeat", type=int, default=3, help="timed runs (median)")
    parser.add_argument("--no-cgal", action="store_true", help="leave out the CGAL column")
    args = parser.parse_args(argv)
    machine = MachineLoad()
    print(f"benchmarks/laplace_3d.py: load average {load_text(machine.before.load)}",
          flush=True)
    built = (dict(skipped="--no-cgal") if args.no_cgal
             else cgal_coordinates.build(source=cgal_coordinates.LAPLACE_3D))
    if "cgal" in built:
        print(f"CGAL {built['cgal']} (driver compiled in {built['compile_s']:.0f} s)")
    points = np.random.default_rng(1).random((args.queries, 3))
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.sizes:
            print(f"  n = {fmt_n(n)} ...", flush=True)
            nodes_file, phi_file = os.path.join(tmp, "nodes.npy"), os.path.join(tmp, "phi.npz")
            ours = in_child(cnem_side, n, args.queries, args.repeat, nodes_file, phi_file)
            theirs = (cgal_side(built["exe"], nodes_file, phi_file, points, args.repeat, tmp)
                      if "exe" in built and "error" not in ours else built)
            rows.append(dict(n=n, cnem=ours, cgal=theirs))
    print()
    print(table(rows, args.queries))
    print("\n" + machine.stop().report())
    return rows


if __name__ == "__main__":
    main()
