"""`cnem.fracture.sif` on nested discs: the default disc fits the geometry and gives the right K.

A mixed-mode Williams field (K_I = 1, K_II = 0.5, plane stress, crack at 30
degrees from the square's edge to its centre) imposed on the outer boundary only
(the crack faces are free, as in the exact field) is solved on a uniform, a
graded and a ring-refined cloud (rings of nodes about the tip as in FEM rosettes,
with nodes on the crack faces); the default K must be within 1 % of |K|. Measured
(K_I, K_II errors in % of K_I; spread): irregular h = 0.05 +0.40, +0.23 (0.25 %);
graded 0.1 -> 0.005 -0.12, -0.07 (0.25 %); rings -0.05, -0.03 (0.39 %).

The discs stay clear of the other tip, free edges, holes, other cracks and kinks
(`cnem.fracture.discs.clearance`); a user's disc that reaches past one warns.
"""

from __future__ import annotations

import functools
import warnings

import numpy as np
import pytest
import shapely
from scipy.spatial import cKDTree

import cnem
from cnem.errors import SIFWarning
from cnem.fracture import nodal_williams, sif
from cnem.fracture.discs import clearance, default_radii
from cnem.geometry import SegmentKind

E, NU, KI, KII = 1.0, 0.3, 1.0, 0.5


def _square(angle_deg=30.0):
    """Side 2 about a tip at the origin; the crack comes in from the boundary along -d."""
    a = np.deg2rad(angle_deg)
    d = np.array([np.cos(a), np.sin(a)])
    return cnem.geometry.rectangle(2.0, 2.0, origin=(-1.0, -1.0), cracks=[[-d / np.abs(d).max(), [0, 0]]])


def ring_cloud(dom, h, first, ratio, rings, per_ring=16):
    """Rings of ``per_ring`` nodes about the (only) tip at radii ``first * ratio**k``, one node
    of each ring on the crack, a lattice of spacing ``h`` outside the rings and off the crack,
    nodes every ``h`` on the outer boundary and on the crack faces beyond the rings."""
    at, d = dom.tip_frame(dom.tips[0])
    radii = first * ratio ** np.arange(rings)
    angles = np.arctan2(d[1], d[0]) + np.pi + 2 * np.pi * np.arange(per_ring) / per_ring
    rings_xy = (at + radii[:, None, None] * np.stack([np.cos(angles), np.sin(angles)], -1)).reshape(-1, 2)
    xmin, ymin, xmax, ymax = dom.bounds
    grid = np.stack(np.meshgrid(np.arange(xmin + h / 2, xmax, h), np.arange(ymin + h / 2, ymax, h)), -1)
    grid = grid.reshape(-1, 2)
    crack = shapely.LineString(dom.cracks[0])
    keep = (np.hypot(*(grid - at).T) > radii[-1] + 0.8 * h) & (
        shapely.distance(shapely.points(grid), crack) > 0.3 * h)
    outline = shapely.LineString(np.vstack([dom.regions[0].exterior.coords]))
    edge = [outline.interpolate(s).coords[0] for s in np.arange(0.0, outline.length, h)]
    behind = np.arange(radii[-1] + h, crack.length, h)
    faces = [crack.interpolate(crack.length - s).coords[0] for s in behind]
    pts = np.concatenate([rings_xy, grid[keep], np.reshape(edge, (-1, 2)), np.reshape(faces, (-1, 2))])
    far = cKDTree(dom.pslg.vertices).query(pts)[0] > 0.2 * first
    return cnem.nodes.from_points(dom, pts[far])


CLOUDS = {
    "uniform": lambda dom: cnem.nodes.irregular(dom, 0.05, seed=1),
    "graded": lambda dom: cnem.nodes.graded(dom, 0.1, near=dom.tips, h_min=0.005, growth=0.15, seed=0),
    "rings": lambda dom: ring_cloud(dom, 0.1, 0.01, 1.6, 6),
}


@functools.lru_cache(maxsize=None)
def _williams_solution(cloud):
    dom = _square()
    model = cnem.discretize(CLOUDS[cloud](dom), progress=False)
    exact = nodal_williams(model, (0.0, 0.0), KI, KII, E, NU, "stress")
    outer = np.unique(model.segments[model.segment_kind == SegmentKind.BOUNDARY])
    prob = cnem.Elasticity(model, (E, NU), plane="stress")
    prob.add_dirichlet(outer, None, lambda p: exact[outer])
    return prob.solve(progress=False)


