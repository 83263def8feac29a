"""The predictor-corrector increment of `grow` (``scheme="corrector"``,
`cnem.fracture.corrector`): symmetry and invariance of the corrected path, its
order against a path known in closed form, events of the trial segment, and the
accepted model's local update still equal to a fresh build."""

import warnings

import numpy as np
import pytest

import cnem
from cnem.errors import GrowthError
from cnem.fracture import advance, grow
from cnem.fracture import growth as growth_module
from test_growth import (assert_same_runs, tension_setup, transformed_cloud, uniaxial_setup,
                         williams_setup)
from test_local_update import _assert_equal_models


def test_symmetric_problem_grows_straight_with_the_corrector():
    dom = cnem.geometry.rectangle(1.0, 2.0, cracks=[[[0.0, 1.0], [0.3, 1.0]]])
    hist = grow(dom, cnem.nodes.regular(dom, 0.05), tension_setup(1.0, 2.0), increment=0.05,
                steps=2, K_Ic=2.0, scheme="corrector", progress=False)
    tips = hist.paths()[:, 0]
    assert np.abs(tips[:, 1] - 1.0).max() < 1e-9
    assert tips[:, 0] == pytest.approx([0.3, 0.35, 0.4], abs=1e-12)
    assert np.abs(hist.array("correction")).max() < 1e-6
    # load factors of the accepted tips, not of the trial ones
    assert hist.array("load_factor")[:, 0] == pytest.approx(2.0 / hist.array("K_eq")[:, 0])
    assert not [e for e in hist.events if e.kind == "predictor"]


@pytest.fixture(scope="module")
def williams_corrector_runs():
    """The mixed-mode run of tests/test_growth.py (`williams_runs`) with the corrector,
    rotated by 0.7 rad and mirrored about x = 0."""
    dom = cnem.geometry.rectangle(1.0, 1.0, origin=(-0.5, -0.5), cracks=[[[-0.5, 0.0], [0.0, 0.0]]])
    cloud = cnem.nodes.irregular(dom, 0.06, seed=3)
    c, s = np.cos(0.7), np.sin(0.7)
    run = dict(increment=0.05, steps=2, scheme="corrector", progress=False)
    out = {"base": (np.eye(2), grow(dom, cloud, williams_setup(1.0, 0.4), **run))}
    for name, m in (("rotated", np.array([[c, -s], [s, c]])), ("mirrored", np.diag([-1.0, 1.0]))):
        d, cl = transformed_cloud(cloud, dom, m)
        out[name] = (m, grow(d, cl, williams_setup(1.0, 0.4 * np.linalg.det(m)), **run))
    return out


@pytest.mark.parametrize("name", ["rotated", "mirrored"])
def test_corrected_path_is_rotated_and_mirrored_with_the_problem(williams_corrector_runs, name):
    base = williams_corrector_runs["base"][1]
    m, hist = williams_corrector_runs[name]
    assert np.abs(hist.paths()[:, 0] - base.paths()[:, 0] @ m.T).max() < 1e-3 * 0.05
    sign = np.sign(np.linalg.det(m))
    for field in ("angle", "correction"):
        expect = sign * base.array(field)[:-1, 0]
        assert hist.array(field)[:-1, 0] == pytest.approx(expect, abs=1e-4)


def test_accepted_segment_leaves_the_tip_at_angle_plus_correction(williams_corrector_runs):
    hist = williams_corrector_runs["base"][1]
    s = hist.steps[0]
    assert abs(s.angle[0]) > np.radians(20) and s.correction[0] != 0.0
    step = hist.steps[1].tips[0] - s.tips[0]
    assert np.hypot(*step) == pytest.approx(0.05, rel=1e-12)
    assert np.arctan2(step[1], step[0]) == pytest.approx(s.angle[0] + s.correction[0], abs=1e-12)
    assert hist.final.correction[0] == 0.0                 # no growth after the last state


# ------------------------------------------------- order against a known path
R, CENTRE = 1.0, np.array([1.5, 3.0])    # the tip (1.5, 2) lies on the circle, tangent along x


