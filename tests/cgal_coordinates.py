"""CGAL's natural-neighbour coordinates: an independent reference for cnem's
(``tests/test_cgal_reference.py``) and the compiled anchor of the benchmarks. Two drivers:
``cgal_sibson.cpp`` (2-D Sibson, ``benchmarks/shape_functions.py``) and ``cgal_laplace3.cpp``
(3-D Laplace, ``benchmarks/laplace_3d.py``). `build` compiles one, `run` runs it.

CGAL is a test- and benchmark-time tool only, never a dependency of cnem: where g++ or CGAL's
headers (Debian: ``apt-get install libcgal-dev``) are missing, `build` says why, the test
skips and the benchmark leaves out the CGAL column.  The executable is compiled once per source / compiler / flags into a
cache folder (``$XDG_CACHE_HOME/cnem-benchmarks`` or ``~/.cache/cnem-benchmarks``) and
reused; nothing is written into the repository.
"""
import hashlib
import os
import shutil
import subprocess
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SIBSON_2D = os.path.join(HERE, "cgal_sibson.cpp")
LAPLACE_3D = os.path.join(HERE, "cgal_laplace3.cpp")
SHARED = os.path.join(HERE, "cgal_driver.h")          # included by both drivers
FLAGS = ["-O3", "-march=native", "-DNDEBUG", "-DCGAL_NDEBUG", "-std=c++17"]
LIBS = ["-lgmp", "-lmpfr"]
INSTALL_HINT = "apt-get install libcgal-dev"


def cache_dir():
    """The folder the driver is compiled into (created on demand)."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "cnem-benchmarks")


def build(cxx=None, source=SIBSON_2D):
    """Compile a driver (or reuse the cached build).

    Parameters
    ----------
    cxx : str, optional
        The compiler (default ``$CXX`` or g++).
    source : str
        `SIBSON_2D` or `LAPLACE_3D`.

    Returns
    -------
    dict
        ``exe`` (path), ``compile_s`` (0.0 when cached), ``cgal`` (CGAL's version string) on
        success; ``skipped`` (why, with the fix) when g++ or CGAL's headers are missing.
    """
    cxx = cxx or os.environ.get("CXX") or "g++"
    if shutil.which(cxx) is None:
        return dict(skipped=f"no C++ compiler ({cxx!r} not on PATH): CGAL column skipped")
    version = subprocess.run([cxx, "--version"], capture_output=True, text=True).stdout
    text = b"".join(open(path, "rb").read() for path in (source, SHARED))
    key = hashlib.sha256(text + " ".join(FLAGS + LIBS + [version]).encode()).hexdigest()
    name = os.path.splitext(os.path.basename(source))[0]
    exe = os.path.join(cache_dir(), f"{name}_{key[:16]}")
    cgal = cgal_version(cxx)
    if cgal is None:
        return dict(skipped=f"CGAL headers not found by {cxx} ({INSTALL_HINT}): "
                            "CGAL column skipped")
    if os.path.exists(exe):
        return dict(exe=exe, compile_s=0.0, cgal=cgal)
    os.makedirs(cache_dir(), exist_ok=True)
    tmp = f"{exe}.tmp{os.getpid()}"
    t0 = time.perf_counter()
    done = subprocess.run([cxx, *FLAGS, source, "-o", tmp, *LIBS], capture_output=True,
                          text=True)
    if done.returncode != 0:
        return dict(skipped="compiling the CGAL driver failed: CGAL column skipped\n"
                            + done.stderr[-2000:])
    os.replace(tmp, exe)
    return dict(exe=exe, compile_s=time.perf_counter() - t0, cgal=cgal)


def cgal_version(cxx):
    """``CGAL_VERSION_STR`` as the compiler sees it, or None when the headers are missing."""
    probe = '#include <CGAL/version.h>\nCGAL_VERSION_STR\n'
    done = subprocess.run([cxx, "-x", "c++", "-E", "-P", "-"], input=probe,
                          capture_output=True, text=True)
    if done.returncode != 0:
        return None
    return done.stdout.strip().splitlines()[-1].strip().strip('"')


def run(exe, nodes, points, repeat, tmp):
    """Run a driver on ``nodes`` (n, d) and ``points`` (q, d) in a fresh process (d = 2
    for `SIBSON_2D`, 3 for `LAPLACE_3D`).

    Returns
    -------
    dict
        ``build`` (Delaunay seconds), ``runs`` (wall seconds per timed run: Hilbert sort +
        coordinates + CSR), ``cpu_runs`` (the runs' CPU seconds), ``outside`` (points the
        driver gave no coordinates: outside the hull, or in 3-D with an unbounded cell), ``rss``
        (peak bytes), ``phi`` (the last run's ``scipy.sparse.csr_matrix``, shape (q, n));
        ``error`` when the driver failed.
    """
    import scipy.sparse as sp

    nodes_bin, points_bin = os.path.join(tmp, "cgal_nodes.bin"), os.path.join(tmp, "cgal_q.bin")
    prefix = os.path.join(tmp, "cgal_phi")
    np.ascontiguousarray(nodes, dtype="<f8").tofile(nodes_bin)
    np.ascontiguousarray(points, dtype="<f8").tofile(points_bin)
    done = subprocess.run([exe, nodes_bin, points_bin, str(repeat), prefix],
                          capture_output=True, text=True)
    if done.returncode != 0:
        return dict(error=f"CGAL driver exit {done.returncode}: {done.stderr[-500:]}")
    out = {}
    for line in done.stdout.splitlines():
        key, *vals = line.split()
        out[key] = [float(v) for v in vals]
    phi = sp.csr_matrix((np.fromfile(prefix + ".data", dtype="<f8"),
                         np.fromfile(prefix + ".indices", dtype="<i4"),
                         np.fromfile(prefix + ".indptr", dtype="<i8")),
                        shape=(len(points), len(nodes)))
    for path in (nodes_bin, points_bin, prefix + ".data", prefix + ".indices",
                 prefix + ".indptr"):
        os.remove(path)
    return dict(build=out["build"][0], n_vertices=int(out["vertices"][0]), runs=out["runs"],
                cpu_runs=out["cpu_runs"],
                outside=int(out["outside"][0]), rss=out["peak_kb"][0] * 1024, phi=phi)