def test_ring_cloud_has_nodes_on_both_crack_faces():
    model = _williams_solution("rings").model
    faces = model.segments[model.segment_kind == SegmentKind.CRACK]
    lengths = np.hypot(*(model.nodes[faces[:, 0]] - model.nodes[faces[:, 1]]).T)
    assert lengths.max() < 0.15            # no face is one straight edge from tip to mouth
    assert len(faces) > 2 * 10


@pytest.mark.parametrize("cloud", list(CLOUDS))
def test_default_discs_give_the_mixed_mode_K_within_one_percent(cloud):
    sol = _williams_solution(cloud)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SIFWarning)            # the discs agree: no warning
        res = sif(sol, (0.0, 0.0))
    np.testing.assert_allclose(res, [KI, KII], atol=0.01 * np.hypot(KI, KII))
    assert len(res.radii) >= 3 and np.all(np.diff(res.radii) > 0)
    assert res.radius == res.radii[-1] and tuple(res) == tuple(res.values[-1])
    assert 0 <= res.spread < 0.01
    # the largest disc stays inside the square (distance 1 from the tip)
    assert res.clearance.obstacle == "the outer boundary or a hole"
    np.testing.assert_allclose(res.clearance.distance, 1.0, rtol=1e-12)
    assert res.radius < 1.0


def test_a_single_user_disc_still_works():
    sol = _williams_solution("graded")
    res = sif(sol, (0.0, 0.0), radius=0.6)
    KI_, KII_ = res
    assert res.radius == 0.6 and res.radii.tolist() == [0.6] and np.isnan(res.spread)
    assert abs(KI_ - KI) < 0.01 and abs(KII_ - KII) < 0.01


def _centre_crack(h, gamma_deg=0.0, a=0.2, W=1.0, H=2.0):
    """A centre crack 2a in a plate 2W x 2H under remote tension sigma = 1 along y."""
    g = np.deg2rad(gamma_deg)
    d = a * np.array([np.cos(g), np.sin(g)])
    dom = cnem.geometry.rectangle(2 * W, 2 * H, origin=(-W, -H), cracks=[[-d, d]])
    model = cnem.discretize(cnem.nodes.regular(dom, h), progress=False)
    prob = cnem.Elasticity(model, (E, NU))
    prob.add_traction(lambda x, n: np.abs(np.abs(x[:, 1]) - H) < 1e-9 * H, lambda x, n: n * [0.0, 1.0])
    prob.add_dirichlet(lambda p: np.hypot(*(p - [-W, -H]).T) < 1e-9 * H, None)
    prob.add_dirichlet(lambda p: np.hypot(*(p - [W, -H]).T) < 1e-9 * H, 1)
    # Tada's fit for the long strip (0.1 %): F = (1 - 0.025 r^2 + 0.06 r^4) sqrt(sec(pi r / 2))
    r = a / W
    K = np.sqrt(np.pi * a) * (1 - 0.025 * r ** 2 + 0.06 * r ** 4) / np.sqrt(np.cos(np.pi * r / 2))
    return prob.solve(progress=False), d, K * np.array([np.cos(g) ** 2, np.sin(g) * np.cos(g)])


