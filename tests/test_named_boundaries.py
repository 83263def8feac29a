"""Named boundaries: the built-in shapes name their sides, files their groups; every problem
class takes a name as ``where`` and selects the same nodes and edges as the predicate
that describes the same place (nodes between polygon vertices included); unknown names
are listed; a bracket read from a file and solved with names gives the displacement of
the bracket built by hand and solved with predicates."""

from __future__ import annotations

import numpy as np
import pytest

import cnem
from cnem import pd
from cnem.fem import P1Elasticity
from geometry_files import WRITERS, by_hand, predicates

STEEL = (200.0, 0.3)


def sides(x0, y0, x1, y1, tol):
    return {"left": lambda x: np.abs(x[:, 0] - x0) < tol, "right": lambda x: np.abs(x[:, 0] - x1) < tol,
            "bottom": lambda x: np.abs(x[:, 1] - y0) < tol, "top": lambda x: np.abs(x[:, 1] - y1) < tol}


@pytest.mark.parametrize("scale, shift", [(1.0, 0.0), (1e-3, 1e6)])
def test_rectangle_sides_pick_the_nodes_between_the_corners(scale, shift):
    dom = cnem.geometry.rectangle(2.0 * scale, 1.0 * scale, origin=(shift, shift))
    assert dom.boundaries == ("left", "right", "bottom", "top")
    model = cnem.discretize(cnem.nodes.irregular(dom, 0.1 * scale, seed=2))
    whole = model.boundary_nodes()
    for name, where in sides(shift, shift, shift + 2 * scale, shift + scale, 1e-9 * scale).items():
        picked = model.boundary_nodes(name)
        assert np.array_equal(picked, np.flatnonzero(where(model.nodes)))
        assert len(picked) > 2                          # more than the two corners
        assert np.array_equal(model.boundary_nodes(where), picked)
    assert np.array_equal(np.unique(np.concatenate([model.boundary_nodes(n) for n in dom.boundaries])),
                          whole)


def test_hole_annulus_and_l_shape_names():
    plate = cnem.geometry.plate_with_hole(2.0, 1.0, 0.2, spacing=0.1)
    model = cnem.discretize(cnem.nodes.regular(plate, 0.04))
    centre = np.array([1.0, 0.5])
    near = model.boundary_nodes(lambda x: np.hypot(*(x - centre).T) < 0.21)
    hole = model.boundary_nodes("hole0")
    assert np.array_equal(hole, near)
    vertices = len(plate.regions[0].interiors[0].coords) - 1
    assert len(hole) > vertices                          # nodes along the chords too
    sector = cnem.geometry.annulus([1.0, 1.5, 2.0], angles=(0.0, np.pi / 2))
    assert set(sector.boundaries) == {"inner", "outer", "start", "stop"}
    points = np.array([[1.0, 0.0], [1.7, 0.0], [0.0, 1.7], [0.0, 2.0], [2.0, 0.0]])
    assert sector.on_boundary(points, "start").tolist() == [True, True, False, False, True]
    assert sector.on_boundary(points, "stop").tolist() == [False, False, True, True, False]
    assert sector.on_boundary(points, "outer").tolist() == [False, False, False, True, True]
    ring = cnem.geometry.annulus([1.0, 2.0])
    assert ring.boundaries == ("inner", "outer")
    ell = cnem.geometry.l_shape(1.0, 0.5)
    assert ell.on_boundary([[0.75, 0.5], [0.5, 0.75], [0.75, 0.75]], "cut").tolist() == \
        [True, True, False]


def test_unknown_names_are_listed_and_no_names_said():
    dom = cnem.geometry.rectangle(2.0, 1.0)
    model = cnem.discretize(cnem.nodes.regular(dom, 0.25))
    prob = cnem.Elasticity(model, STEEL)
    with pytest.raises(cnem.ConditionError, match="'clamp'.*'left', 'right', 'bottom', 'top'"):
        prob.add_dirichlet("clamp", None)
    with pytest.raises(cnem.ConditionError, match="'load'.*'left'"):
        prob.add_traction("load", [0.0, -1.0])
    with pytest.raises(cnem.ConditionError, match="'lft'.*'left'"):
        model.boundary_nodes("lft")
    bare = cnem.discretize(cnem.nodes.regular(cnem.Domain([[0, 0], [1, 0], [1, 1]]), 0.25))
    with pytest.raises(cnem.ConditionError, match="no named boundaries.*predicate"):
        cnem.Elasticity(bare, STEEL).add_dirichlet("left", None)


