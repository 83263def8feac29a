"""Node clouds refuse what they cannot build, by name and in bounded time: spacings that are
not positive, too large, below what the coordinates resolve or too many nodes; a user's
points that are duplicated, outside, of the wrong shape or not finite; bare crack faces
(filled, or named with ``fill=False``)."""

from __future__ import annotations

import re

import numpy as np
import pytest

import cnem
from boxed import run_boxed
from cnem import geometry, nodes
from cnem.errors import GeometryError, LimitError

SQUARE = geometry.rectangle(1.0, 1.0)


def raises(match):
    """`pytest.raises` for a GeometryError whose message matches ``match``."""
    return pytest.raises(cnem.GeometryError, match=match)


# ----------------------------------------------------------------- spacing
GENERATORS = {
    "regular": lambda d, h: nodes.regular(d, h),
    "irregular": lambda d, h: nodes.irregular(d, h, seed=0),
    "graded": lambda d, h: nodes.graded(d, h, near=[[0.5, 0.5]], h_min=min(abs(h), 0.05) or 0.05),
}


@pytest.mark.parametrize("gen", list(GENERATORS))
@pytest.mark.parametrize("h, text", [(0.0, "0.0"), (-0.1, "-0.1"), (np.nan, "nan"),
                                     (np.inf, "inf")])
def test_non_positive_spacing(gen, h, text):
    with raises(rf"h must be a positive spacing, received {re.escape(text)}"):
        GENERATORS[gen](SQUARE, h)


@pytest.mark.parametrize("gen", list(GENERATORS))
@pytest.mark.parametrize("h", [np.sqrt(2.0), 2.0, 100.0])
def test_spacing_larger_than_the_domain(gen, h):
    with raises(rf"h = {h:g} is not smaller than the domain diameter 1\.41421"):
        GENERATORS[gen](SQUARE, h)


def test_graded_h_min_not_positive():
    with raises(r"h_min must be a positive spacing, received 0\.0"):
        nodes.graded(SQUARE, 0.1, near=[[0.5, 0.5]], h_min=0.0)


def test_graded_h_min_above_h():
    with raises(r"h_min \(0\.2\) must not exceed h \(0\.1\)"):
        nodes.graded(SQUARE, 0.1, near=[[0.5, 0.5]], h_min=0.2)


@pytest.mark.parametrize("growth", [0.0, -0.5, 1.5])
def test_graded_growth_out_of_range(growth):
    with raises(rf"growth must lie in \(0, 1\], received {re.escape(repr(growth))}"):
        nodes.graded(SQUARE, 0.1, near=[[0.5, 0.5]], h_min=0.02, growth=growth)


def test_graded_without_centres():
    with raises(r"`near` is empty"):
        nodes.graded(SQUARE, 0.1, near=[], h_min=0.02)


# ------------------------------------------------------------- from_points
def test_duplicate_points():
    pts = [[0.1, 0.1], [0.5, 0.5], [0.2, 0.2], [0.5, 0.5]]
    with raises(r"1 pairs of duplicated points \(closer than 1\.41e-09\), first 1 and 3; "
                r"remove the duplicates"):
        nodes.from_points(SQUARE, pts)


def test_nearly_duplicate_points():
    pts = [[0.1, 0.1], [0.5, 0.5], [0.5 + 1e-12, 0.5]]
    with raises(r"duplicated points .* first 1 and 2"):
        nodes.from_points(SQUARE, pts)


def test_points_outside():
    pts = [[0.1, 0.1], [1.5, 0.5], [0.2, 0.2], [-0.1, 0.5]]
    with raises(r"2 of 4 points lie outside the domain, first \(index: point\) 1: \[1\.5, 0\.5\], "
                r"3: \[-0\.1, 0\.5\]"):
        nodes.from_points(SQUARE, pts)


def test_point_in_a_hole_is_outside():
    dom = geometry.plate_with_hole(1.0, 1.0, 0.2)
    with raises(r"1 of 2 points lie outside the domain, first \(index: point\) 1: \[0\.5, 0\.5\]"):
        nodes.from_points(dom, [[0.1, 0.1], [0.5, 0.5]])


