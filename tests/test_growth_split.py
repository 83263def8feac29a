"""A body that the cracks cut apart (`cnem.fracture.grow`, ``continue_with``): without it the
run stops with a `GeometryError` naming the pieces; with it the loose piece is dropped,
recorded as event ``"split"``, and growth goes on on the remaining body."""

import numpy as np
import pytest
import shapely

import cnem
from cnem.errors import GeometryError, GrowthError, GrowthWarning
from cnem.fracture import grow

E, NU, W, PULL, TOL = 1.0, 0.3, 2.0, 0.01, 1e-9

#: an edge crack aimed at the bottom edge near the bottom-left corner (it cuts the corner
#: off in the first step) and a vertical internal crack that keeps growing
CORNER = [[0.0, 0.15], [0.1, 0.05]]
MIDDLE = [[1.4, 0.4], [1.4, 0.6]]


def strip():
    return cnem.geometry.rectangle(W, 1.0, cracks=[CORNER, MIDDLE])


def stretch(corner_support=False):
    """Left edge on rollers, right edge pulled along x; u_y held at the top-left corner
    (``corner_support``: at the bottom-left corner, which the corner crack cuts off)."""
    held = (0.0, 0.0) if corner_support else (0.0, 1.0)

    def setup(model):
        prob = cnem.Elasticity(model, (E, NU), plane="strain")
        prob.add_dirichlet(lambda p: np.abs(p[:, 0]) < TOL, 0)
        prob.add_dirichlet(lambda p: np.abs(p[:, 0] - W) < TOL, 0, PULL)
        prob.add_dirichlet(lambda p: np.hypot(*(p - held).T) < TOL, 1)
        return prob
    return setup


def run(steps=3, **options):
    dom = strip()
    with pytest.warns(GrowthWarning):                  # the increment leaves the domain
        return grow(dom, cnem.nodes.regular(dom, 0.05), stretch(**options.pop("setup", {})),
                    increment=0.1, steps=steps, progress=False, **options)


def test_without_continue_with_the_error_names_the_pieces():
    with pytest.raises(GeometryError, match="2 pieces") as info:
        run()
    message = str(info.value)
    assert "piece 0: area" in message and "piece 1: area" in message
    assert "continue_with" in message                   # says how to go on
    hist = info.value.history
    assert [e.kind for e in hist.events if e.kind != "left_domain"] == ["boundary"]


def test_continue_with_largest_drops_the_corner_and_grows_on():
    hist = run(steps=3, continue_with="largest")
    split = [e for e in hist.events if e.kind == "split"]
    assert len(split) == 1 and split[0].step == 0 and split[0].tip == -1
    assert "dropped piece 1" in split[0].message and "crack" in split[0].message
    # the corner piece, bounded by the left edge, the crack and the bottom edge (shoelace)
    path = np.vstack([CORNER[0], hist.steps[0].tips[0], hist.steps[1].tips[0]])
    assert abs(path[-1, 1]) < 1e-12                     # the crack ended on the bottom edge
    ring = np.vstack([[0.0, 0.0], path])
    corner = 0.5 * abs(np.dot(ring[:, 0], np.roll(ring[:, 1], -1))
                       - np.dot(ring[:, 1], np.roll(ring[:, 0], -1)))
    assert 0.005 < corner < 0.05
    assert hist.domain.area == pytest.approx(W - corner, rel=1e-12)
    assert str(f"area {corner:.4g}") in split[0].message
    # the corner crack is boundary now: one crack left, its two tips grew every step
    assert len(hist.cracks) == 1 and len(hist.domain.tips) == 2
    assert len(hist.steps) == 3
    assert not hist.final.active[0] and hist.final.active[1:].all()
    middle = hist.paths()[:, 1:]
    assert np.hypot(*np.diff(middle, axis=0).T) == pytest.approx(0.1, rel=1e-9)
    # mode I under the pull along x: the middle crack grows along y, up and down
    assert np.abs(middle[..., 0] - 1.4).max() < 0.02
    assert hist.final.tips[0] == pytest.approx(path[-1])   # the stopped tip keeps its place
    # no node left in the dropped corner
    nodes = hist.model.nodes
    inside = shapely.contains_xy(shapely.Polygon(ring).buffer(-1e-6), nodes[:, 0], nodes[:, 1])
    assert not inside.any()


def test_continue_with_a_callable_or_an_index_chooses_the_piece():
    chosen = []

    def pick(pieces):
        chosen.append([p.area for p in pieces])
        return 0
    a = run(steps=2, continue_with=pick)
    b = run(steps=2, continue_with=0)
    assert len(chosen) == 1 and chosen[0][0] > chosen[0][1]
    np.testing.assert_allclose(a.paths(), b.paths(), atol=1e-12)
    with pytest.raises(GeometryError, match="expected the index of one of them"):
        run(steps=1, continue_with=5)


def test_supports_on_the_dropped_piece_are_named_in_the_error():
    with pytest.raises(GeometryError, match="remaining body") as info:
        run(steps=2, continue_with="largest", setup=dict(corner_support=True))
    assert "selects no node" in str(info.value)
    assert [e.kind for e in info.value.history.events][-1] == "split"


@pytest.mark.parametrize("bad", ["smallest", -1, 1.5, True])
def test_bad_continue_with_is_a_growth_error(bad):
    with pytest.raises(GrowthError, match="continue_with"):
        grow(strip(), 0.2, stretch(), increment=0.1, steps=1, continue_with=bad, progress=False)
