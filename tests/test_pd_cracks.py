"""Cracks read off a damage image (`cnem.pd.cracks`): drawn cracks of known tip, branching
point, half-angle and speed are measured back; `cnem.exact.rayleigh_speed`."""

import numpy as np
import pytest

from cnem.errors import GeometryError, InputError
from cnem.exact import rayleigh_speed
from cnem.pd import cracks


def grid(h, nx, ny, origin):
    """The axes and the ``(nx, ny)`` coordinate images of a grid starting at ``origin``."""
    x = origin[0] + np.arange(nx) * h
    y = origin[1] + np.arange(ny) * h
    return np.meshgrid(x, y, indexing="ij")


def y_crack(X, Y, start, fork, end, half_angle, h):
    """A stem along y = start[1] from start[0] to fork, then two straight arms at
    +-half_angle (degrees) to end, each one grid point thick."""
    s = np.tan(np.radians(half_angle))
    dy = Y - start[1]
    stem = (X > start[0]) & (X <= fork) & (np.abs(dy) < h)
    arms = (X > fork) & (X < end) & (np.abs(np.abs(dy) - s * (X - fork)) < h)
    return stem | arms


@pytest.mark.parametrize("h, origin, half_angle", [
    (0.25e-3, (0.125e-3, -0.019875), 20.0),      # the branching demo's plate
    (0.1, (-3.0, 5.0), 30.0),                     # another origin and scale
    (1.0, (0.0, 0.0), 12.0),
])
def test_branching_of_a_drawn_y_crack(h, origin, half_angle):
    nx, ny = 400, 160
    X, Y = grid(h, nx, ny, origin)
    start = (origin[0] + 200.0 * h, origin[1] + 79.5 * h)      # between two rows
    fork = start[0] + 40 * h
    horizon = 4 * h
    drawn = y_crack(X, Y, start, fork, fork + 80 * h, half_angle, h)
    found = cracks.branching(drawn, origin, h, start[0], persistence=2 * horizon,
                             window=20 * h)
    assert abs(found["x"] - fork) < h and abs(found["y"] - start[1]) < h
    assert abs(found["half_angle"] - half_angle) < 0.5
    stem = drawn & (X <= fork)
    assert cracks.branching(stem, origin, h, start[0], persistence=2 * horizon,
                            window=20 * h) is None


def test_region_tip_and_bands_of_a_drawn_crack():
    """Only the damaged set touching the start is the crack; its tip is its right-most
    point; a straight crack has one band per column on its line, two after a fork."""
    h, origin = 0.5, (0.25, -9.75)
    X, Y = grid(h, 80, 40, origin)
    start = (10.0, 0.0)
    image = np.zeros(X.shape)
    crack = (X > start[0]) & (X < 25.0) & (np.abs(Y) < h)       # rows y = +-0.25
    image[crack] = 0.8
    image[(X > 30) & (X < 35) & (np.abs(Y - 5) < h)] = 0.9       # a separate damaged patch
    image[crack & (X < 12)] = 0.2                                 # below the threshold
    mask = cracks.crack_region(image, origin, h, (12.0, 0.0), 1.0, threshold=0.35)
    assert (mask == (crack & (X >= 12))).all()
    assert cracks.crack_tip(mask, origin, h, start[0]) == X[crack].max()
    assert cracks.crack_tip(np.zeros_like(mask), origin, h, start[0]) == start[0]
    xs, centres = cracks.bands(mask, origin, h, start[0])
    assert xs[0] == X[X >= start[0]].min()
    for x, c in zip(xs, centres):
        assert len(c) == (1 if 12 <= x < 25 else 0)
        if len(c):
            assert abs(c[0]) < 1e-12                               # centred on the line
    # nothing near the start: no crack, even if damage elsewhere
    assert not cracks.crack_region(image, origin, h, (2.0, -8.0), 1.0).any()


