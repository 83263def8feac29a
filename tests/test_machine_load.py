"""The machine-load report the benchmarks print (`cnem._machine_load.MachineLoad`) on synthetic
/proc texts: the steal share, the other processes' CPU time and the busy verdict are
worked out by hand from the numbers written into the texts."""
from cnem import _machine_load as machine_load


def stat_text(user, nice, system, idle, iowait, irq, softirq, steal):
    """A /proc/stat with the aggregate line, a per-CPU line and other lines around it."""
    return (f"cpu  {user} {nice} {system} {idle} {iowait} {irq} {softirq} {steal} 7 3\n"
            "cpu0 1 2 3 4 5 6 7 8 0 0\n"
            "intr 12345 0 0\nctxt 999\nbtime 1700000000\n")


def self_stat_text(utime, stime, cutime, cstime):
    """A /proc/self/stat whose command name holds a space and a ')'."""
    return (f"4242 (py thon) x) S 1 4242 4242 0 -1 4194304 100 0 0 0 "
            f"{utime} {stime} {cutime} {cstime} 20 0 3 0 5000 1000000 2000\n")


def samples(*looks):
    """A sample function that returns the given LoadSamples one after the other."""
    it = iter(looks)
    return lambda: next(it)


BEFORE = machine_load.LoadSample(
    wall=10.0, load=(0.30, 0.20, 0.10),
    cpu=machine_load.cpu_times(stat_text(1000, 10, 200, 5000, 50, 5, 5, 30)),
    own=machine_load.own_cpu_ticks(self_stat_text(300, 40, 7, 3)))


def after(load, user, system, idle, steal, own):
    return machine_load.LoadSample(
        wall=20.0, load=load,
        cpu=machine_load.cpu_times(stat_text(user, 10, system, idle, 50, 5, 5, steal)),
        own=machine_load.own_cpu_ticks(self_stat_text(*own)))


def test_parsing_of_the_cpu_line_and_the_process_times():
    assert machine_load.cpu_times(stat_text(1, 2, 3, 4, 5, 6, 7, 8)) == dict(
        user=1, nice=2, system=3, idle=4, iowait=5, irq=6, softirq=7, steal=8)
    # an old kernel without the steal field
    assert machine_load.cpu_times("cpu  1 2 3 4\n")["steal"] == 0
    assert machine_load.cpu_times("intr 1 2\n") is None and machine_load.cpu_times(None) is None
    assert machine_load.own_cpu_ticks(self_stat_text(300, 40, 7, 3)) == 350
    assert machine_load.own_cpu_ticks(None) is None


def test_steal_and_other_processes_between_two_looks():
    # deltas: user +1500, system +300, idle +100, steal +100: 2000 ticks in all;
    # this process tree: +900 + 60 + 40 + 0 = 1000 of the 1800 busy ticks
    m = machine_load.MachineLoad(samples(BEFORE, after((0.4, 0.3, 0.2), 2500, 500, 5100, 130,
                                                   (1200, 100, 47, 3))),
                             cores=2, ticks_per_s=100)
    m.stop()
    assert m.steal() == 100 / 2000
    assert m.others_cpu_s() == (1800 - 1000) / 100
    # 8 CPU s of others over 10 s: 0.80 cores > 0.25; steal 5 % is not above 5 %
    assert m.busy_reasons() == ["other processes 0.80 cores > 0.25"]
    text = m.report()
    assert "8.0 CPU s = 0.80 cores on average" in text and "5.0% of all CPU time" in text


def test_busy_by_load_before_by_others_or_by_steal():
    # load before 1.5 > 0.5 x 2 cores; others: 1800 busy - 0 own ticks = 18 s over 10 s
    # = 1.80 cores; steal 200 of 1000 ticks = 20 % > 5 %
    busy_before = BEFORE._replace(load=(1.5, 0.3, 0.2))
    m = machine_load.MachineLoad(samples(busy_before, after((0.2, 0.3, 0.2), 2500, 500, 5200, 230,
                                                        (300, 40, 7, 3))),
                             cores=2, ticks_per_s=100).stop()
    assert m.steal() == 200 / 2200
    assert m.busy_reasons() == ["1-min load before 1.50 > 1.00",
                                "other processes 1.80 cores > 0.25", "steal 9.1% > 5%"]
    assert m.verdict().startswith("machine busy")
    # the same load on 4 cores is below the threshold 2.0; a high load after is not judged
    m4 = machine_load.MachineLoad(samples(busy_before, m.after._replace(load=(9.0, 9.0, 9.0))),
                              cores=4, ticks_per_s=100).stop()
    assert [r for r in m4.busy_reasons() if "load" in r] == []


def test_quiet_machine():
    # others: 1000 busy ticks - 1000 own = 0; no steal; load before 0.3 <= 1.0
    m = machine_load.MachineLoad(samples(BEFORE, after((1.9, 0.3, 0.2), 1800, 400, 5100, 30,
                                                   (1200, 100, 47, 3))),
                             cores=2, ticks_per_s=100).stop()
    assert m.others_cpu_s() == 0.0 and m.steal() == 0.0
    assert m.busy_reasons() == [] and m.verdict().startswith("machine quiet")


def test_own_time_above_the_machines_busy_time_is_clamped_to_zero():
    m = machine_load.MachineLoad(samples(BEFORE, after(None, 1010, 200, 5100, 30,
                                                   (400, 40, 7, 3))),
                             cores=2, ticks_per_s=100).stop()
    assert m.others_cpu_s() == 0.0


def test_without_proc_or_load_average_it_says_not_available(tmp_path, monkeypatch):
    def no_load_average():
        raise OSError("Load average is unobtainable")

    monkeypatch.setattr(machine_load.os, "getloadavg", no_load_average)
    missing = str(tmp_path / "missing")
    sample = machine_load.take_load_sample(stat_path=missing, self_stat_path=missing)
    assert sample.load is None and sample.cpu is None and sample.own is None
    m = machine_load.MachineLoad(lambda: sample, cores=2, ticks_per_s=100).stop()
    text = m.report()
    assert text.count("not available") == 5 and "verdict not available" in text
    assert m.short() == "load not available, others not available, steal not available"


def test_sample_reads_the_given_files(tmp_path):
    stat, own = tmp_path / "stat", tmp_path / "self_stat"
    stat.write_text(stat_text(1, 2, 3, 4, 5, 6, 7, 8))
    own.write_text(self_stat_text(10, 20, 30, 40))
    sample = machine_load.take_load_sample(stat_path=str(stat), self_stat_path=str(own))
    assert sample.cpu["steal"] == 8 and sample.own == 100
