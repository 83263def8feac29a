"""Irregular clouds (`cnem.nodes.irregular`) on non-convex 3-D bodies: the L-block and
the box with a cubic cavity, of one material and of two (region 0 below z = 0.5,
region 1 above; the interface meets the re-entrant edge, or cuts the cavity in half).

Coarse irregular clouds put a node of a face near the face's border, and its cell
then has a facet in the face's plane that runs past the border (a shadow beyond a
re-entrant edge), cut differently by the cells on the other side; and they give
boundary faces that are right triangles, whose circumcentre lies on an edge. Each
used to stop `cnem.discretize` or the smoothed gradients. The patch tests: the
piecewise-linear bimaterial field of `test_interface_facets` (continuous in
displacement and traction across z = 0.5), imposed on the whole boundary, or on
x = 0 with its tractions elsewhere, is reproduced at every node, and every cell has
the exact stress of its region.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import cases3d
import cnem
from cnem.geometry.face_refinement import refine_faces
from test_interface_facets import (A, LOWER, UPPER, Z_INTERFACE, _bimaterial_field, _stress,
                                   _upper_gradient)

#: Each region's exact volume: the L-block's two halves, the cavity box's.
CAVITY_HALF = 0.5 - (1.0 / 3.0) ** 2 / 6.0
BODIES = {"two_material_l_block": (0.375, 0.375),
          "two_material_cavity": (CAVITY_HALF, CAVITY_HALF)}


def _voigt(s):
    return np.array([s[0, 0], s[1, 1], s[2, 2], s[1, 2], s[0, 2], s[0, 1]])


def _exact_stress(region):
    """Voigt stress ``(k, 6)`` of the bimaterial field in cells of ``region (k,)``."""
    lower, upper = _voigt(_stress(A, LOWER)), _voigt(_stress(_upper_gradient(), UPPER))
    return np.where((region == 0)[:, None], lower[None], upper[None])


def _traction(x, n):
    """The bimaterial field's traction on facets of normals ``n`` at points ``x``."""
    lower, upper = _stress(A, LOWER), _stress(_upper_gradient(), UPPER)
    return np.where((x[:, 2] < Z_INTERFACE)[:, None], n @ lower, n @ upper)


@pytest.fixture(scope="module", params=[
    ("two_material_l_block", 0.25, 0), ("two_material_l_block", 0.25, 1),
    ("two_material_l_block", 0.25, 3), ("two_material_l_block", 0.2, 0),
    ("two_material_cavity", 0.25, 0), ("two_material_cavity", 0.25, 3),
    ("two_material_cavity", 0.2, 2),
    pytest.param(("two_material_l_block", 0.125, 0), marks=pytest.mark.slow),
    pytest.param(("two_material_cavity", 0.125, 0), marks=pytest.mark.slow)],
    ids=lambda p: f"{p[0]}-h{p[1]}-seed{p[2]}")
def two_materials(request):
    name, h, seed = request.param
    dom = cnem.Domain3D(getattr(cases3d, name)())
    return name, cnem.discretize(cnem.nodes.irregular(dom, h, seed=seed))


def test_cells_fill_each_region(two_materials):
    name, m = two_materials
    got = np.bincount(m.cells.region, weights=m.cells.volume, minlength=2)
    np.testing.assert_allclose(got, BODIES[name], rtol=1e-12)


@pytest.mark.parametrize("stabilization", [0.0, 1.0])
def test_upper_stiffness_is_the_triangle_of_the_whole(two_materials, stabilization):
    """K assembled as its upper triangle (what `Elasticity.solve` uses in 3-D) is the
    whole K's diagonal and right of it, pattern and values, exactly; the whole one
    asked of a problem that holds the triangle is K."""
    _, m = two_materials
    whole = cnem.Elasticity(m, [LOWER, UPPER], stabilization=stabilization).stiffness()
    prob = cnem.Elasticity(m, [LOWER, UPPER], stabilization=stabilization)
    upper = prob.stiffness(upper=True)
    want = sp.triu(whole, format="csr")
    want.sort_indices()
    np.testing.assert_array_equal(upper.indptr, want.indptr)
    np.testing.assert_array_equal(upper.indices, want.indices)
    np.testing.assert_array_equal(upper.data, want.data)
    assert abs(prob.stiffness() - whole).max() <= 1e-14 * abs(whole).max()