def test_tip_times_and_speeds_of_a_known_motion():
    """A tip at rest until t0, then at speed v: the passage times and the fitted speeds
    are those of the motion."""
    t = np.linspace(0.0, 10.0, 101)
    t0, v, x0 = 2.0, 3.0, 1.0
    tip = x0 + v * np.clip(t - t0, 0.0, None)
    assert cracks.first_passage(t, tip, x0) == 0.0
    assert abs(cracks.first_passage(t, tip, x0 + v * 1.234) - (t0 + 1.234)) < 1e-12
    assert np.isnan(cracks.first_passage(t, tip, tip[-1] + 1.0))
    moving = t > t0 + 0.1
    assert abs(cracks.mean_speed(t[moving], tip[moving]) - v) < 1e-9
    assert np.isnan(cracks.mean_speed(t[:2], tip[:2]))
    speeds = cracks.local_speeds(t, tip, 1.0, where=moving)
    np.testing.assert_allclose(speeds[moving], v, rtol=1e-9)
    assert np.isnan(speeds[~moving]).all()


def test_bad_images_are_named():
    with pytest.raises(GeometryError, match="expected a 2-D grid image"):
        cracks.crack_region(np.zeros(10), (0, 0), 1.0, (0, 0), 1.0)
    with pytest.raises(GeometryError, match="expected a positive grid spacing"):
        cracks.bands(np.zeros((4, 4), bool), (0, 0), -1.0, 0.0)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf"), [1.0, 2.0], 1j])
@pytest.mark.parametrize("measure", ["local_speeds window", "branching window",
                                     "branching persistence", "crack_region reach"])
def test_a_window_that_measures_nothing_is_named(measure, bad):
    """A window of zero fitted no sample and gave NaN speeds (or three columns of branches)
    without a word: a window, a persistence or a reach must be a positive length."""
    function, name = measure.split()
    t = np.arange(6.0)
    image = np.zeros((12, 9))
    image[4:10, 4] = 1.0
    calls = {"local_speeds": lambda v: cracks.local_speeds(t, 2.0 * t, v),
             "branching": lambda v: cracks.branching(
                 image > 0, (0.0, -4.0), 1.0, 4.0,
                 **{"persistence": 2.0, "window": 4.0, name: v}),
             "crack_region": lambda v: cracks.crack_region(image, (0.0, -4.0), 1.0,
                                                           (4.0, 0.0), v)}
    with pytest.raises(InputError, match=rf"^{name}: expected"):
        calls[function](bad)


def test_a_positive_window_still_measures():
    """The checks keep the measures: a tip moving at speed 2 has speed 2 in every window of
    three samples or more (a window of 4 holds three at the ends)."""
    t = np.arange(6.0)
    speeds = cracks.local_speeds(t, 2.0 * t, 4.0)
    np.testing.assert_allclose(speeds, 2.0)


@pytest.mark.parametrize("nu", [0.0, 0.25, 1 / 3, 0.45])
@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_rayleigh_speed_solves_the_rayleigh_equation(nu, plane):
    """The speed is below the shear speed, solves the Rayleigh equation, and matches
    Viktorov's approximation c_R / c_s = (0.862 + 1.14 nu') / (1 + nu') within 1.5 %
    (nu' the 3-D Poisson ratio of the plane law: nu / (1 + nu) in plane stress)."""
    E, density = 2.0e11, 7800.0
    c = rayleigh_speed(E, nu, density, plane)
    mu = E / (2 * (1 + nu))
    cs = np.sqrt(mu / density)
    nu3 = nu / (1 + nu) if plane == "stress" else nu
    lam3 = 2 * mu * nu3 / (1 - 2 * nu3)
    cd = np.sqrt((lam3 + 2 * mu) / density)
    k2, r2 = (c / cs) ** 2, (cs / cd) ** 2
    assert 0 < c < cs
    assert abs((2 - k2) ** 2 - 4 * np.sqrt(1 - k2 * r2) * np.sqrt(1 - k2)) < 1e-10
    assert abs(c / cs - (0.862 + 1.14 * nu3) / (1 + nu3)) < 1.5e-2   # its error at nu = 0: 1.2 %
