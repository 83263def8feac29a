"""Crack opening at the split nodes (`cnem.fracture.opening`): the exact Williams field of
an inclined edge crack opens and slides by (8 K / E') sqrt(r / 2 pi), and K_I is fitted
back from the opening."""

import numpy as np
import pytest

import cnem
from cnem.errors import GeometryError
from cnem.fracture import nodal_williams
from cnem.fracture.opening import crack_opening, k_from_opening

E, NU = 2.0, 0.3


@pytest.fixture(scope="module")
def model():
    mouth, tip = np.array([0.0, 0.3]), np.array([0.5, 0.55])
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[mouth, tip]])
    return cnem.discretize(cnem.nodes.regular(dom, 0.05), progress=False), mouth, tip


@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_williams_field_opens_like_the_crack_tip_solution(model, plane):
    model, mouth, tip = model
    KI, KII = 1.3, -0.4
    u = nodal_williams(model, tip, KI, KII, E, NU, plane)
    points, opening, sliding = crack_opening(model, u, [mouth, tip])
    length = np.linalg.norm(tip - mouth)
    along = (points - mouth) @ (tip - mouth) / length
    assert len(points) >= 5 and (np.diff(along) > 0).all()
    assert (along >= 0).all() and (along < length).all()    # the mouth splits, the tip not
    r = length - along
    Ep = E if plane == "stress" else E / (1 - NU ** 2)
    np.testing.assert_allclose(opening, 8 * KI / Ep * np.sqrt(r / (2 * np.pi)), rtol=1e-10)
    np.testing.assert_allclose(sliding, 8 * KII / Ep * np.sqrt(r / (2 * np.pi)), rtol=1e-10)
    assert k_from_opening(r, opening, E, NU, plane) == pytest.approx(KI, rel=1e-10)
    near = r < 0.2
    assert k_from_opening(r, opening, E, NU, plane, where=near) == pytest.approx(KI, rel=1e-10)
    assert np.isnan(k_from_opening(r, opening, E, NU, plane, where=np.zeros(len(r), bool)))


def test_the_reversed_segment_turns_the_faces(model):
    model, mouth, tip = model
    u = nodal_williams(model, tip, 1.0, 0.0, E, NU, "stress")
    p1, o1, _ = crack_opening(model, u, [mouth, tip])
    p2, o2, _ = crack_opening(model, u, [tip, mouth])
    np.testing.assert_array_equal(p2, p1[::-1])
    np.testing.assert_allclose(o2, o1[::-1], rtol=1e-12)     # the normal and the faces turn
    with pytest.raises(GeometryError, match="two distinct end points"):
        crack_opening(model, u, [tip, tip])


@pytest.mark.parametrize("gamma", [0.0, 0.4, 1.2])
@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_central_crack_fields_agree_with_its_sifs(gamma, plane):
    """`cnem.exact.CentralCrack`: the opening near a tip is (8 K_I / E') sqrt(r / 2 pi)
    (so `k_from_opening` returns K_I), the normal stress ahead of a tip is
    K_I / sqrt(2 pi r) near it and the remote normal stress far from it."""
    from cnem.exact import CentralCrack
    a, sigma = 0.3, 2.0
    crack = CentralCrack(a, sigma, gamma)
    KI, KII = crack.sif()
    assert KI == pytest.approx(sigma * np.sqrt(np.pi * a) * np.cos(gamma) ** 2, rel=1e-14)
    assert KII == pytest.approx(sigma * np.sqrt(np.pi * a) * np.sin(gamma) * np.cos(gamma),
                                rel=1e-14)
    r = a * np.geomspace(1e-9, 1e-7, 5)
    opening = crack.opening(a - r, E, NU, plane)
    Ep = E if plane == "stress" else E / (1 - NU ** 2)
    np.testing.assert_allclose(opening, 8 * KI / Ep * np.sqrt(r / (2 * np.pi)), rtol=1e-6)
    assert k_from_opening(r, opening, E, NU, plane) == pytest.approx(KI, rel=1e-6)
    assert (crack.opening([-a, a, 2 * a], E, NU, plane) == 0).all()
    np.testing.assert_allclose(crack.normal_stress_ahead(r), KI / np.sqrt(2 * np.pi * r),
                               rtol=1e-6)
    assert crack.normal_stress_ahead(1e9 * a) == pytest.approx(sigma * np.cos(gamma) ** 2,
                                                                rel=1e-8)