@pytest.mark.parametrize("stabilization", [0.0, 1.0])
def test_bimaterial_patch_test(two_materials, stabilization):
    _, m = two_materials
    prob = cnem.Elasticity(m, [LOWER, UPPER], stabilization=stabilization)
    prob.add_dirichlet(m.boundary_nodes(), None, _bimaterial_field)
    sol = prob.solve(progress=False)
    exact = _bimaterial_field(m.nodes)
    assert np.abs(sol.u - exact).max() <= 1e-10 * np.abs(exact).max()
    stress = _exact_stress(sol.cells.region)
    assert np.abs(sol.stress - stress).max() <= 1e-10 * np.abs(stress).max()


def test_bimaterial_patch_test_with_tractions(two_materials):
    _, m = two_materials
    prob = cnem.Elasticity(m, [LOWER, UPPER])
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None, _bimaterial_field)
    prob.add_traction(lambda x, n: x[:, 0] > 1e-9, _traction)
    sol = prob.solve(progress=False)
    exact = _bimaterial_field(m.nodes)
    assert np.abs(sol.u - exact).max() <= 1e-10 * np.abs(exact).max()
    stress = _exact_stress(sol.cells.region)
    assert np.abs(sol.stress - stress).max() <= 1e-10 * np.abs(stress).max()


@pytest.mark.parametrize("name, h, seed", [
    ("l_block", 0.25, 1), ("box_with_cavity", 0.25, 0), ("box_with_cavity", 0.25, 1),
    pytest.param("box_with_cavity", 0.125, 0, marks=pytest.mark.slow)])
def test_one_material_patch_test(name, h, seed):
    """Clouds whose cells have a facet partly on a face and partly its shadow beyond."""
    v, f, _ = getattr(cases3d, name)(2 if name == "l_block" else 3, jitter=0.0)
    m = cnem.discretize(cnem.nodes.irregular(cnem.Domain3D((v, f)), h, seed=seed))
    prob = cnem.Elasticity(m, LOWER)
    prob.add_dirichlet(m.boundary_nodes(), None, lambda p: p @ A.T)
    sol = prob.solve(progress=False)
    exact = m.nodes @ A.T
    assert np.abs(sol.u - exact).max() <= 1e-10 * np.abs(exact).max()
    stress = np.broadcast_to(_voigt(_stress(A, LOWER)), sol.stress.shape)
    assert np.abs(sol.stress - stress).max() <= 1e-10 * np.abs(stress).max()


def _area(x):
    return 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)


@pytest.mark.parametrize("seed", range(8))
def test_a_right_triangle_splits_on_its_hypotenuse(seed):
    """Two faces whose shared edge is the diameter of both circumcircles (right
    triangles, in a tilted plane so that the centre is rounded), in a planar patch (every
    edge may flip): splitting one puts the node at the edge's midpoint, in both faces,
    and leaves no face of no area."""
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0.3, 2.8, 2) * np.array([1.0, -1.0])     # one above, one below
    ring = np.array([[-1.0, 0.0], [np.cos(angle[1]), np.sin(angle[1])], [1.0, 0.0],
                     [np.cos(angle[0]), np.sin(angle[0])]])    # counter-clockwise
    edge = np.roll(ring, -1, axis=0) - ring
    outward = np.column_stack([edge[:, 1], -edge[:, 0]])
    apex = 0.5 * (ring + np.roll(ring, -1, axis=0)) + 0.8 * outward
    flat = np.concatenate([ring, apex])
    frame = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    points = np.column_stack([flat, np.zeros(len(flat))]) @ frame.T * 0.37 + rng.normal(size=3)
    faces = np.array([[0, 2, 3], [2, 0, 1]] + [[k, 4 + k, (k + 1) % 4] for k in range(4)])
    regions = np.tile([0, -1], (len(faces), 1))
    p, f, _ = refine_faces(points, faces, regions, np.array([0]))
    before, after = _area(points[faces]), _area(p[f])
    assert after.min() > 1e-6 * before.sum()
    assert np.isclose(after.sum(), before.sum(), rtol=1e-12)
    np.testing.assert_allclose(p[len(points):], points[[0, 2]].mean(axis=0)[None], atol=1e-12)
