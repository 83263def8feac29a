"""The explicit time stepper (`cnem.solvers.stepping`): velocity Verlet against the exact
motion of a harmonic oscillator and of a fixed-fixed spring chain (second order in dt,
bounded energy error without drift), the prescribed dofs, and when the hooks run."""

from __future__ import annotations

import numpy as np
import pytest

from cnem.errors import CNEMError
from cnem.solvers import Prescribed, velocity_verlet


def oscillator_error(dt, omega=3.0, t_end=2.0):
    """|x - cos(omega t)| and |v + omega sin(omega t)| at ``t_end`` of ``x'' = -omega^2 x``."""
    steps = round(t_end / dt)
    u, v = np.array([1.0]), np.array([0.0])
    velocity_verlet(u, v, t_end / steps, steps, forces=lambda u: -omega ** 2 * u, mass=1.0,
                    progress=False)
    return abs(u[0] - np.cos(omega * t_end)), abs(v[0] + omega * np.sin(omega * t_end))


def test_the_oscillator_converges_at_second_order():
    dts = 0.02 / 2.0 ** np.arange(5)
    errors = np.array([oscillator_error(dt) for dt in dts])
    for column in errors.T:
        slope = np.polyfit(np.log(dts), np.log(column), 1)[0]
        assert 1.9 < slope < 2.1


def chain(n=9, k=4.0, m=0.5):
    """Stiffness of ``n`` free masses ``m`` between fixed walls (springs ``k``), its
    eigenpairs and an initial displacement of the two lowest modes."""
    K = k * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    w2, modes = np.linalg.eigh(K / m)
    u0 = modes[:, 0] + 0.3 * modes[:, 1]
    return K, m, np.sqrt(w2), modes, u0


def run_chain(dt, steps, walls=False):
    """The chain by the stepper; with ``walls`` the fixed ends are two extra dofs held at
    zero by `Prescribed`. Returns the final u, v and the energies at the frames."""
    K, m, omega, modes, u0 = chain()
    n = len(u0)
    if walls:
        Kw = np.zeros((n + 2, n + 2))
        Kw[1:-1, 1:-1] = K
        Kw[0, 1] = Kw[1, 0] = Kw[-1, -2] = Kw[-2, -1] = -K[0, 1]
        Kw[0, 0] = Kw[-1, -1] = -K[0, 1]
        K = Kw
        u0 = np.concatenate([[0.0], u0, [0.0]])
    u, v = u0.copy(), np.zeros_like(u0)
    energy = []

    def record(step, u, v):
        energy.append(0.5 * m * v @ v + 0.5 * u @ K @ u)

    velocity_verlet(u, v, dt, steps, forces=lambda u: -K @ u, mass=m, frame=record, every=1,
                    prescribed=Prescribed([0, len(u) - 1], [0.0, 0.0]) if walls else None,
                    progress=False)
    return (u[1:-1], v[1:-1], np.array(energy)) if walls else (u, v, np.array(energy))


def chain_exact(t):
    K, m, omega, modes, u0 = chain()
    a = modes.T @ u0
    return modes @ (a * np.cos(omega * t)), modes @ (-a * omega * np.sin(omega * t))


@pytest.mark.parametrize("walls", [False, True])
def test_the_spring_chain_follows_its_modes_at_second_order(walls):
    t_end, errors = 3.0, []
    dts = np.array([0.02, 0.01, 0.005])
    for dt in dts:
        u, v, _ = run_chain(dt, round(t_end / dt), walls)
        exact_u, exact_v = chain_exact(t_end)
        errors.append(np.abs(u - exact_u).max())
    slope = np.polyfit(np.log(dts), np.log(errors), 1)[0]
    assert 1.9 < slope < 2.1


def test_the_chain_energy_error_is_bounded_and_does_not_drift():
    omega_max = chain()[2].max()
    errors = []
    for dt in (0.1 / omega_max, 0.05 / omega_max):
        energy = run_chain(dt, round(2000 / (dt * omega_max)))[2]
        relative = np.abs(energy / energy[0] - 1)
        errors.append(relative.max())
        half = len(relative) // 2                      # the second half no worse than the first
        assert relative[half:].max() < 1.01 * relative[:half].max()
        assert relative.max() < 0.02 * (dt * omega_max) ** 2
    assert 3.8 < errors[0] / errors[1] < 4.2           # the bound shrinks as dt^2


