"""Array arguments checked at the public boundary: wrong lengths,
NaN and inf, coordinates whose squares overflow, and moduli whose stiffness overflows
raise a `cnem.CNEMError` naming the argument and the received shape or value, instead
of NumPy broadcast errors, scipy overflows or "form ... is not bilinear"."""

from __future__ import annotations

import numpy as np
import pytest

import cnem
import cnem.pd as pd
from cnem import config
from cnem.errors import check_array, check_points
from cnem.spatial import RTree, family_search

H = 0.1
POINTS = np.array([(x, y) for x in np.arange(0, 1 + 1e-9, H) for y in np.arange(0, 1 + 1e-9, H)])
N = len(POINTS)


def test_check_array_names_the_argument_shape_and_first_bad_entry():
    with pytest.raises(cnem.InputError, match=r"^r: expected an array of shape \(4,\), "
                                              r"received shape \(3,\)$"):
        check_array("r", [1, 2, 3], shape=(4,))
    with pytest.raises(cnem.SpatialError, match=r"x: expected finite values, received NaN at "
                                                r"index \(1, 0\) \(shape \(2, 2\)\)"):
        check_array("x", [[0, 0], [np.nan, 1]], shape=(None, 2), error=cnem.SpatialError)
    with pytest.raises(cnem.InputError, match=r"received -inf at index 2"):
        check_array("v", [1, 2, -np.inf])
    with pytest.raises(cnem.InputError, match=r"expected positive values, received 0.0 at "
                                              r"index 1"):
        check_array("v", [1, 0], positive=True)
    with pytest.raises(cnem.InputError, match=r"does not convert to one float array"):
        check_array("v", [[1, 2], [3]])
    out = check_array("h", 2.0, shape=(3,), broadcast=True)
    assert out.tolist() == [2.0, 2.0, 2.0] and out.flags.writeable and out.flags.c_contiguous


@pytest.mark.parametrize("bad, match", [
    (np.ones(3), r"r: expected a number or an array of shape \(121,\), received shape \(3,\)"),
    (np.nan, r"r: expected finite values, received NaN"),
    (np.inf, r"r: expected finite values, received inf"),
    (-1.0, r"r: expected non-negative values, received -1.0")])
def test_query_radii(bad, match):
    with pytest.raises(cnem.SpatialError, match=match):
        RTree.from_points(POINTS).query_ball(POINTS, bad)


@pytest.mark.parametrize("bad, match", [
    (np.full(3, 0.3), r"horizon: expected a number or an array of shape \(121,\), received "
                      r"shape \(3,\)"),
    (np.r_[np.full(N - 1, 0.3), np.nan], r"horizon must be positive and finite, received "
                                         r"nan at point 120"),
    (np.inf, r"horizon must be positive and finite, received inf at point 0")])
def test_per_point_horizons(bad, match):
    with pytest.raises(cnem.SpatialError, match=match):
        family_search(POINTS, bad)


@pytest.mark.parametrize("volumes, horizon, match", [
    (np.full(3, 0.01), 0.3, r"volumes: expected a number or an array of shape \(121,\), "
                            r"received shape \(3,\)"),
    (np.r_[np.full(N - 1, 0.01), np.inf], 0.3, r"volumes: expected finite values, received inf "
                                               r"at index 120"),
    (np.nan, 0.3, r"volumes: expected finite values, received NaN"),
    (-0.01, 0.3, r"volumes: expected positive values, received -0.01"),
    (0.01, np.full(3, 0.3), r"horizon: expected one positive number .*received shape \(3,\)"),
    (0.01, np.nan, r"horizon: expected finite values, received NaN.*three node spacings")])
def test_pd_volumes_and_horizon(volumes, horizon, match):
    with pytest.raises(cnem.InputError, match=match):
        pd.Body(POINTS, volumes, horizon)