def test_points_of_the_wrong_shape():
    with raises(r"points: expected a \(p, 2\) array, received shape \(3,\)"):
        nodes.from_points(SQUARE, [0.1, 0.2, 0.3])


def test_non_finite_points():
    with raises(r"points: 1 rows are not finite, first \[1\]"):
        nodes.from_points(SQUARE, [[0.1, 0.1], [np.nan, 0.5]])


# ------------------------------------------------------------------ graded clouds
CENTRE_CRACK = "cnem.Domain([[0, 0], [1, 0], [1, 1], [0, 1]], cracks=[[[0.25, 0.5], [0.75, 0.5]]])"


def test_graded_below_the_resolvable_spacing_is_refused_in_bounded_time():
    """h_min = 1e-9 at the tips of a unit square's crack (below ten snapping
    tolerances; no answer in 120 s before) is refused, naming the smallest spacing."""
    code = (
        "import cnem\n"
        f"dom = {CENTRE_CRACK}\n"
        "try:\n"
        "    cnem.nodes.graded(dom, 0.05, near=dom.tips, h_min=1e-9)\n"
        "except cnem.errors.GeometryError as e:\n"
        "    print(e)\n")
    out = run_boxed(code, timeout=120)
    assert "h_min = 1e-09 is below the smallest spacing this domain resolves" in out
    assert "expected h_min >= 1.41e-08" in out


def test_graded_spacing_along_the_crack_follows_the_law():
    """With h_min = 3e-8 the spacing between consecutive crack nodes follows
    s(x) = min(h, h_min + growth d) to a few per cent all the way to both tips (a fixed
    65-point rule gave the first 1/64 of the crack one uniform tiny spacing), the
    cloud stays small (logarithmic in h / h_min), and its cells partition the square."""
    code = (
        "import numpy as np, cnem\n"
        f"dom = {CENTRE_CRACK}\n"
        "h, h_min, growth = 0.05, 3e-8, 0.3\n"
        "cloud = cnem.nodes.graded(dom, h, near=dom.tips, h_min=h_min, growth=growth)\n"
        "p = cloud.points\n"
        "x = np.sort(p[(p[:, 1] == 0.5) & (p[:, 0] >= 0.25) & (p[:, 0] <= 0.75), 0])\n"
        "mid = 0.5 * (x[1:] + x[:-1])\n"
        "law = np.minimum(h, h_min + growth * np.minimum(mid - 0.25, 0.75 - mid))\n"
        "ratio = np.diff(x) / law\n"
        "model = cnem.discretize(cloud, progress=False)\n"
        "print(len(p), x[1] - x[0], ratio.min(), ratio.max(), model.cells.area.sum())\n")
    n, first, lo, hi, area = map(float, run_boxed(code).split())
    assert n < 5000
    assert first < 1.3 * 3e-8                  # the law reaches h_min at the tips
    assert 0.95 < lo and hi < 1.05
    assert area == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize("call, message", [
    (lambda dom: cnem.nodes.regular(dom, 1e-5),
     r"regular with h = 1e-05 would need ~1e\+10 nodes.*expected h >= "),
    (lambda dom: cnem.nodes.graded(dom, 0.05, near=dom.tips, h_min=2e-8, growth=0.001),
     r"graded with h = 0.05, h_min = 2e-08, growth = 0.001 around 2 centres would need "
     r"~.* nodes.*expected h_min >= "),
], ids=["regular", "graded"])
def test_clouds_too_large_are_refused_before_generation(call, message):
    dom = eval(CENTRE_CRACK)
    with pytest.raises(LimitError, match=message):
        call(dom)