def circle_kink(self, sol, tip):
    """`_Run.tip_kink` of a direction field whose paths are the circles about CENTRE
    (counter-clockwise): the kink turns the tip's crack onto the circle's tangent."""
    for crack in self.cracks:
        for end in (0, -1):
            if np.array_equal(crack[end], tip):
                d = advance.tip_direction(crack, end)
    r = tip - CENTRE
    t = np.array([-r[1], r[0]]) / np.hypot(*r)
    theta = np.arctan2(d[0] * t[1] - d[1] * t[0], d @ t)
    return np.array([1.0, 0.0]), theta, 1.0, False


def circle_errors(monkeypatch, scheme, increment, length=1.2):
    """Distance of the tip from the circle, and from the circle's point at arc length
    ``length`` from the start, after ``length`` of growth."""
    monkeypatch.setattr(growth_module._Run, "tip_kink", circle_kink)
    dom = cnem.geometry.rectangle(4.0, 4.0, cracks=[[[0.0, 2.0], [1.5, 2.0]]])
    hist = grow(dom, cnem.nodes.regular(dom, 0.25), uniaxial_setup(1.0), increment=increment,
                steps=int(round(length / increment)), scheme=scheme, refine=None, keep=False,
                progress=False)
    assert hist.array("crack_length")[-1, 0] == pytest.approx(1.5 + length, rel=1e-12)
    tip, phi = hist.cracks[0][-1], -0.5 * np.pi + length / R
    exact = CENTRE + R * np.array([np.cos(phi), np.sin(phi)])
    return abs(np.hypot(*(tip - CENTRE)) - R), np.hypot(*(tip - exact))


def test_corrector_converges_faster_than_first_order_on_a_known_path(monkeypatch):
    """Explicit steps along the tangent of a circle of radius R leave it by exactly
    sqrt(R^2 + n da^2) - R after n steps (each step along the tangent at its start):
    first order at a fixed length. The corrector's chord is the mean of the end
    tangents, off the exact chord by O(da^3): it leaves the circle by O(da^3) (8x per
    halved increment), and its tip lags the exact point at the same length by the arc
    minus chord, O(da^2) (4x)."""
    explicit = np.array([circle_errors(monkeypatch, "explicit", da) for da in (0.2, 0.1)])
    for (off, _), da in zip(explicit, (0.2, 0.1)):
        n = int(round(1.2 / da))
        assert off == pytest.approx(np.sqrt(R ** 2 + n * da ** 2) - R, rel=1e-9)
    corrected = np.array([circle_errors(monkeypatch, "corrector", da) for da in (0.2, 0.1)])
    assert explicit[0] / explicit[1] == pytest.approx([2.0, 2.0], rel=0.1)
    off, along = corrected[0] / corrected[1]
    assert off > 7.0 and along > 3.5
    assert np.all(corrected[0] < 0.1 * explicit[0])


# ------------------------------------------------------------ events, update
def test_trial_segment_into_the_boundary_falls_back_to_the_predictor():
    """The right tip 0.08 from the edge, increment 0.1: its trial meets the boundary,
    the step takes the predictor there (reported) and the tip stops on the edge; the
    left tip is corrected as usual."""
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.3, 0.5], [0.92, 0.5]]])
    with pytest.warns(cnem.errors.GrowthWarning, match="leave the domain"):
        hist = grow(dom, cnem.nodes.regular(dom, 0.05), uniaxial_setup(1.0), increment=0.1,
                    steps=1, scheme="corrector", progress=False)
    right = int(np.argmax(hist.steps[0].tips[:, 0]))
    mine = [e.kind for e in hist.events if e.tip == right]
    assert mine[0] == "predictor" and "boundary" in hist.events[0].message
    assert mine[1:] == ["left_domain", "boundary"]
    assert not [e for e in hist.events if e.tip != right]
    assert hist.steps[0].correction[right] == 0.0
    assert hist.final.tips[right, 0] == pytest.approx(1.0, abs=1e-12)       # on the edge
    assert hist.final.tips[right, 1] == pytest.approx(0.5, abs=1e-3)        # mode I: straight on
    assert not hist.final.active[right] and hist.final.active[1 - right]


