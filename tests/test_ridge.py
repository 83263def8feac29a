"""The crack path through a damage field (`cnem.demos.damage.ridge.ridge_path`): a synthetic
damage band around a known polyline, in any direction, at any origin and scale, on
regular and perturbed clouds, is traced back to that polyline."""

import numpy as np
import pytest
import shapely

from cnem.errors import GeometryError
from cnem.demos.damage.ridge import ridge_bands, ridge_path

#: A kinked crack (+37 and -37 degrees) in units of the scale.
KINKED = np.array([[0.0, 0.0], [0.4, 0.0], [0.7, 0.25], [0.9, 0.1]])


def cloud(scale, angle, origin, h, perturb, seed=0):
    """A lattice of spacing ``h`` over [-0.2, 1.1]^2 (times ``scale``), optionally moved by
    up to ``perturb`` spacings, turned by ``angle`` degrees and moved to ``origin``;
    returns the points and the map applied to them."""
    g = np.arange(-0.2 * scale, 1.1 * scale, h)
    points = np.array([(x, y) for x in g for y in g])
    points += np.random.default_rng(seed).uniform(-perturb, perturb, points.shape) * h
    c, s = np.cos(np.radians(angle)), np.sin(np.radians(angle))
    rotation = np.array([[c, -s], [s, c]])

    def place(p):
        return np.asarray(p) @ rotation.T + origin
    return place(points), place


def band(points, polyline, half_width):
    """Damage falling linearly from 1 on the polyline to 0.5 at ``half_width``."""
    d = shapely.distance(shapely.points(points), shapely.LineString(polyline))
    return np.clip(1.0 - 0.5 * d / half_width, 0.0, 1.0)


@pytest.mark.parametrize("scale, angle, origin", [(1.0, 0.0, (0.0, 0.0)),
                                                  (0.01, 40.0, (3.0, -2.0)),
                                                  (100.0, -130.0, (-50.0, 20.0))])
@pytest.mark.parametrize("perturb", [0.0, 0.3])
def test_path_of_a_kinked_band_is_its_polyline(scale, angle, origin, perturb):
    h = 0.02 * scale
    points, place = cloud(scale, angle, origin, h, perturb)
    crack = place(KINKED * scale)
    w = 3 * h
    path = ridge_path(points, band(points, crack, w), crack[0])
    line = shapely.LineString(crack)
    # every vertex but the last on the crack, within a spacing; the last in the band's cap
    inner = shapely.distance(shapely.points(path[:-1]), line)
    assert inner.max() < 1.0 * h
    assert np.linalg.norm(path[0] - crack[0]) < 1.5 * h
    assert np.linalg.norm(path[-1] - crack[-1]) < w + h
    assert abs(shapely.LineString(path).length / line.length - 1) < 0.05
    # in order along the crack
    along = shapely.line_locate_point(line, shapely.points(path))
    assert (np.diff(along) > 0).all()


def test_branched_band_follows_the_longer_branch():
    h = 0.02
    points, _ = cloud(1.0, 0.0, (0.0, 0.0), h, 0.0)
    stem = np.array([[0.0, 0.5], [0.4, 0.5]])
    long_arm, short_arm = np.array([[0.4, 0.5], [0.9, 0.8]]), np.array([[0.4, 0.5], [0.6, 0.3]])
    damage = np.maximum.reduce([band(points, c, 2 * h) for c in (stem, long_arm, short_arm)])
    path = ridge_path(points, damage, stem[0])
    assert np.linalg.norm(path[-1] - long_arm[-1]) < 3 * h
    assert (shapely.distance(shapely.points(path[:-1]),
                             shapely.LineString(np.vstack([stem, long_arm[1:]]))) < 1.5 * h).all()


def test_three_dimensional_band():
    h = 0.1
    g = np.arange(0.0, 2.0 + 1e-9, h)
    points = np.array([(x, y, z) for x in g for y in g for z in g])
    crack = np.array([[0.2, 1.0, 1.0], [1.8, 1.4, 0.6]])
    d = np.linalg.norm(np.cross(points - crack[0], crack[1] - crack[0]), axis=1) \
        / np.linalg.norm(crack[1] - crack[0])
    t = (points - crack[0]) @ (crack[1] - crack[0]) / np.sum((crack[1] - crack[0]) ** 2)
    damage = np.where((t >= 0) & (t <= 1), np.clip(1 - d / (4 * h), 0, 1), 0.0)
    path = ridge_path(points, damage, crack[0])
    u = (crack[1] - crack[0]) / np.linalg.norm(crack[1] - crack[0])
    off = path - crack[0]
    assert len(path) > 3
    assert np.linalg.norm(off - np.outer(off @ u, u), axis=1).max() < h     # on the line
    assert (np.diff(off @ u) > 0).all()                                     # along it
    assert np.linalg.norm(path[-1] - crack[1]) < 4 * h + h


def test_no_band_is_named():
    points = np.random.default_rng(0).uniform(0, 1, (50, 2))
    with pytest.raises(GeometryError, match="expected some values >= threshold = 0.5"):
        ridge_path(points, np.full(50, 0.2), (0.5, 0.5))
    with pytest.raises(GeometryError, match="expected points \\(n, d\\), field \\(n,\\)"):
        ridge_path(points, np.zeros(49), (0.5, 0.5))


@pytest.mark.parametrize("scale, origin", [(1.0, (0.0, 0.0)), (1e-3, (5e6, -3e6))])
def test_separate_bands_are_told_apart(scale, origin):
    """Three bands a few spacings wide around known segments (two of them 2 spacings
    apart: separate; the third touching one: the same crack) are labelled as two cracks,
    at any origin and scale; the labels are those of a brute-force flood fill."""
    h = 0.01 * scale
    points, place = cloud(scale, 20.0, origin, h, perturb=0.2)
    segments = [((0.0, 0.2), (0.8, 0.2)), ((0.1, 0.25), (0.9, 0.25)), ((0.5, 0.25), (0.5, 0.8))]
    near = [shapely.distance(shapely.LineString(place(np.array(s) * scale)),
                             shapely.points(points)) < 0.6 * h for s in segments]
    damage = np.where(near[0], 1.0, 0.0) + np.where(near[1] | near[2], 0.7, 0.0)
    labels = ridge_bands(points, damage, threshold=0.5, spacing=h)
    assert set(labels[near[0]]) == {1} and set(labels[near[1] | near[2]]) == {0}
    assert np.all(labels[~(near[0] | near[1] | near[2])] == -1)
    # flood fill over links shorter than 1.5 h, point by point
    band = np.flatnonzero(damage >= 0.5)
    seen = {int(band[0])}
    front = [int(band[0])]
    while front:
        i = front.pop()
        for j in band[np.hypot(*(points[band] - points[i]).T) < 1.5 * h]:
            if int(j) not in seen:
                seen.add(int(j))
                front.append(int(j))
    assert len(set(labels[sorted(seen)])) == 1
