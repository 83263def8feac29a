"""Memory-bandwidth bound of the peridynamic step: streaming kernels over its bond arrays.

The bond-based force loop (``cnem.pd._pmb_kernels.pmb_forces``) reads, per bond, the
length, the partner index, the stiffness and the alive flag, once per step (21 bytes;
the reference bond vector comes from the points); the per-point arrays (points,
displacements, volumes, forces) are about 10x smaller and are read from the caches, as
the bonds of one point reach only nearby points. Two kernels measure how fast this machine
streams such arrays:

* ``read``: one pass over the step's own bond arrays (or synthetic ones of the same
  sizes and dtypes), summing them -- the bytes the force loop cannot avoid reading; its
  rate over the bytes per bond bounds the bond updates per second;
* ``triad``: STREAM's ``a = b + s c`` over three float64 arrays of the same total size,
  at most ``TRIAD_MAX_BYTES`` (far beyond the caches; 24 bytes per element counted, as
  STREAM does; the write-allocate read is not).

Each is timed after one warm-up call, the median over ``repeat`` calls, at each thread
count (``numba.set_num_threads``) or, with `concurrent_read`, in several single-threaded
processes at once (as MPI ranks on one machine run).
"""

import multiprocessing as mp
import os
import time

import numpy as np

from _harness import median

STREAM_REPEAT = 5
TRIAD_MAX_BYTES = 2 ** 29
WORKER_TIMEOUT = 600.0                  # s, a streaming process that never reports


def _kernels():
    import numba

    @numba.njit(parallel=True, fastmath=True, cache=False)
    def read(length, bond_j, stiffness, alive):
        total = 0.0
        for b in numba.prange(length.shape[0]):
            total += length[b] + stiffness[b] + bond_j[b] + alive[b]
        return total

    @numba.njit(parallel=True, fastmath=True, cache=False)
    def triad(a, b, c, s):
        for i in numba.prange(a.shape[0]):
            a[i] = b[i] + s * c[i]

    return read, triad


def bond_arrays(bonds, index_dtype=np.int32):
    """Synthetic arrays of the force loop's sizes and dtypes:
    ``(length, bond_j, stiffness, alive)``."""
    return (np.ones(bonds), np.arange(bonds, dtype=index_dtype), np.full(bonds, 2.0),
            np.ones(bonds, dtype=np.uint8))


def nbytes(arrays):
    return sum(a.nbytes for a in arrays)


def _timed(fn, repeat):
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return median(times)


def measure(arrays, threads, repeat=STREAM_REPEAT):
    """Read and triad bandwidth at each thread count.

    Parameters
    ----------
    arrays : tuple of ndarray
        ``(length, bond_j, stiffness, alive)`` of the force loop.
    threads : sequence of int

    Returns
    -------
    dict
        ``{t: {"read": GB/s, "triad": GB/s}}`` (GB = 1e9 bytes), plus ``"bytes"``: the
        bytes the read kernel streams.
    """
    import numba
    read, triad = _kernels()
    total = nbytes(arrays)
    m = max(1, min(total, TRIAD_MAX_BYTES) // 24)
    a, b, c = np.zeros(m), np.ones(m), np.full(m, 2.0)
    out = {"bytes": total}
    for t in threads:
        numba.set_num_threads(t)
        tr = _timed(lambda: read(*arrays), repeat)
        tt = _timed(lambda: triad(a, b, c, 3.0), repeat)
        out[t] = {"read": total / tr / 1e9, "triad": 24 * m / tt / 1e9}
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return out


def _read_worker(bonds, repeat, barrier, queue):
    read, _ = _kernels()
    arrays = bond_arrays(bonds)
    read(*arrays)                       # compiled and pages touched before the others wait
    barrier.wait()
    queue.put(nbytes(arrays) / _timed(lambda: read(*arrays), repeat) / 1e9)


def concurrent_read(bonds, procs, repeat=STREAM_REPEAT):
    """Aggregate read bandwidth (GB/s) of ``procs`` single-threaded processes that each
    stream ``bonds / procs`` synthetic bonds at the same time (started together at a
    barrier after their warm-up; the sum of each process's own rate)."""
    ctx = mp.get_context("spawn")
    barrier, queue = ctx.Barrier(procs), ctx.Queue()
    saved = {k: os.environ.get(k) for k in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS")}
    os.environ.update(NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1")
    try:
        workers = [ctx.Process(target=_read_worker,
                               args=(bonds // procs, repeat, barrier, queue))
                   for _ in range(procs)]
        for w in workers:
            w.start()
        rates = [queue.get(timeout=WORKER_TIMEOUT) for _ in workers]
        for w in workers:
            w.join()
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    return sum(rates)