# ------------------------------------------------------------------ the user's own points
def lattice_with_tip_rings(dom, h):
    """A square lattice offset by h / 2 (no point on the outline or the crack line)
    plus rosette rings of nodes around each tip, none on the crack line."""
    g = np.arange(-1 + h / 2, 1, h)
    pts = np.column_stack([a.ravel() for a in np.meshgrid(g, g)])
    rings = []
    for tip in dom.tips:
        pts = pts[np.hypot(*(pts - tip).T) > 4 * h]
        for r in h * np.array([0.25, 0.5, 1, 1.7, 2.5, 3.3]):
            m = max(8, int(2 * np.pi * r / (0.6 * r if r < h else 0.8 * h)))
            th = (np.arange(m) + 0.5 * (r < h)) * 2 * np.pi / m
            rings.append(tip + r * np.column_stack([np.cos(th), np.sin(th)]))
    pts = np.concatenate([pts] + rings)
    return pts[np.abs(pts[:, 1]) > 1e-9]


def centre_crack_KI(cloud):
    """K_I / sqrt(pi a) at the right tip of the centre crack under unit remote tension."""
    from cnem.fracture import sif
    prob = cnem.Elasticity(cnem.discretize(cloud, progress=False), (1.0, 0.3))
    prob.add_traction(lambda x, n: np.abs(np.abs(x[:, 1]) - 1.0) < 1e-9, lambda x, n: n * [0.0, 1.0])
    prob.add_dirichlet(lambda p: np.hypot(*(p - [-1.0, -1.0]).T) < 1e-12, None)
    prob.add_dirichlet(lambda p: np.hypot(*(p - [1.0, -1.0]).T) < 1e-12, 1)
    return sif(prob.solve(progress=False), (0.2, 0.0)).KI / np.sqrt(np.pi * 0.2)


def test_from_points_fills_bare_crack_faces_and_boundaries():
    """A lattice offset by h / 2 plus rings around the tips has no point on the outline
    or the crack faces: filled at the local spacing, the crack opens and K_I of the
    centre crack (a / W = 0.2 in a square plate) is within 4 % of the handbook's
    long strip, 1.0245 sqrt(pi a) (Tada), which a finite height raises slightly."""
    dom = cnem.geometry.rectangle(2.0, 2.0, origin=(-1.0, -1.0), cracks=[[[-0.2, 0.0], [0.2, 0.0]]])
    pts = lattice_with_tip_rings(dom, 0.1)
    cloud = cnem.nodes.from_points(dom, pts)
    np.testing.assert_array_equal(cloud.points[:len(pts)], pts)       # the user's points first
    length = np.linalg.norm(np.diff(cloud.points[cloud.segments], axis=1), axis=2)[:, 0]
    assert length.max() <= 2 * 0.1                                     # no long gap is left
    assert abs(centre_crack_KI(cloud) / 1.0245 - 1) < 0.04


def test_from_points_without_fill_names_the_bare_crack_face():
    dom = cnem.geometry.rectangle(2.0, 2.0, origin=(-1.0, -1.0), cracks=[[[-0.2, 0.0], [0.2, 0.0]]])
    with pytest.raises(GeometryError, match=r"first the crack gap from \[-0\.2, 0\.0\] to "
                                            r"\[0\.2, 0\.0\].*cannot open.*pass fill=True"):
        cnem.nodes.from_points(dom, lattice_with_tip_rings(dom, 0.1), fill=False)




@pytest.mark.parametrize("call, match", [
    (lambda dom: cnem.nodes.irregular(dom, 0.1, seed="a"), "seed: expected a whole number"),
    (lambda dom: cnem.nodes.irregular(dom, 0.1, seed=-1), "seed: expected a whole number >= 0"),
    (lambda dom: cnem.nodes.irregular(dom, 0.1, seed=1.5), "seed: expected a whole number"),
    (lambda dom: cnem.nodes.graded(dom, 0.1, near=[[np.nan, 0.5]], h_min=0.02),
     "near: expected finite values"),
    (lambda dom: cnem.nodes.graded(dom, 0.1, near=[[0.5, 0.5, 0.0]], h_min=0.02),
     r"near: expected refinement points \(q, 2\)"),
], ids=["seed str", "seed negative", "seed float", "near NaN", "near 3 columns"])
def test_seeds_and_refinement_points_are_checked(call, match):
    """numpy's SeedSequence and shapely's messages came through before."""
    with pytest.raises(cnem.GeometryError, match=match):
        call(cnem.geometry.rectangle())
