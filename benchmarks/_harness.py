"""Helpers shared by the benchmark scripts: peak memory, medians, size labels, warm-ups,
the machine's load."""

import os
import resource
import statistics
import sys
import time


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


def load_text():
    """The load average (1, 5 and 15 min) and the core count, as a line to print."""
    return (" ".join(f"{x:.2f}" for x in os.getloadavg())
            + f" (1, 5, 15 min) on {os.cpu_count()} cores")
