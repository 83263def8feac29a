"""3-D C-NEM elasticity on real models: `cnem.discretize` of a `cnem.Domain3D` cloud,
smoothed gradients from the cells' facets, `cnem.Elasticity` without `plane`.

The patch tests: a linear displacement imposed on the whole boundary, or on one
face with the matching tractions on the others, is reproduced at every node and
the stress is exact in every cell, on irregular and regular clouds, with and
without the stabilisation.
"""

from __future__ import annotations

import numpy as np
import pytest

import cnem
from cnem.material import LinearElastic

A = np.array([[0.3, -0.2, 0.1], [0.05, -0.4, 0.25], [0.15, 0.2, 0.35]]) * 1e-2
B = np.array([0.1, -0.3, 0.2]) * 1e-2
E, NU = 3.0, 0.3


def _exact_stress():
    """The constant Voigt stress ``(6,)`` of the field ``A x + B``."""
    eps = 0.5 * (A + A.T)
    C = LinearElastic(E, NU).elasticity_matrix(3)
    voigt = np.array([eps[0, 0], eps[1, 1], eps[2, 2], 2 * eps[1, 2], 2 * eps[0, 2],
                      2 * eps[0, 1]])
    return C @ voigt


@pytest.fixture(scope="module", params=["irregular", "regular", "regular_fine"])
def box_model(request):
    dom = cnem.geometry.box((0.0, 0.0, 0.0), (1.0, 0.8, 0.6))
    if request.param == "regular":          # a lattice: cospherical ties everywhere
        return cnem.discretize(cnem.nodes.regular(dom, 0.25))
    if request.param == "regular_fine":     # zero-area Voronoi facets inside and on the surface
        return cnem.discretize(cnem.nodes.regular(dom, 0.15))
    return cnem.discretize(cnem.nodes.irregular(dom, 0.25, seed=3))


def test_cells_fill_the_body(box_model):
    assert np.isclose(box_model.cells.volume.sum(), 1.0 * 0.8 * 0.6, rtol=1e-12)


@pytest.mark.parametrize("stabilization", [0.0, 1.0])
def test_patch_test_on_a_box(box_model, stabilization):
    model = box_model
    prob = cnem.Elasticity(model, (E, NU), stabilization=stabilization)
    faces, _ = prob.boundary_edges()
    on_boundary = np.zeros(len(model.nodes), dtype=bool)
    on_boundary[faces.ravel()] = True
    prob.add_dirichlet(on_boundary, None, lambda p: p @ A.T + B)
    sol = prob.solve(progress=False)
    assert sol.u.shape == (len(model.nodes), 3)
    np.testing.assert_allclose(sol.u, model.nodes @ A.T + B, atol=1e-12)
    assert sol.stress.shape == (len(model.cells.node), 6)
    np.testing.assert_allclose(sol.stress, np.broadcast_to(_exact_stress(), sol.stress.shape),
                               atol=1e-10 * np.abs(_exact_stress()).max())


@pytest.mark.parametrize("stabilization", [0.0, 1.0])
def test_patch_test_with_tractions(box_model, stabilization):
    """Clamped to the linear field on x = 0, loaded by its tractions everywhere else:
    the loads are integrated on the cells' own boundary facet points, so they balance
    K u exactly (with the P1 hats of the boundary triangles instead, an h = 0.2 box
    missed the field by 30 %)."""
    model = box_model
    sv = _exact_stress()
    S = np.array([[sv[0], sv[5], sv[4]], [sv[5], sv[1], sv[3]], [sv[4], sv[3], sv[2]]])
    prob = cnem.Elasticity(model, (E, NU), stabilization=stabilization)
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None, lambda p: p @ A.T + B)
    prob.add_traction(lambda x, n: x[:, 0] > 1e-9, lambda x, n: n @ S)
    sol = prob.solve(progress=False)
    np.testing.assert_allclose(sol.u, model.nodes @ A.T + B, atol=1e-12)
    np.testing.assert_allclose(sol.stress, np.broadcast_to(sv, sol.stress.shape),
                               atol=1e-10 * np.abs(sv).max())


def test_boundary_nodes_of_a_3d_model(box_model):
    """The outer surface's nodes, by coordinates; a predicate picks among them; names are
    refused until 3-D bodies have them."""
    nodes = box_model.nodes
    lo, hi = np.zeros(3), np.array([1.0, 0.8, 0.6])
    on = np.flatnonzero(np.any(np.isclose(nodes, lo) | np.isclose(nodes, hi), axis=1))
    np.testing.assert_array_equal(box_model.boundary_nodes(), on)
    np.testing.assert_array_equal(box_model.boundary_nodes(lambda p: p[:, 2] > 0.5),
                                  on[nodes[on, 2] > 0.5])
    with pytest.raises(cnem.ConditionError, match="no named boundaries"):
        box_model.boundary_nodes("top")


def test_cell_quadrature_and_energy_error_in_3d(box_model):
    """The cones over the facets integrate each cell's volume, and the energy-norm error of
    the patch test's solution is zero against its stress and ``sqrt(V e C^-1 e)`` against a
    stress off by ``e``."""
    from cnem.assembly.quadrature import cell_quadrature
    model = box_model
    cell, _, weights = cell_quadrature(model.cells, model.nodes, 2)
    np.testing.assert_allclose(np.bincount(cell, weights=weights, minlength=len(model.cells)),
                               model.cells.volume, atol=1e-14)
    prob = cnem.Elasticity(model, (E, NU))
    prob.add_dirichlet(lambda p: np.ones(len(p), dtype=bool), None, lambda p: p @ A.T + B)
    sol = prob.solve(progress=False)
    exact = _exact_stress()
    assert sol.energy_error(lambda x: np.tile(exact, (len(x), 1))) < 1e-12 * np.abs(exact).max()
    off = 0.1 * exact
    C = LinearElastic(E, NU).elasticity_matrix(3)
    want = np.sqrt(0.48 * off @ np.linalg.solve(C, off))
    np.testing.assert_allclose(sol.energy_error(lambda x: np.tile(exact + off, (len(x), 1))),
                               want, rtol=1e-10)


def test_patch_test_beside_a_faceted_hole():
    """A tube whose hole is a 16-gon, coarsely: the facets of the hole hide nothing, so
    the cells beside it are not star-shaped from their nodes and some pyramid spokes
    cross the hole (their sub-cells merge). The patch test still holds, stabilised."""
    import cases3d

    dom = cnem.Domain3D(cases3d.tube_surface(0.4, 1.0, 1.0, 16))
    model = cnem.discretize(cnem.nodes.irregular(dom, 0.4, seed=1))
    prob = cnem.Elasticity(model, (E, NU), stabilization=1.0)
    faces, _ = prob.boundary_edges()
    on_boundary = np.zeros(len(model.nodes), dtype=bool)
    on_boundary[faces.ravel()] = True
    prob.add_dirichlet(on_boundary, None, lambda p: p @ A.T + B)
    sol = prob.solve(progress=False)
    np.testing.assert_allclose(sol.u, model.nodes @ A.T + B, atol=1e-12)
    np.testing.assert_allclose(sol.stress, np.broadcast_to(_exact_stress(), sol.stress.shape),
                               atol=1e-10 * np.abs(_exact_stress()).max())
    # the cells' vertices (VTU files, pictures) take the displacement inside the body
    vertices, _ = cnem.io.cell_points(model)
    nudge = cnem.config.VERTEX_NUDGE * np.abs(A).sum(axis=1).max() * 2.0     # diameter 2
    np.testing.assert_allclose(sol.vertex_displacement(), vertices @ A.T + B, atol=nudge + 1e-12)
