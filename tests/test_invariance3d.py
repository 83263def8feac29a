"""A non-convex 3-D body (an L-block: a re-entrant edge) at the origin, moved a million
units and in millimetres gives the same cells, shape functions and patch-test answers
to the coordinates' round-off (issue 37, "Invariance").

The moved cloud is the original one mapped by ``x -> s x + o``: far from the origin
the coordinates carry ``eps |o|`` of round-off (2e-10 at 2e6 for a body of size
1.7), so the comparisons allow ``1e-8`` relative (the stresses ``1e-7``: measured 2e-8
at 1e6); before the cells were computed in
the model's local frame the moved body failed (its facet points paired only to
1e-10 of its size, and unpaired facets were taken for interfaces).
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from scipy.spatial import cKDTree

import cnem
from cases3d import l_block
from cnem.material import LinearElastic

A = np.array([[0.3, -0.2, 0.1], [0.05, -0.4, 0.25], [0.15, 0.2, 0.35]]) * 1e-2
E, NU = 3.0, 0.3
VOLUME = 0.75
#: (scale, offset) of the moved bodies
MOVED = [(1.0, (1e6, -2e6, 5e5)), (1e-3, (0.0, 0.0, 0.0)), (1e3, (0.0, 0.0, 0.0)),
         # millimetres a thousand units out: the lattice's near-ties, rounded, left cells
         # with slivers a round-off thick whose faces cancelled real facets
         (1e-3, (1e3, -2e3, 5e2))]
RTOL = 1e-8
#: the stresses are derivatives: the coordinates' round-off over the spacing, amplified
STRESS_RTOL = 1e-7


def _domain(s, o):
    """The unit cube without its quarter ``x, y > 1/2``, mapped by ``x -> s x + o``."""
    vertices, faces, _ = l_block(2, jitter=0.0)
    return cnem.Domain3D((vertices * s + np.asarray(o, dtype=float), faces))


@functools.lru_cache(maxsize=None)
def _case(s, o):
    """The model mapped by ``x -> s x + o``, shape functions at fixed relative points,
    and the patch tests' stresses (Dirichlet everywhere; clamped at x = 0 and loaded
    by the tractions elsewhere)."""
    points = cnem.nodes.regular(_domain(1.0, (0.0, 0.0, 0.0)), 0.2).points
    o = np.asarray(o, dtype=float)
    model = cnem.discretize(cnem.nodes.from_points(_domain(s, o), points * s + o))
    rng = np.random.default_rng(3)
    where = rng.uniform(0.02, 0.98, (400, 3))
    where = where[(where[:, 0] < 0.5) | (where[:, 1] < 0.5)]
    phi = model.shape_functions(where * s + o).toarray()
    sv = _exact_stress()
    S = np.array([[sv[0], sv[5], sv[4]], [sv[5], sv[1], sv[3]], [sv[4], sv[3], sv[2]]])
    field = lambda p: (p - o) @ A.T              # noqa: E731  (u scales with s)
    stresses = []
    for clamp_all in (True, False):
        prob = cnem.Elasticity(model, (E, NU))
        if clamp_all:
            prob.add_dirichlet(model.boundary_nodes(), None, field)
        else:
            left = (model.nodes[:, 0] - o[0]) < 1e-9 * s
            prob.add_dirichlet(left, None, field)
            prob.add_traction(lambda x, n: (x[:, 0] - o[0]) > 1e-9 * s, lambda x, n: n @ S)
        sol = prob.solve(progress=False)
        stresses.append(sol.stress)
    return model, phi, stresses


def _exact_stress():
    eps = 0.5 * (A + A.T)
    voigt = np.array([eps[0, 0], eps[1, 1], eps[2, 2], 2 * eps[1, 2], 2 * eps[0, 2],
                      2 * eps[0, 1]])
    return LinearElastic(E, NU).elasticity_matrix(3) @ voigt


def test_the_body_at_the_origin_passes_the_patch_tests():
    model, _, stresses = _case(1.0, (0.0, 0.0, 0.0))
    assert 150 <= len(model.nodes) <= 800
    np.testing.assert_allclose(model.cells.volume.sum(), VOLUME, rtol=1e-12)
    sv = _exact_stress()
    for stress in stresses:
        np.testing.assert_allclose(stress, np.broadcast_to(sv, stress.shape),
                                   atol=1e-9 * np.abs(sv).max())


@pytest.mark.parametrize("s, o", MOVED)
def test_moved_and_rescaled_bodies_give_the_same_answers(s, o):
    ref, ref_phi, ref_stress = _case(1.0, (0.0, 0.0, 0.0))
    model, phi, stresses = _case(s, o)
    np.testing.assert_array_equal(model.nodes[model.node_of_point >= 0], model.cloud.points)
    # the nodes the tetrahedrisation added may come in another order: match them
    gap, match = cKDTree(ref.nodes).query((model.nodes - o) / s)
    assert gap.max() <= RTOL and np.array_equal(np.sort(match), np.arange(len(ref.nodes)))
    key = match[model.cells.node] * 8 + model.cells.region
    order = np.argsort(key)
    np.testing.assert_array_equal(key[order], ref.cells.node * 8 + ref.cells.region)
    np.testing.assert_allclose(model.cells.volume[order] / s ** 3, ref.cells.volume, rtol=0,
                               atol=RTOL * VOLUME)
    np.testing.assert_allclose(model.cells.volume.sum() / s ** 3, VOLUME, rtol=1e-11)
    np.testing.assert_allclose((model.cells.centroid()[order] - o) / s, ref.cells.centroid(),
                               rtol=0, atol=RTOL)
    same = np.zeros_like(ref_phi)
    same[:, match] = phi
    np.testing.assert_allclose(same, ref_phi, rtol=0, atol=RTOL)
    sv = np.abs(_exact_stress()).max()
    for got, want in zip(stresses, ref_stress):
        np.testing.assert_allclose(got[order], want, rtol=0, atol=STRESS_RTOL * sv)
