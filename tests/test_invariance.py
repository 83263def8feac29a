"""The same cracked body at the origin, moved far away (1e6, 1e8: UTM-like) and in
other units gives the same model and the same answers to the coordinates' round-off
(issue 19, item 1).

Far from the origin the coordinates themselves carry ``eps |x|`` of round-off (1.5e-8
at 1e8): the moved problem is the original one perturbed by that much, so the
comparisons allow a few times ``ROUND = eps (|offset| + scale) / scale`` (relative to
the body's size 1), and the node and cell counts must be equal. Measured (irregular
cloud, h = 0.06 and graded 0.05 -> 0.005): at 1e8 K_I within 1-3e-8 (1 ROUND) and u
within 5-7e-8; at 5e6 with a 100 m body 1-3e-11; before the fixes the 1e8 body had 6
more nodes and K_I 54 % off (crack points not snapped, crack faces' sides lost), a
graded cloud u 16 % off (spurious slits), branch enrichment 1.2 % off already at 1e6.
"""

from __future__ import annotations

import functools
import warnings

import numpy as np
import pytest

import cnem
from cnem import config
from cnem.errors import SIFWarning
from cnem.fracture import sif
from cnem.fracture.opening import crack_opening
from cnem.fracture.williams import sided_polar

KINK = np.array([[0.2, 0.62], [0.45, 0.7], [0.62, 0.66]])
OUTLINE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
_t = np.linspace(0.0, 2.0 * np.pi, 32, endpoint=False)
HOLE = np.column_stack([0.7 + 0.15 * np.cos(_t), 0.3 + 0.15 * np.sin(_t)])
#: (offset, scale) of the moved bodies: UTM-like far away, UTM-like in metres, units
FAR = [(1e8, 1.0), (5e6, 100.0), (1e6, 1.0)]


def _moved(s, o):
    """The body mapped by ``x -> s x + o``."""
    return cnem.Domain([(OUTLINE * s + o, [HOLE * s + o])], cracks=[KINK * s + o])


@functools.lru_cache(maxsize=None)
def _points(cloud):
    body = _moved(1.0, 0.0)
    if cloud == "graded":
        return cnem.nodes.graded(body, 0.05, near=body.tips, h_min=0.005, seed=3).points
    return cnem.nodes.irregular(body, 0.06, seed=1).points


def _pulled(model, s, o, enrich):
    """Bottom held (its left corner also sideways), the top pulled by a unit traction."""
    prob = cnem.Elasticity(model, (1.0, 0.3), plane="strain", enrich=enrich)
    near = 4 * model.domain.tolerance
    bottom = lambda p: np.abs(p[:, 1] - o) <= near                          # noqa: E731
    prob.add_dirichlet(bottom, 1)
    prob.add_dirichlet(lambda p: bottom(p) & (np.abs(p[:, 0] - o) <= near), 0)
    prob.add_traction(lambda x, n: np.abs(x[:, 1] - (o + s)) <= near, np.array([0.0, 1.0]))
    return prob


@functools.lru_cache(maxsize=None)
def _solved(cloud, s, o, functions=None):
    """Model and answers of the body mapped by ``x -> s x + o``, mapped back."""
    body = _moved(s, o)
    model = cnem.discretize(cnem.nodes.from_points(body, _points(cloud) * s + o), progress=False)
    enrich = None if functions is None else dict(radius=0.1 * s, functions=functions)
    sol = _pulled(model, s, o, enrich).solve(progress=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SIFWarning)          # coarse near the tips: same K
        K = np.array([sif(sol, tip) for tip in body.tips]) / np.sqrt(s)     # (KI, KII) each
    cells = model.cells
    at, opening, _ = crack_opening(model, sol.u, KINK[1:] * s + o)      # the last segment
    return dict(nodes=(model.nodes - o) / s, segments=model.segments, offsets=cells.offsets,
                area=cells.area / s**2, u=sol.u / s, K=K, at=(at - o) / s, opening=opening / s)


def _round(s, o):
    return np.finfo(float).eps * (abs(o) + s) / s


@pytest.mark.parametrize("o, s", FAR)
def test_far_body_gives_the_model_and_K_of_the_origin(o, s):
    """Same nodes (count exact, positions to round-off), segments, cells (count and
    vertices per cell exact, areas), displacements, K_I, K_II at both tips and the
    crack's opening at its face nodes."""
    ref, got, tol = _solved("irregular", 1.0, 0.0), _solved("irregular", s, o), _round(s, o)
    assert len(got["nodes"]) == len(ref["nodes"])
    np.testing.assert_array_equal(got["segments"], ref["segments"])
    np.testing.assert_allclose(got["nodes"], ref["nodes"], rtol=0, atol=4 * tol)
    np.testing.assert_array_equal(got["offsets"], ref["offsets"])
    np.testing.assert_allclose(got["area"], ref["area"], rtol=0, atol=10 * tol)
    np.testing.assert_allclose(got["u"], ref["u"], rtol=0, atol=10 * tol * np.abs(ref["u"]).max())
    np.testing.assert_allclose(got["K"], ref["K"], rtol=0, atol=10 * tol * np.abs(ref["K"]).max())
    assert len(ref["at"]) >= 3                        # the face nodes of the last segment
    np.testing.assert_allclose(got["at"], ref["at"], rtol=0, atol=4 * tol)
    np.testing.assert_allclose(got["opening"], ref["opening"], rtol=0,
                               atol=10 * tol * np.abs(ref["opening"]).max())


