"""The one harness of the benchmark scripts: a measurement in a fresh child process
(`in_child`), the memory check before a size (`memory_skip`), the machine's load
(`MachineLoad`, from `cnem._machine_load`), the targets table (`print_targets`), and peak
memory, medians, size labels and warm-ups."""

import multiprocessing as mp
import resource
import statistics
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool

from cnem._machine_load import MachineLoad, load_text  # noqa: F401 - the harness's load report


def peak_rss_bytes():
    """High-water resident set size of this process.

    Linux: ``VmHWM`` (``ru_maxrss`` inherits the parent's peak across ``exec``, so a
    fresh child would report its parent's peak); ``ru_maxrss`` elsewhere.
    """
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return rss if sys.platform == "darwin" else rss * 1024


def reset_peak_rss():
    """Reset ``VmHWM`` to the current RSS (Linux >= 4.0); True if it worked."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def mem_available_bytes():
    """``MemAvailable`` from /proc/meminfo, or None."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def median(xs):
    """Median of a sequence, NaN when empty."""
    xs = list(xs)
    return statistics.median(xs) if xs else float("nan")


def warm_median(fn, repeat):
    """One warm-up call, then the median of ``repeat`` timed calls, and the last result."""
    out = fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return median(times), out


def warm_both(fn):
    """``fn()`` twice: as is, and with every `cnem._parallel.ParallelKernel` on its
    parallel copy, so that a tiny warm-up compiles (or loads) both copies of the kernels
    (below ``cnem.config.PARALLEL_MIN`` work items a kernel runs its serial copy, which
    the timed large problems do not use)."""
    from cnem._parallel import always_parallel
    fn()
    with always_parallel():
        return fn()


def fmt_n(n):
    """Short size label: 10000 -> '10k', 1000000 -> '1M'."""
    for div, suffix in ((1_000_000, "M"), (1_000, "k")):
        if n >= div and n % div == 0:
            return f"{n // div}{suffix}"
    if n >= 1000:
        return f"{n / 1000:.0f}k"
    return str(n)


def in_child(fn, *args):
    """``fn(*args)`` in a fresh spawned interpreter (its own peak memory, its own numba
    threads), and its result; a child that dies or raises becomes ``dict(error=...)`` so
    that the other measurements go on.

    Parameters
    ----------
    fn : callable
        A module-level function of the benchmark (spawned children import it by name).
    *args
        Its arguments (picklable).
    """
    try:
        with ProcessPoolExecutor(max_workers=1, mp_context=mp.get_context("spawn")) as ex:
            return ex.submit(fn, *args).result()
    except BrokenProcessPool:
        return dict(error="child process died (killed -- out of memory?)")
    except Exception as exc:          # noqa: BLE001 - report, keep the other measurements
        return dict(error=f"{type(exc).__name__}: {exc}")


def memory_limit(limit_gb=None):
    """The bytes a measurement may take: ``limit_gb`` (a ``--mem-limit-gb`` option) if
    given, else 80 % of ``MemAvailable`` now (infinite where unknown)."""
    if limit_gb is not None:
        return limit_gb * 2 ** 30
    avail = mem_available_bytes()
    return 0.8 * avail if avail else float("inf")


def memory_skip(need, limit=None, *, detail="", digits=".1f"):
    """None if an estimated need fits, else the reason to skip the measurement.

    Parameters
    ----------
    need : float
        Estimated peak bytes.
    limit : float or None
        Bytes allowed; None: `memory_limit` now.
    detail : str
        How the estimate was made, printed after it (" (... )").
    digits : str
        Format of the GB numbers.
    """
    limit = memory_limit() if limit is None else limit
    if need <= limit:
        return None
    return (f"needs ~{need / 2**30:{digits}} GB{detail} > limit {limit / 2**30:{digits}} GB")


def verdict(good):
    """A target's verdict: MET or MISSED."""
    return "MET" if good else "MISSED"


def print_targets(rows, title="targets (issue):"):
    """The targets table: one line per target, ``  label: measured -> MET/MISSED``.

    Parameters
    ----------
    rows : list of (str, str, bool or None)
        The target, what was measured, whether it is met (None: not evaluated, the
        measured text says why).
    title : str
    """
    print(title)
    for label, measured, good in rows:
        print(f"  {label}: {measured}" + ("" if good is None else f" -> {verdict(good)}"))