def test_names_off_the_boundary_are_refused():
    square = [[0, 0], [1, 0], [1, 1], [0, 1]]
    with pytest.raises(cnem.GeometryError, match="'middle'.*do not lie on the domain's boundary"):
        cnem.Domain(square, boundaries={"middle": [[0.5, 0.0], [0.5, 1.0]]})
    with pytest.raises(cnem.GeometryError, match="non-empty strings"):
        cnem.Domain(square, boundaries={3: [[0, 0], [1, 0]]})
    dom = cnem.Domain(square, boundaries={"base": [[0.25, 0.0], [0.75, 0.0]]})   # part of a side
    assert dom.on_boundary([[0.5, 0.0], [0.1, 0.0]], "base").tolist() == [True, False]


@pytest.mark.parametrize("polyline, where", [
    ([[0, 0], [1 + 1e-3j, 0]], r"boundaries\['base'\]: expected real numbers, received complex"),
    (np.ones((2, 2), dtype=bool), r"boundaries\['base'\]: expected real numbers, received bool"),
    ([[[0, 0], [1, 0]], [[1, 0], [1, 0.5], [1, 1j]]],      # ragged: the polyline is named
     r"boundaries\['base'\] polyline 1: expected real numbers, received complex")])
def test_named_coordinates_that_are_not_real_are_refused(polyline, where):
    """Complex coordinates lost their imaginary part (or raised a bare TypeError) and
    booleans became a zero-length segment at a corner."""
    square = [[0, 0], [1, 0], [1, 1], [0, 1]]
    with pytest.raises(cnem.GeometryError, match=where):
        cnem.Domain(square, boundaries={"base": polyline})


def test_traction_and_dirichlet_by_name_equal_predicates():
    dom = cnem.geometry.plate_with_hole(2.0, 1.0, 0.2)
    model = cnem.discretize(cnem.nodes.irregular(dom, 0.08, seed=3))
    named, by_predicate = cnem.Elasticity(model, STEEL), cnem.Elasticity(model, STEEL)
    named.add_dirichlet("left", None)
    named.add_traction("right", [1.0, 0.0])
    named.add_traction("hole0", lambda x, n: -0.5 * n)
    by_predicate.add_dirichlet(lambda x: x[:, 0] < 1e-9, None)
    by_predicate.add_traction(lambda x, n: x[:, 0] > 2 - 1e-9, [1.0, 0.0])
    by_predicate.add_traction(lambda x, n: np.hypot(x[:, 0] - 1, x[:, 1] - 0.5) < 0.21,
                              lambda x, n: -0.5 * n)
    for a, b in zip(named.tractions, by_predicate.tractions):
        assert np.array_equal(a.index, b.index)
    assert np.array_equal(named.prescribed()[0], by_predicate.prescribed()[0])
    sol_a, sol_b = named.solve(progress=False), by_predicate.solve(progress=False)
    assert np.array_equal(sol_a.u, sol_b.u)


@pytest.mark.parametrize("suffix", ["msh", "dxf", "geojson"])
def test_bracket_from_a_file_solved_by_names(tmp_path, suffix):
    """The same nodes on the bracket read from a file (names) and built by hand
    (predicates): the same displacement at a point to round-off."""
    hand = by_hand()
    cloud = cnem.nodes.irregular(hand, 0.2, seed=0)
    read = cnem.Domain.from_file(WRITERS[suffix](tmp_path / f"bracket.{suffix}"))
    models = [cnem.discretize(cloud), cnem.discretize(cnem.nodes.from_points(read, cloud.points))]
    assert np.abs(models[0].nodes - models[1].nodes).max() <= 1e-14 * hand.diameter
    where = predicates()
    u = []
    for model, select in zip(models, [where, None]):
        prob = cnem.Elasticity(model, STEEL)
        name = (lambda n: n) if select is None else (lambda n: select[n])
        edge = (lambda n: n) if select is None else (lambda n: lambda x, nrm: select[n](x))
        prob.add_dirichlet(name("clamp"), None)
        prob.add_traction(edge("load"), [0.0, -1.0])
        prob.add_traction(edge("hole"), lambda x, nrm: -0.2 * nrm)
        u.append(prob.solve(progress=False).displacement(np.array([[3.5, 0.5], [0.75, 2.5]])))
    assert np.abs(u[1] - u[0]).max() <= 1e-9 * np.abs(u[0]).max()
    assert np.abs(u[0][0, 1]) > 0                          # the load bends the arm