def test_the_hooks_run_when_they_should():
    calls = {"forces": 0, "after": [], "frames": []}

    def forces(u):
        calls["forces"] += 1
        return -u

    velocity_verlet(np.ones(3), np.zeros(3), 0.1, 23, forces=forces, mass=2.0, every=5,
                    after_step=lambda step, u, v: calls["after"].append(step),
                    frame=lambda step, u, v: calls["frames"].append(step), progress=False)
    assert calls["forces"] == 24                       # once at the start, once per step
    assert calls["after"] == list(range(1, 24))
    assert calls["frames"] == [0, 5, 10, 15, 20, 23]


def test_a_resumed_run_equals_one_run():
    u, v = np.array([1.0, -0.5]), np.array([0.2, 0.0])
    whole_u, whole_v = u.copy(), v.copy()
    velocity_verlet(whole_u, whole_v, 0.01, 40, forces=lambda u: -u, progress=False)
    frames = []
    velocity_verlet(u, v, 0.01, 25, forces=lambda u: -u, progress=False)
    velocity_verlet(u, v, 0.01, 40, forces=lambda u: -u, start=25, every=10, progress=False,
                    frame=lambda step, u, v: frames.append(step))
    assert np.array_equal(u, whole_u) and np.array_equal(v, whole_v)
    assert frames == [25, 30, 40]


def test_default_frames_are_a_tenth_of_the_run():
    frames = []
    velocity_verlet(np.ones(1), np.zeros(1), 0.1, 35, forces=lambda u: -u, progress=False,
                    frame=lambda step, u, v: frames.append(step))
    assert frames == [0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 33, 35]


def test_mass_one_equals_forces_as_accelerations():
    runs = []
    for mass in (None, 1.0):
        u, v = np.array([[1.0, 0.3], [0.0, -0.2]]), np.zeros((2, 2))
        velocity_verlet(u, v, 0.05, 30, forces=lambda u: -4.0 * u, mass=mass, progress=False)
        runs.append((u, v))
    assert np.array_equal(runs[0][0], runs[1][0]) and np.array_equal(runs[0][1], runs[1][1])


def test_prescribed_dofs_hold_their_values_and_speeds():
    """Dof 0 fixed at 0.25, dof 3 moving at -2 (also listed as fixed: the speed wins),
    all under a force that would move them."""
    rule = Prescribed(fixed=[0, 3], values=[0.25, 9.0], moving=[3], speeds=[-2.0])
    u, v = np.zeros((2, 2)), np.full((2, 2), 7.0)
    rule.start(u, v)
    assert u.tolist() == [[0.25, 0.0], [0.0, 0.0]] and v.tolist() == [[0.0, 7.0], [7.0, -2.0]]
    dt, steps = 0.01, 50
    velocity_verlet(u, v, dt, steps, forces=lambda u: np.ones_like(u), mass=1.0,
                    prescribed=rule, progress=False)
    assert u[0, 0] == 0.25 and v[0, 0] == 0.0
    assert u[1, 1] == -2.0 * (steps * dt) and v[1, 1] == -2.0
    t = steps * dt                                     # a free dof: 7 t + t^2 / 2 (exact)
    assert u[0, 1] == pytest.approx(7.0 * t + 0.5 * t * t, rel=1e-12)


def test_progress_bar_only_when_asked(capsys):
    for progress, shown in ((False, False), (None, False), (True, True)):  # None: not a tty
        velocity_verlet(np.ones(1), np.zeros(1), 0.1, 5, forces=lambda u: -u,
                        progress=progress, desc="test steps")
        assert ("test steps" in capsys.readouterr().err) == shown


@pytest.mark.parametrize("bad", [dict(dt=0.0), dict(steps=3, start=5), dict(every=0),
                                 dict(v=np.zeros(3)), dict(u=np.zeros((4, 2))[:, 0])])
def test_wrong_arguments_are_refused(bad):
    args = dict(u=np.zeros(4), v=np.zeros(4), dt=0.1, steps=10)
    args.update(bad)
    with pytest.raises(CNEMError, match="expected"):
        velocity_verlet(args.pop("u"), args.pop("v"), args.pop("dt"), args.pop("steps"),
                        forces=lambda u: -u, progress=False, **args)


def test_prescribed_needs_a_value_per_dof():
    with pytest.raises(CNEMError, match="as many values as fixed dofs"):
        Prescribed(fixed=[0, 1], values=[0.0])