@pytest.mark.parametrize("o", [1e8, 1e6])
@pytest.mark.parametrize("functions", ["branch", "sqrt"])
def test_far_enriched_graded_body_gives_the_K_of_the_origin(o, functions):
    """A graded cloud (spacing 0.005 at the tips: round-off 3e-6 of it at 1e8) with
    near-tip enrichment: the crack-face sides of the branch functions, the slits of
    the tip cells and the graded rules at the tips found as at the origin."""
    ref, got = _solved("graded", 1.0, 0.0, functions), _solved("graded", 1.0, o, functions)
    tol = _round(1.0, o)
    np.testing.assert_array_equal(got["offsets"], ref["offsets"])
    np.testing.assert_allclose(got["u"], ref["u"], rtol=0, atol=10 * tol * np.abs(ref["u"]).max())
    np.testing.assert_allclose(got["K"], ref["K"], rtol=0, atol=10 * tol * np.abs(ref["K"]).max())


def test_tolerance_covers_the_coordinates_round_off():
    """`Domain.tolerance`: ``SNAP_TOL * diameter`` near the origin, at least
    ``ROUNDOFF_ULPS`` ulps of the coordinates far away, so that a point of a crack
    moved there (rounded off its line) is snapped onto it, not taken for a node beside it."""
    assert _moved(1.0, 0.0).tolerance == config.SNAP_TOL * np.sqrt(2.0)
    far = _moved(1.0, 1e8)
    assert far.tolerance >= config.ROUNDOFF_ULPS * np.spacing(1e8) / 2
    on_crack = 0.3 * KINK[0] + 0.7 * KINK[1]
    cloud = cnem.nodes.from_points(far, (_points("irregular") + 1e8).tolist() + [on_crack + 1e8])
    assert len(cloud.points) == len(cnem.nodes.from_points(
        _moved(1.0, 0.0), np.vstack([_points("irregular"), on_crack])).points)
    crack = cloud.segments[cloud.segment_kind == cnem.geometry.SegmentKind.CRACK]
    assert len(_points("irregular")) in crack


def test_far_body_refuses_a_spacing_below_its_round_off():
    """At 1e8 a body 1 across resolves no spacing below ten tolerances (3.6e-6): a
    graded cloud asking for 1e-6 at the tips is refused by name, as at the origin only
    below 1e-8 times the diameter."""
    far = _moved(1.0, 1e8)
    with pytest.raises(cnem.errors.GeometryError, match="h_min = 1e-06 is below the smallest "
                       "spacing this domain resolves.*nearer the origin"):
        cnem.nodes.graded(far, 0.05, near=far.tips, h_min=1e-6)
    body = _moved(1.0, 0.0)
    assert cnem.nodes.graded(body, 0.05, near=body.tips, h_min=1e-6, growth=1.0).points.size


def test_points_on_the_faces_within_the_tolerance_take_their_side():
    """`sided_polar`: a point behind the tip off the crack line by less than the
    tolerance (a face point's round-off far away) gets theta = +-pi from its side,
    one farther off keeps its own angle."""
    tip, d, tol = np.array([0.0, 0.0]), np.array([1.0, 0.0]), 1e-6
    pts = np.array([[-0.5, 0.5 * tol], [-0.5, 0.5 * tol], [-0.5, 2 * tol]])
    sides = np.array([[-0.5, -0.1], [-0.5, 0.1], [-0.5, -0.1]])
    r, theta = sided_polar(pts, tip, d, sides, tol)
    assert theta[0] == -np.pi and theta[1] == np.pi
    assert 0 < theta[2] < np.pi
    np.testing.assert_allclose(r, np.hypot(*pts.T))


def test_far_shape_functions_are_those_of_its_nodes_at_the_origin():
    """What differs at 1e8 is the input (nodes and points rounded to 1.5e-8), not
    the arithmetic: the shape functions of the moved body equal, bit for bit, those
    of its own rounded nodes shifted back to the origin (exact shifts)."""
    o = 1e8
    far = cnem.nodes.from_points(_moved(1.0, o), _points("irregular") + o)
    back = cnem.Domain([(OUTLINE + o - o, [HOLE + o - o])], cracks=[KINK + o - o])
    near = cnem.nodes.NodeCloud(back, far.points - o, far.segments, far.segment_kind, far.spacing)
    rng = np.random.default_rng(2)
    query = rng.random((600, 2)) + o
    query = query[far.domain.contains(query)]
    got = cnem.discretize(far, progress=False).shape_functions(query)
    ref = cnem.discretize(near, progress=False).shape_functions(query - o)
    assert (got != ref).nnz == 0
