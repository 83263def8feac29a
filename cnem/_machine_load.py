"""What else ran on the machine while something was measured: the load average, the
CPU time of other processes and the CPU steal between two looks (`MachineLoad`), read from
/proc on Linux ("not available" elsewhere). The benchmarks print it beside their timings
(``benchmarks/_harness.py``), since the machine they run on is often shared."""

import os
import time
import typing

__all__ = ["MachineLoad", "LoadSample", "take_load_sample", "load_average", "load_text",
           "cpu_times", "own_cpu_ticks"]


def load_average():
    """The load average (1, 5 and 15 min) as a tuple of 3 floats, None where the
    platform has none (Windows)."""
    try:
        return os.getloadavg()
    except (AttributeError, OSError):
        return None


def load_text(load=None):
    """A load average (1, 5 and 15 min; default: now) and the core count, as text to print.

    Parameters
    ----------
    load : tuple of 3 float or None
        A `load_average` result; None takes one now.
    """
    load = load or load_average()
    if load is None:
        return "not available"
    return " ".join(f"{x:.2f}" for x in load) + f" (1, 5, 15 min) on {os.cpu_count()} cores"


#: The fields of the aggregate ``cpu`` line of /proc/stat, in clock ticks (guest time is
#: already inside user and nice, so the two guest fields are left out).
CPU_FIELDS = ("user", "nice", "system", "idle", "iowait", "irq", "softirq", "steal")
#: The fields among `CPU_FIELDS` in which a CPU runs something (idle, iowait and steal
#: are time it does not).
CPU_BUSY = ("user", "nice", "system", "irq", "softirq")
#: Thresholds of `MachineLoad`'s verdict: 1-min load above this many per core, steal share.
BUSY_LOAD_PER_CORE = 0.5
BUSY_OTHERS_CORES = 0.25
BUSY_STEAL = 0.05


def cpu_times(stat_text):
    """The machine's CPU time so far: the ``cpu`` line of a /proc/stat text.

    Parameters
    ----------
    stat_text : str or None
        The content of /proc/stat.

    Returns
    -------
    dict or None
        Clock ticks summed over all CPUs for each of `CPU_FIELDS` (0 for a field an old
        kernel does not write); None when there is no text or no ``cpu`` line.
    """
    for line in (stat_text or "").splitlines():
        fields = line.split()
        if fields and fields[0] == "cpu":
            ticks = [int(x) for x in fields[1:1 + len(CPU_FIELDS)]]
            return dict(zip(CPU_FIELDS, ticks + [0] * (len(CPU_FIELDS) - len(ticks))))
    return None


def own_cpu_ticks(self_stat_text):
    """CPU time of a process and its finished children: utime + stime + cutime + cstime
    of a /proc/PID/stat text, in clock ticks (None without text).

    Children count once waited for (``subprocess.run``, ``Process.join``), with the
    children they waited for in turn; one still running at the end does not.
    """
    if not self_stat_text:
        return None
    # the command name (field 2) is in parentheses and may hold spaces and ')'
    rest = self_stat_text[self_stat_text.rindex(")") + 1:].split()
    return sum(int(rest[i]) for i in range(11, 15))   # fields 14-17: after ')' from 3 on


def _read(path):
    try:
        with open(path) as f:
            return f.read()
    except OSError:
        return None


class LoadSample(typing.NamedTuple):
    """One look at the machine (see `take_load_sample`); a field is None where unknown."""
    wall: float                 #: time.perf_counter(), s
    load: tuple                 #: load average (1, 5, 15 min)
    cpu: dict                   #: `cpu_times` of /proc/stat
    own: int                    #: `own_cpu_ticks` of /proc/self/stat


def take_load_sample(stat_path="/proc/stat", self_stat_path="/proc/self/stat"):
    """The load average, the machine's CPU times and this process tree's, now.

    Parameters
    ----------
    stat_path, self_stat_path : str
        Where to read the ``cpu`` line and this process's times (parameters for tests).

    Returns
    -------
    LoadSample
    """
    return LoadSample(wall=time.perf_counter(), load=load_average(),
                      cpu=cpu_times(_read(stat_path)), own=own_cpu_ticks(_read(self_stat_path)))


def _clock_ticks_per_s():
    try:
        return os.sysconf("SC_CLK_TCK")
    except (AttributeError, ValueError, OSError):
        return 100