def test_coarse_centre_crack_disc_stops_short_of_the_other_tip():
    """a/W = 0.2 on a uniform cloud of 4 spacings per crack: six spacings (the old default)
    would span the other tip (+8.2 % on this plate); the default discs stop before it
    (measured -3.6 %, and -1.0 % at h = 0.05)."""
    sol, d, exact = _centre_crack(0.1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = sif(sol, d)
    assert res.clearance.obstacle == "the other tip of crack 0"
    np.testing.assert_allclose(res.clearance.distance, 0.4, rtol=1e-12)
    assert res.radius < 0.4
    assert abs(res.KI / exact[0] - 1) < 0.04, (res.KI, exact)
    # so few spacings per crack: the discs disagree by a few %, and say so
    assert res.spread > 0.01
    assert any(issubclass(w.category, SIFWarning) and "vary by" in str(w.message) for w in caught)
    with pytest.warns(SIFWarning, match="reaches the other tip of crack 0"):
        sif(sol, d, radius=0.6)


def test_edge_crack_disc_stays_off_the_free_edge():
    dom = cnem.geometry.rectangle(1.0, 2.0, cracks=[[[0.0, 1.0], [0.2, 1.0]]])
    lim = clearance(dom, *dom.tip_frame((0.2, 1.0)))
    np.testing.assert_allclose(lim.distance, 0.2, rtol=1e-12)
    np.testing.assert_allclose(lim.point, [0.0, 1.0], atol=1e-12)
    assert lim.obstacle == "the outer boundary or a hole"


def test_clearance_sees_holes_interfaces_other_cracks_and_kinks():
    hole = np.array([[0.6, 0.4], [0.8, 0.4], [0.8, 0.6], [0.6, 0.6]])[::-1]
    dom = cnem.Domain([(np.array([[0, 0], [1, 0], [1, 1], [0, 1]]), [hole])],
                      cracks=[[[0.0, 0.5], [0.5, 0.5]]])
    lim = clearance(dom, *dom.tip_frame((0.5, 0.5)))
    np.testing.assert_allclose(lim.distance, 0.1, rtol=1e-9)
    two = cnem.Domain([[[0, 0], [0.7, 0], [0.7, 1], [0, 1]], [[0.7, 0], [1, 0], [1, 1], [0.7, 1]]],
                      cracks=[[[0.0, 0.5], [0.5, 0.5]]])
    lim = clearance(two, *two.tip_frame((0.5, 0.5)))
    assert lim.obstacle == "the interface of region 0"
    np.testing.assert_allclose(lim.distance, 0.2, rtol=1e-9)
    cracks = cnem.geometry.rectangle(2.0, 2.0, cracks=[[[0.0, 1.0], [0.8, 1.0]], [[1.0, 1.15], [1.6, 1.6]]])
    lim = clearance(cracks, *cracks.tip_frame((0.8, 1.0)))
    assert lim.obstacle == "crack 1"
    np.testing.assert_allclose(lim.distance, np.hypot(0.2, 0.15), rtol=1e-9)
    # a 10 degree kink 0.2 behind the tip: the disc may reach little past it
    k = np.deg2rad(10.0)
    start = [-0.2 - 0.5 * np.cos(k), 0.5 * np.sin(k)]
    kinked = cnem.geometry.rectangle(2.0, 2.0, origin=(-1, -1), cracks=[[start, [-0.2, 0.0], [0, 0]]])
    lim = clearance(kinked, *kinked.tip_frame((0.0, 0.0)))
    assert lim.obstacle == "the other tip of crack 0"
    np.testing.assert_allclose(lim.distance, np.hypot(0.2 + 0.5 * np.cos(k), 0.5 * np.sin(k)))
    assert 0.2 < lim.straight < 0.2 / (1 - cnem.config.SIF_STRAIGHTNESS / np.sin(k)) * 1.01
    # a straight crack split into collinear pieces (crack growth) is one straight crack
    pieces = cnem.geometry.rectangle(1.0, 2.0, cracks=[[[0.0, 1.0], [0.1, 1.0], [0.15, 1.0], [0.2, 1.0]]])
    lim = clearance(pieces, *pieces.tip_frame((0.2, 1.0)))
    np.testing.assert_allclose(lim.distance, 0.2, rtol=1e-12)
    assert lim.straight == np.inf


def test_a_kink_limits_the_discs_but_not_below_a_few_spacings():
    """Discs stop at a kink far behind the tip; a fresh kink one spacing behind a growing tip
    leaves them six spacings wide (a smaller disc cannot resolve the field)."""
    for s0, h in ((0.3, 0.1), (0.05, 0.05)):
        k = np.deg2rad(20.0)
        dom = cnem.geometry.rectangle(2.0, 2.0, origin=(-1, -1),
                                      cracks=[[[-s0 - 0.5 * np.cos(k), 0.5 * np.sin(k)], [-s0, 0.0], [0, 0]]])
        model = cnem.discretize(cnem.nodes.regular(dom, h), progress=False)
        lim = clearance(dom, *dom.tip_frame((0.0, 0.0)))
        radii, spacing, limited_by = default_radii(model, np.zeros(2), lim)
        assert "bend" in limited_by
        np.testing.assert_allclose(radii[-1], max(0.9 * lim.straight, 6 * spacing), rtol=1e-12)
        assert radii[-1] < lim.distance


def test_clearance_is_relative_to_the_model():
    """The same edge crack moved by 1e6 and scaled by 1e-3: the same clearance, scaled."""
    def limit(shift, scale):
        crack = shift + scale * np.array([[0.0, 1.0], [0.3, 1.05]])
        dom = cnem.geometry.rectangle(scale, 2 * scale, origin=(shift, shift), cracks=[crack])
        return clearance(dom, *dom.tip_frame(dom.tips[0]))
    base = limit(0.0, 1.0)
    for shift, scale in ((1e6, 1.0), (0.0, 1e-3)):
        lim = limit(shift, scale)
        np.testing.assert_allclose(lim.distance, scale * base.distance, rtol=1e-8)
        assert lim.obstacle == base.obstacle