@pytest.mark.parametrize("build", [
    lambda p: RTree.from_points(p),
    lambda p: family_search(p, 0.3 * np.abs(p).max()),
    lambda p: pd.Body(p, 1.0, 0.3 * np.abs(p).max())], ids=["rtree", "family", "pd"])
def test_coordinates_whose_squares_overflow(build):
    with pytest.raises(cnem.InputError, match=r"points: expected coordinates below 1e\+150 .*"
                                              r"received 1e\+300 \(shape \(121, 2\)\); express"):
        build(POINTS * 1e300)
    assert np.isfinite((POINTS * 0.99 * config.COORDINATE_LIMIT) ** 2).all()
    build(POINTS * 1e100)                        # large but representable: accepted


def test_node_coordinates_nan_named_by_row():
    pts = np.vstack([POINTS, [np.nan, 0.5]])
    with pytest.raises(cnem.InputError, match=r"points: expected finite values, received NaN at "
                                              r"index \(121, 0\).*drop or repair"):
        pd.Body(pts, 0.01, 0.3)
    with pytest.raises(cnem.InputError, match=r"expected an \(n, 2\) or \(n, 3\) array"):
        check_points("points", np.zeros((4, 4)))


def _bar(E, nu=0.3, plane="stress"):
    dom = cnem.Domain([[0, 0], [2, 0], [2, 1], [0, 1]])
    prob = cnem.Elasticity(cnem.discretize(cnem.nodes.regular(dom, 0.25)), (E, nu), plane=plane)
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_dirichlet(lambda p: p[:, 0] > 2 - 1e-9, 0, 1e-3)
    return prob


@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_a_huge_modulus_gives_the_scaled_answer_not_a_form_error(plane):
    # E = 1e300 used to overflow the plane-stress lambda* = 2 lambda mu / (lambda + 2 mu):
    # "form elasticity_form is not bilinear". Displacement-driven: u does not depend on E
    big, unit = _bar(1e300, plane=plane).solve(), _bar(1.0, plane=plane).solve()
    np.testing.assert_allclose(big.u, unit.u, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_a_modulus_whose_stiffness_overflows_is_named(plane):
    with pytest.raises(cnem.MaterialError, match=r"elasticity matrix is not finite.*E up to "
                                                 r"1.7e\+308 \(material 0.*other units"):
        _bar(1.7e308, plane=plane)


def test_plane_stress_lambda_is_unchanged():
    from cnem.material import lame
    E, nu = np.array([1.0, 210e9, 3.0]), np.array([0.3, 0.0, -0.5])
    lam, mu = lame(E, nu, "stress")
    strain_lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    np.testing.assert_allclose(lam, 2 * strain_lam * mu / (strain_lam + 2 * mu), rtol=1e-15)


def _entry_points():
    """Public calls that take coordinates or a spacing, each as ``call(bad)``."""
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    dom = cnem.Domain(square)
    model = cnem.discretize(cnem.nodes.regular(dom, 0.25))
    inside = np.array([[0.3, 0.4], [0.6, 0.7]])
    return {
        "Domain": lambda kind: cnem.Domain(square.astype(kind)),
        "from_points": lambda kind: cnem.nodes.from_points(dom, inside.astype(kind)),
        "shape_functions": lambda kind: model.shape_functions(inside.astype(kind)),
        "family_search": lambda kind: cnem.spatial.family_search(inside.astype(kind), 0.5),
        "regular h": lambda kind: cnem.nodes.regular(dom, np.asarray(0.25).astype(kind)),
    }


@pytest.mark.parametrize("kind", [complex, bool, str])
@pytest.mark.parametrize("call", sorted(_entry_points()))
def test_coordinates_that_are_not_real_numbers_are_refused(call, kind):
    """Complex coordinates lost their imaginary part, booleans became 0 and 1 and the
    string "0.1" a spacing, silently: each is refused by name."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")                # no ComplexWarning on the way
        with pytest.raises(cnem.CNEMError, match="expected real numbers"):
            _entry_points()[call](kind)