def test_p1_and_peridynamics_take_names():
    dom = cnem.geometry.rectangle(2.0, 1.0)
    p1 = P1Elasticity(dom, STEEL, max_area=0.02)
    p1.add_dirichlet("left", None)
    p1.add_traction("right", [1.0, 0.0])
    left = np.flatnonzero(p1.nodes[:, 0] < 1e-9)
    assert np.array_equal(p1.prescribed()[0], np.sort(np.concatenate([2 * left, 2 * left + 1])))
    edges, _ = p1.boundary_edges()
    right = np.flatnonzero((p1.nodes[edges, 0] > 2 - 1e-9).all(axis=1))
    assert np.array_equal(p1.tractions[0].index, right)
    cloud = cnem.nodes.regular(dom, 0.1)
    body = pd.Body.from_cloud(cloud)
    prob = pd.Problem(body, pd.BondBased(1.0))
    prob.add_dirichlet("left", 0)
    prob.add_velocity("right", 0, 1.0)
    assert np.array_equal(prob.prescribed()[0] // 2, np.flatnonzero(body.points[:, 0] < 1e-9))
    assert np.array_equal(prob.prescribed_velocity()[0] // 2,
                          np.flatnonzero(body.points[:, 0] > 2 - 1e-9))
    plain = pd.Problem(pd.Body(body.points, body.volumes, body.horizon), pd.BondBased(1.0))
    with pytest.raises(cnem.ConditionError, match="knows no domain.*Body.from_cloud"):
        plain.add_dirichlet("left", 0)


def test_names_survive_crack_growth_rebuild():
    from cnem.fracture.advance import rebuilt_domain
    dom = cnem.geometry.rectangle(2.0, 1.0, cracks=[[[0.0, 0.5], [0.5, 0.5]]])
    grown = rebuilt_domain(dom, [np.array([[0.0, 0.5], [0.5, 0.5], [0.7, 0.55]])])
    assert grown.boundaries == dom.boundaries
    model = cnem.discretize(cnem.nodes.regular(grown, 0.1))
    left = model.boundary_nodes("left")
    assert np.array_equal(left, np.flatnonzero(model.nodes[:, 0] < 1e-9))
    assert np.count_nonzero(np.all(model.nodes[left] == [0.0, 0.5], axis=1)) == 2   # the mouth, both faces


@pytest.mark.parametrize("suffix", ["msh", "dxf", "geojson"])
def test_file_names_pick_the_same_nodes_moved_and_scaled(tmp_path, suffix):
    """The file's coordinates moved by 1e6 and scaled by 1e-3: each name still picks the
    nodes its predicate picks, and the same ones as at the origin in unit scale."""
    picked = []
    for scale, shift in [(1.0, 0.0), (1e-3, 1e6)]:
        cloud = cnem.nodes.irregular(by_hand(scale, shift), 0.2 * scale, seed=0)
        read = cnem.Domain.from_file(WRITERS[suffix](tmp_path / f"b{scale}.{suffix}", scale, shift))
        model = cnem.discretize(cnem.nodes.from_points(read, cloud.points))
        where = predicates(scale, shift)
        names = {n: model.boundary_nodes(n) for n in ("clamp", "load", "hole")}
        for name, nodes in names.items():
            assert np.array_equal(nodes, np.flatnonzero(where[name](model.nodes))), name
        picked.append(names)
    for name in picked[0]:
        assert np.array_equal(picked[0][name], picked[1][name]), name


def test_get_dofs_takes_the_whole_boundary_or_a_name():
    """`CellBasis.get_dofs()` with no predicate means the whole boundary (what a
    scikit-fem user expects), and a boundary name means that boundary's nodes."""
    dom = cnem.geometry.rectangle(1.0, 1.0)
    model = cnem.discretize(cnem.nodes.regular(dom, 0.25))
    basis = cnem.assembly.CellBasis(model)
    x, y = model.nodes.T
    edge = (np.isclose(x, 0) | np.isclose(x, 1) | np.isclose(y, 0) | np.isclose(y, 1))
    np.testing.assert_array_equal(basis.get_dofs(), np.flatnonzero(edge))
    np.testing.assert_array_equal(basis.get_dofs("left"), np.flatnonzero(np.isclose(x, 0)))
