"""A peridynamic body with a crack has the same families and the same cut bonds in
any units and at any origin: shifted by 1e8 or by a UTM-like 5e6, scaled by 1e-6 or
1e6 (with its horizon)."""

from __future__ import annotations

import numpy as np
import pytest

import cnem
import cnem.pd as pd
from cnem.pd import Body

H = 2.0 ** -5
#: A kinked crack through lattice points: its ends, its inner vertex and the points
#: of its slanted segment (slope 1/2: every second column) are lattice points, so
#: bonds run through its ends and points lie exactly on it.
CRACK = np.array([[0.25, 0.5], [0.5, 0.5], [0.75, 0.625]])
MOVES = [("shift 1e8", 1.0, (1e8, 1e8)), ("shift UTM", 1.0, (5e5, 5e6)),
         ("scale 1e-6", 1e-6, (0.0, 0.0)), ("scale 1e6", 1e6, (0.0, 0.0)),
         ("scale 1e-6 at 5e6", 1e-6, (5e5 * 1e-6 + 3.0, 5e6 * 1e-6))]


def lattice():
    x = np.arange(33) * H
    return np.column_stack([g.ravel() for g in np.meshgrid(x, x, indexing="ij")])


def bonds(body):
    return set(zip(body.bond_i.tolist(), body.bond_j.tolist()))


@pytest.mark.parametrize("name, scale, shift", MOVES)
def test_cut_bonds_of_a_crack_through_lattice_points_are_invariant(name, scale, shift):
    pts = lattice()
    on_line = np.isclose(pts[:, 1], 0.5) & (pts[:, 0] >= 0.25) & (pts[:, 0] <= 0.5)
    assert on_line.sum() == 9
    ref_whole = bonds(Body(pts, H * H, 3.1 * H))
    ref = bonds(Body(pts, H * H, 3.1 * H, cracks=[CRACK]))
    cut = ref_whole - ref
    # bonds through the crack's first end and its tip are kept, those across it cut
    i = np.flatnonzero(np.isclose(pts, [0.25, 0.5 - H]).all(axis=1))[0]
    j = np.flatnonzero(np.isclose(pts, [0.25, 0.5 + H]).all(axis=1))[0]
    k = np.flatnonzero(np.isclose(pts, [0.3125, 0.5 + H]).all(axis=1))[0]
    assert (i, j) in ref and (i, k) in cut
    moved = pts * scale + np.asarray(shift)
    whole = bonds(Body(moved, (H * scale) ** 2, 3.1 * H * scale))
    body = Body(moved, (H * scale) ** 2, 3.1 * H * scale, cracks=[CRACK * scale + np.asarray(shift)])
    assert whole == ref_whole
    assert whole - bonds(body) == cut


@pytest.mark.parametrize("scale, shift", [(1.0, (1e8, 1e8)), (1.0, (5e5, 5e6)), (1e-6, (0.0, 0.0)),
                                          (1e6, (0.0, 0.0))])
def test_body_from_a_cracked_cloud_is_invariant(scale, shift):
    """`Body.from_cloud` splits the crack-face points and nudges each copy towards its
    face for the crossing test: the same bonds, in the same order, far from the origin
    and in other units (the nudge, 1e-6 h, is below the round-off of coordinates at 1e8)."""
    def body(s, t):
        dom = cnem.geometry.rectangle(s, s, origin=t,
                                      cracks=[np.array([[0.0, 0.5], [0.5, 0.5]]) * s + t])
        return Body.from_cloud(cnem.nodes.regular(dom, s / 16), 3.0)
    ref = body(1.0, np.zeros(2))
    moved = body(scale, np.asarray(shift))
    np.testing.assert_allclose((moved.points - np.asarray(shift)) / scale, ref.points, atol=1e-9)
    np.testing.assert_array_equal(moved.family.offsets, ref.family.offsets)
    np.testing.assert_array_equal(moved.family.indices, ref.family.indices)


def _clamped_plate(material, horizon, shift=0.0):
    """A 0.1 lattice of the unit square, left edge clamped, body force (1, 0.5): the
    number of bonds and max |u|."""
    g = np.arange(0.0, 1.0 + 1e-9, 0.1)
    pts = np.array([(x, y) for x in g for y in g]) + shift
    body = pd.Body(pts, 0.01, horizon)
    prob = pd.Problem(body, material)
    prob.add_dirichlet(lambda p: p[:, 0] < shift + 0.05, None)
    prob.add_body_force([1.0, 0.5])
    return len(body.bond_j), float(np.abs(prob.solve().u).max())


@pytest.mark.parametrize("material", [pd.StateBased(1.0, 0.3), pd.BondBased(1.0)],
                         ids=["state", "bond"])
def test_bonds_at_a_horizon_of_whole_spacings_do_not_turn_on_round_off(material):
    """Horizon 3h on an h lattice: the bonds of length 3h (partial volume 1/2) are in the
    family wherever the body lies and however the horizon is rounded. Before, the body
    moved by 1e6 lost or gained such bonds (u changed by 0.3-2.4 %), and the horizons
    0.3 - 1e-12, 0.3 and 0.3 + 1e-12 gave max |u| 1.568, 1.581 and 1.615."""
    bonds, u = _clamped_plate(material, 0.3)
    for horizon, shift in ((0.3, 1e6), (0.3 - 1e-12, 0.0), (0.3 + 1e-12, 0.0),
                           (0.1 + 0.2, 0.0)):
        moved_bonds, moved_u = _clamped_plate(material, horizon, shift)
        assert moved_bonds == bonds, (horizon, shift)
        assert abs(moved_u - u) <= 1e-9 * u, (horizon, shift, moved_u, u)