def test_corrected_local_update_equals_full_rebuilds_with_rings(caplog):
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.45], [0.3, 0.55]]])
    cloud = cnem.nodes.irregular(dom, 0.08, seed=1)
    rings = cnem.fracture.Refinement(spacing=0.02, radius=0.24)
    with caplog.at_level("INFO", logger="cnem.fracture.growth"):
        local, full = [grow(dom, cloud, uniaxial_setup(1.0), increment=0.06, steps=2, refine=rings,
                            scheme="corrector", progress=False, local=flag)
                       for flag in (True, False)]
    assert not [r for r in caplog.records if "refuses" in r.getMessage()]   # updated locally
    assert np.abs(local.array("correction")[:-1, 0]).min() > 1e-3         # the corrector turned
    _assert_equal_models(local.model, cnem.discretize(local.model.cloud, progress=False))
    assert_same_runs(local, full)


def test_bad_scheme_raises_a_growth_error():
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.4, 0.5]]])
    with pytest.raises(GrowthError, match="scheme.*corrector.*received 'heun'"):
        grow(dom, 0.2, uniaxial_setup(1.0), increment=0.1, steps=1, scheme="heun", progress=False)


def test_tip_dependent_increments_are_those_of_the_accepted_tips():
    """Paris-type increments da_i = increment (K_eq,i / K_eq,max)^2 from the accepted
    K's; each accepted segment has that length and leaves at angle + correction."""
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.25, 0.45], [0.55, 0.55]]])
    hist = grow(dom, cnem.nodes.irregular(dom, 0.07, seed=1), uniaxial_setup(1.0), increment=0.06,
                steps=2, exponent=2.0, scheme="corrector", progress=False)
    tips = hist.paths()
    start = np.array([[0.55, 0.55], [0.25, 0.45]])          # the other end of each tip's crack
    if np.hypot(*(tips[0, 0] - start[0])) < 1e-9:
        start = start[::-1]
    for k, s in enumerate(hist.steps):
        assert s.increment == pytest.approx(0.06 * (s.K_eq / s.K_eq.max()) ** 2, rel=1e-12)
        assert s.increment.min() < 0.99 * s.increment.max()            # the tips differ
        step = tips[k + 1] - tips[k]
        assert np.hypot(*step.T) == pytest.approx(s.increment, rel=1e-9)
        d = tips[k] - (start if k == 0 else tips[k - 1])
        turn = np.arctan2(d[:, 0] * step[:, 1] - d[:, 1] * step[:, 0], np.sum(d * step, axis=1))
        assert turn == pytest.approx(s.angle + s.correction, abs=1e-9)
        assert np.abs(s.correction).min() > 0


def test_sif_warnings_name_accepted_tips_only(monkeypatch):
    """The discs at a trial tip are the corrector's business: every `SIFWarning` that
    reaches the user is one of an accepted tip (a tip of the recorded path)."""
    def warning_kink(self, sol, tip):
        warnings.warn(f"tip {tip[0]!r} {tip[1]!r}", cnem.errors.SIFWarning)
        return circle_kink(self, sol, tip)

    monkeypatch.setattr(growth_module._Run, "tip_kink", warning_kink)
    dom = cnem.geometry.rectangle(4.0, 4.0, cracks=[[[0.0, 2.0], [1.5, 2.0]]])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        hist = grow(dom, cnem.nodes.regular(dom, 0.25), uniaxial_setup(1.0), increment=0.2,
                    steps=3, scheme="corrector", refine=None, keep=False, progress=False)
    warned = {str(w.message) for w in caught if issubclass(w.category, cnem.errors.SIFWarning)}
    accepted = {f"tip {p[0]!r} {p[1]!r}" for p in hist.cracks[0][1:]}
    assert warned and warned <= accepted