class MachineLoad:
    """What else ran on the machine while a benchmark did: a look at its start (on
    construction) and one at `stop`.

    `report` gives, between the two looks:

    - the load average (1, 5, 15 min) before and after (it counts the benchmark's own
      threads too);
    - the CPU time of OTHER processes: all CPUs' busy time in /proc/stat (user + nice +
      system + irq + softirq) minus this process's and its finished children's
      (utime + stime + cutime + cstime of /proc/self/stat), also as cores busy on
      average; it counts the kernel's interrupt work and tick rounding (~1 tick per CPU);
    - the CPU steal: the share of all CPU time (the 8 fields of `CPU_FIELDS`) that the
      hypervisor gave to other virtual machines;
    - a verdict: "machine busy" when the 1-min load average before is above
      `BUSY_LOAD_PER_CORE` x cores, other processes kept more than `BUSY_OTHERS_CORES`
      cores busy on average during the run, or the steal was above `BUSY_STEAL` (5 %);
      "machine quiet" otherwise.  The load after is printed but not judged: it counts
      the benchmark's own threads, so a multi-threaded run of a minute would be "busy"
      by its own doing.

    Off Linux, what cannot be measured reads "not available".

    Parameters
    ----------
    sample : callable
        Returns a `LoadSample` (a parameter for tests).
    cores : int or None
        Default ``os.cpu_count()``.
    ticks_per_s : int or None
        Clock ticks per second of /proc (default ``SC_CLK_TCK``).

    Examples
    --------
    >>> machine = MachineLoad()
    >>> text = machine.stop().report()          # the benchmark runs in between
    >>> text.splitlines()[-1].split(":")[0].strip() in ("machine busy", "machine quiet",
    ...                                                 "verdict not available")
    True
    """

    def __init__(self, sample=take_load_sample, cores=None, ticks_per_s=None):
        self._sample = sample
        self.cores = cores or os.cpu_count() or 1
        self.ticks_per_s = ticks_per_s or _clock_ticks_per_s()
        self.before = sample()
        self.after = None

    def stop(self):
        """Take the second look (again on each call); returns self."""
        self.after = self._sample()
        return self

    def steal(self):
        """Steal share of all CPU time between the looks, or None."""
        b, a = self.before.cpu, self.after.cpu
        if b is None or a is None:
            return None
        total = sum(a.values()) - sum(b.values())
        return (a["steal"] - b["steal"]) / total if total > 0 else 0.0

    def others_cpu_s(self):
        """CPU seconds of other processes between the looks (>= 0), or None."""
        b, a = self.before, self.after
        if None in (b.cpu, a.cpu, b.own, a.own):
            return None
        busy = sum(a.cpu[k] - b.cpu[k] for k in CPU_BUSY)
        return max(0, busy - (a.own - b.own)) / self.ticks_per_s

    def busy_reasons(self):
        """Why the machine counts as busy (see the class docstring); [] if quiet."""
        limit = BUSY_LOAD_PER_CORE * self.cores
        load = self.before.load
        reasons = [f"1-min load before {load[0]:.2f} > {limit:.2f}"] \
            if load is not None and load[0] > limit else []
        others = self.others_cpu_s()
        if others is not None:
            cores = others / max(self.after.wall - self.before.wall, 1e-9)
            if cores > BUSY_OTHERS_CORES:
                reasons.append(f"other processes {cores:.2f} cores > {BUSY_OTHERS_CORES}")
        steal = self.steal()
        if steal is not None and steal > BUSY_STEAL:
            reasons.append(f"steal {steal:.1%} > {BUSY_STEAL:.0%}")
        return reasons

    def verdict(self):
        """One line: machine busy (and why) or quiet (and the rule)."""
        if self.before.load is None and self.steal() is None:
            return "verdict not available"
        reasons = self.busy_reasons()
        if reasons:
            return "machine busy: " + ", ".join(reasons)
        return (f"machine quiet: 1-min load before <= {BUSY_LOAD_PER_CORE} x {self.cores} "
                f"cores, other processes <= {BUSY_OTHERS_CORES} cores, steal <= "
                f"{BUSY_STEAL:.0%}")

    def short(self):
        """One line for a table row or a size: 1-min load before -> after, the other
        processes as cores busy on average, the steal."""
        steal, others = self.steal(), self.others_cpu_s()
        wall = max(self.after.wall - self.before.wall, 1e-9)
        loads = (self.before.load, self.after.load)
        load = "not available" if None in loads else f"{loads[0][0]:.2f} -> {loads[1][0]:.2f}"
        return (f"load {load}, others "
                + ("not available" if others is None else f"{others / wall:.2f} cores")
                + ", steal " + ("not available" if steal is None else f"{steal:.1%}"))

    def report(self):
        """The lines described in the class docstring, as one text."""
        steal, others = self.steal(), self.others_cpu_s()
        wall = self.after.wall - self.before.wall
        lines = [f"machine load over {wall:.1f} s (cnem._machine_load.MachineLoad):",
                 f"  load average before {load_text(self.before.load)}",
                 f"  load average after  {load_text(self.after.load)}",
                 "  other processes' CPU time (all CPUs' busy time in /proc/stat minus this "
                 "process's and its children's): "
                 + ("not available" if others is None else
                    f"{others:.1f} CPU s = {others / max(wall, 1e-9):.2f} cores on average"),
                 "  CPU steal: " + ("not available" if steal is None else
                                    f"{steal:.1%} of all CPU time"),
                 f"  {self.verdict()}"]
        return "\n".join(lines)
