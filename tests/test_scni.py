"""SCNI smoothed gradients (`cnem.assembly.smoothed_gradient`, C-NEM eq. 26-32).

Checked against what must hold exactly: linear fields have their exact
gradient in every cell (the integration constraint that makes the patch test
pass), the cell sums equal the boundary integral of each shape function, the
quadrature converges as Gauss points are added, crack faces are seen from
their own side, and B~ is the slow cell-by-cell evaluation of eq. 31-32
(`reference.smoothed_gradient`) to round-off.
"""

from __future__ import annotations

import gc
import weakref

import numpy as np
import pytest
import scipy.sparse as sp

import cases
import reference
from cnem import config
from cnem.assembly import GradientCache, cell_edges, smoothed_gradient
from cnem.assembly.edges import circle_pieces

NAMES = cases.NAMES


def _boundary_integral(model):
    """∮ phi_j n over the domain boundary and crack faces, ``(n, 2)``: phi is linear
    on every boundary edge, so each end gets half the edge's ``n * length``."""
    from cnem.elasticity import Elasticity
    edges, normal = Elasticity(model, (1.0, 0.3)).boundary_edges()
    length = np.linalg.norm(model.nodes[edges[:, 1]] - model.nodes[edges[:, 0]], axis=1)
    out = np.zeros((len(model.nodes), 2))
    for k in range(2):
        np.add.at(out, edges[:, k], 0.5 * length[:, None] * normal)
    return out


@pytest.mark.parametrize("name", NAMES)
def test_linear_fields_have_exact_smoothed_gradients(name):
    _, _, model = cases.model(name)
    grad = smoothed_gradient(model)
    x, y = model.nodes.T
    scale = 1.0 / np.sqrt(model.cells.area.min())
    for field, gx, gy in [(1.0 + 0 * x, 0.0, 0.0), (x, 1.0, 0.0), (y, 0.0, 1.0),
                          (3.0 - 2.0 * x + 0.5 * y, -2.0, 0.5)]:
        np.testing.assert_allclose(grad.x @ field, gx, atol=1e-11 * scale)
        np.testing.assert_allclose(grad.y @ field, gy, atol=1e-11 * scale)


@pytest.mark.parametrize("name", NAMES)
def test_integration_constraint(name):
    """sum_k A_k b~_kj = ∮_Γ phi_j n dΓ: interior cell edges cancel (to the precision
    of the cell vertices, which two neighbouring cells may hold up to ~1e-12 apart)."""
    _, _, model = cases.model(name)
    grad = smoothed_gradient(model)
    area = model.cells.area
    lhs = np.column_stack([grad.x.T @ area, grad.y.T @ area])
    rhs = _boundary_integral(model)
    h = np.sqrt(area.mean())
    np.testing.assert_allclose(lhs, rhs, atol=1e-11 * h)


@pytest.mark.parametrize("name", ["square_irregular", "plate_hole_irregular",
                                  "three_rectangles_irregular", "kinked_crack_irregular",
                                  "graded_inclined_crack"])
def test_smoothed_gradient_is_the_cell_by_cell_reference(name):
    """B~ equals eq. 31-32 evaluated cell by cell (`reference.smoothed_gradient`: every
    edge cut at every circumcircle it crosses, crack faces and slits from their own
    side) to round-off: the distinct edges, the shared points and the passes change
    nothing but the summation order."""
    _, _, model = cases.model(name)
    gx, gy = reference.smoothed_gradient(model)
    grad = smoothed_gradient(model)
    scale = max(abs(gx).max(), abs(gy).max())
    np.testing.assert_allclose(grad.x.toarray(), gx, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(grad.y.toarray(), gy, rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize("name", ["square_irregular", "lshape_regular", "annulus_sector_regular",
                                  "edge_crack_regular", "graded_inclined_crack"])
def test_quadrature_converges(name):
    """b~ settles as Gauss points per edge piece are added (geometric convergence)."""
    _, _, model = cases.model(name)
    ref = smoothed_gradient(model, gauss=12)
    scale = abs(ref.x).max()
    errors = []
    for g in (1, 2, 4, 8):
        grad = smoothed_gradient(model, gauss=g)
        errors.append(max(abs(grad.x - ref.x).max(), abs(grad.y - ref.y).max()) / scale)
    assert all(b < a for a, b in zip(errors, errors[1:])), errors
    assert errors[-1] < 1e-5, errors
    assert errors[1] < 1e-2, errors


def test_edges_are_cut_at_circumcircles():
    """Between two pieces' ends no circumcircle is crossed: the pieces' ends include
    every crossing of the cell edges with the circumcircles (checked by brute force)."""
    _, _, model = cases.model("random_points")
    _, a, b = cell_edges(model.cells)
    edge, t0, t1 = circle_pieces(model, a, b)
    tri = model.triangles
    pick = np.random.default_rng(0).choice(len(a), 60, replace=False)
    for e in pick:
        ends = np.union1d(t0[edge == e], t1[edge == e])
        for s in np.linspace(0.0, 1.0, 41)[1:-1]:
            j = max(np.searchsorted(ends, s), 1)
            lo, hi = ends[j - 1], ends[j]
            inside = _in_circles(model.nodes, tri, a[e] + 0.5 * (lo + hi) * (b[e] - a[e]))
            for s2 in (lo + 1e-6 * (hi - lo), s, hi - 1e-6 * (hi - lo)):
                x2 = a[e] + s2 * (b[e] - a[e])
                assert (_in_circles(model.nodes, tri, x2) == inside).all()


@pytest.mark.parametrize("name", ["random_points", "kinked_crack_irregular"])
def test_one_query_per_cell_finds_the_same_pieces(name):
    """Candidate circles looked up once per cell (the box of its edges) give the
    pieces of one lookup per edge, exactly."""
    _, _, model = cases.model(name)
    cell, a, b = cell_edges(model.cells)
    for got, ref in zip(circle_pieces(model, a, b, group=cell), circle_pieces(model, a, b)):
        np.testing.assert_array_equal(got, ref)


def _cross(u, v):
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _in_circles(nodes, tri, x):
    """Whether ``x`` lies strictly inside each triangle's circumcircle (brute force)."""
    p = nodes[tri] - x
    sq = (p ** 2).sum(axis=2)
    det = (sq[:, 0] * _cross(p[:, 1], p[:, 2]) - sq[:, 1] * _cross(p[:, 0], p[:, 2])
           + sq[:, 2] * _cross(p[:, 0], p[:, 1]))
    return det > 0


@pytest.mark.parametrize("name", cases.CRACKED)
def test_crack_faces_do_not_see_each_other(name):
    """A cell on one crack face gets no gradient from nodes that only the other
    face can see: a field that jumps across the crack is smooth on each side."""
    dom, _, model = cases.model(name)
    grad = smoothed_gradient(model)
    cells = model.cells
    # cells whose node lies on a crack face: split nodes come in pairs with one cloud point
    counts = np.bincount(model.node_of_point)
    split = counts[model.node_of_point] == 2
    face_cells = np.flatnonzero(split[cells.node])
    assert face_cells.size > 0
    # field = 1 on the triangles' vertices of one face side... use the linear field on
    # every node: exact gradient holds cell by cell, which fails if a face saw across
    x = model.nodes[:, 0]
    np.testing.assert_allclose((grad.x @ x)[face_cells], 1.0, atol=1e-10 / np.sqrt(cells.area.min()))


def test_kept_by_their_owner_and_validated():
    """`GradientCache` computes B~ once and hands the same operator to every
    caller; it is the operator `smoothed_gradient` computes afresh."""
    _, _, model = cases.model("square_regular")
    gradients = GradientCache(model)
    kept = gradients.cells()
    assert gradients.cells() is kept and gradients.of(model.cells) is kept
    fresh = smoothed_gradient(model)
    assert fresh is not kept
    for a, b in ((fresh.x, kept.x), (fresh.y, kept.y)):
        np.testing.assert_array_equal(a.toarray(), b.toarray())
    with pytest.raises(ValueError, match="positive number of Gauss points"):
        smoothed_gradient(model, gauss=0)
    with pytest.raises(ValueError, match="positive number of Gauss points"):
        GradientCache(model, gauss=0)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["kinked_crack_irregular", "three_rectangles_irregular"])
def test_passes_over_runs_of_cells_give_the_same_operator(name, monkeypatch):
    """B~ built a few cells at a time (edges between runs integrated twice) is the
    one-pass B~ up to summation order."""
    _, _, model = cases.model(name)
    whole = smoothed_gradient(model, cells=model.cells)
    monkeypatch.setattr(config, "CELLS_PER_PASS", 7)
    runs = smoothed_gradient(model, cells=model.cells)
    for a, b in ((whole.x, runs.x), (whole.y, runs.y)):
        np.testing.assert_allclose(a.toarray(), b.toarray(), atol=1e-13 * abs(a).max())
    assert runs.points > whole.points


@pytest.mark.slow
@pytest.mark.parametrize("name", ["kinked_crack_irregular", "three_rectangles_irregular",
                                  "plate_hole_irregular", "edge_crack_regular"])
@pytest.mark.parametrize("per_pass", [None, 5])
@pytest.mark.parametrize("cells_cached", [False, True])
def test_fan_gradient_shares_the_cells_points(name, per_pass, cells_cached, monkeypatch):
    """The fan sub-cells' B~ and the cells' B~, computed together from one set of
    points (in one pass or many), equal each computed alone; with the cells' B~
    already kept only the sub-cells' is computed, and no second copy of it is made."""
    from cnem.assembly import gradients as owner
    from cnem.assembly.subdivision import subdivide, tip_cells
    _, _, model = cases.model(name)
    alone = smoothed_gradient(model, cells=model.cells)
    sub, _ = subdivide(model.cells, model.nodes, node_apex=tip_cells(model), mark_spokes=True)
    sub_alone = smoothed_gradient(model, cells=sub)
    if per_pass is not None:
        monkeypatch.setattr(config, "CELLS_PER_PASS", per_pass)
    gradients = GradientCache(model)
    kept = gradients.cells() if cells_cached else None
    computed = []                          # the cells' B~ computed on its own
    monkeypatch.setattr(owner, "smoothed_gradient",
                        lambda *a, **k: computed.append(1) or smoothed_gradient(*a, **k))
    with_cells, fan_gradients = [], owner._fan_gradients    # the cells' B~ computed with the fan's
    monkeypatch.setattr(owner, "_fan_gradients",
                        lambda *a, **k: with_cells.append(k["with_cells"]) or fan_gradients(*a, **k))
    fan_sub, fan = gradients.fan()
    np.testing.assert_array_equal(fan_sub.vertices, sub.vertices)
    together = gradients.cells()
    assert computed == [] and with_cells == [not cells_cached]
    assert (together is kept) == cells_cached
    assert gradients.fan()[1] is fan
    for a, b in ((alone.x, together.x), (alone.y, together.y),
                 (sub_alone.x, fan.x), (sub_alone.y, fan.y)):
        np.testing.assert_allclose(a.toarray(), b.toarray(), atol=1e-12 * abs(a).max())
    # the spokes add points; the edges shared with the cells do not
    assert alone.points < fan.points < alone.points + sub_alone.points
    # its last user takes it: the owner keeps no reference (the cells' B~ it keeps)
    assert gradients.fan(release=True)[1] is fan
    again = gradients.fan(release=True)[1]
    assert again is not fan and gradients.cells() is together and computed == []
    assert with_cells == [not cells_cached, False]
    np.testing.assert_allclose(again.x.toarray(), fan.x.toarray(), atol=1e-12 * abs(fan.x).max())
    released = weakref.ref(again)
    del again
    gc.collect()
    assert released() is None


@pytest.mark.slow
def test_runs_are_compact_blocks_whatever_the_order_of_the_nodes(monkeypatch):
    """Nodes in random order: the passes still take compact blocks of cells, so few
    edges lie between runs (runs of consecutive cells would share about 3/4 of
    them with other runs at four passes); B~ is the one-pass B~."""
    import cnem
    dom = cnem.geometry.rectangle(1.0, 1.0)
    pts = np.random.default_rng(3).uniform(0.01, 0.99, (3000, 2))
    model = cnem.discretize(cnem.nodes.from_points(dom, pts), progress=False)
    whole = smoothed_gradient(model, cells=model.cells)
    monkeypatch.setattr(config, "CELLS_PER_PASS", len(model.cells) // 4 + 1)
    runs = smoothed_gradient(model, cells=model.cells)
    assert whole.points < runs.points < 1.2 * whole.points
    for a, b in ((whole.x, runs.x), (whole.y, runs.y)):
        np.testing.assert_allclose(a.toarray(), b.toarray(), atol=1e-13 * abs(a).max())


def _fan_operators(quads, model):
    phi, order = quads[0].shape_functions(model)
    return [quad.cell_integrals(phi, rows=order) for quad in quads]


@pytest.mark.parametrize("name", [n for n in NAMES if n not in cases.CRACKED])
@pytest.mark.parametrize("node_apex", [False, True])
def test_fan_quadratures_take_the_sub_cells_edges_from_their_cells(name, node_apex):
    """The sub-cells' edges taken from where they come from (no search) give the
    points and the operators of the search by coordinates; fans from the cells'
    nodes put the apex on a vertex for boundary nodes, where a spoke is a cell
    edge: it is that edge (cut at the circles), not a spoke."""
    from cnem.assembly.subdivision import subdivide
    from cnem.assembly.edge_quadrature import boundary_quadratures
    from cnem.assembly.fan_quadrature import fan_quadratures
    _, _, model = cases.model(name)
    cells = model.cells
    sub, parent = subdivide(cells, model.nodes, node_apex=np.full(len(cells), node_apex),
                            mark_spokes=True)
    fast = fan_quadratures(model, cells, sub, parent)
    slow = boundary_quadratures(model, [cells, sub])
    assert len(fast[0].points) == len(slow[0].points)
    for f, s in zip(_fan_operators(fast, model), _fan_operators(slow, model)):
        for a, b in zip(f, s):
            np.testing.assert_allclose(a.toarray(), b.toarray(), rtol=0,
                                       atol=1e-13 * abs(b).max())
    # no spoke lies on a cell edge
    _, a, b = cell_edges(sub)
    spoke = sub.spokes
    _, ca, cb = cell_edges(cells)
    key = {tuple(np.r_[p, q]) for p, q in zip(ca, cb)}
    assert not any(tuple(np.r_[p, q]) in key or tuple(np.r_[q, p]) in key
                   for p, q in zip(a[spoke], b[spoke]))
    if node_apex:       # the case arose: apexes on a vertex of their cell
        apex = sub.vertices[sub.offsets[:-1]]
        on_vertex = [any((apex[s] == cells.polygon(c)).all(axis=1))
                     for s, c in enumerate(parent) if sub.spokes[sub.offsets[s]:sub.offsets[s + 1]].any()]
        assert any(on_vertex)


@pytest.mark.parametrize("name", ["edge_crack_regular", "three_rectangles_irregular"])
def test_edge_integrals_from_point_rows_or_a_matrix(name):
    """The edge integrals from the kernel's rows (`point_rows`) equal those from the
    shape-function matrix, and the cells' integrals from them equal the direct
    ``to_cells @ W @ Phi``."""
    from cnem.assembly.edge_quadrature import boundary_quadrature
    _, _, model = cases.model(name)
    quad = boundary_quadrature(model)
    phi, order = quad.shape_functions(model)
    ex, ey = quad.edge_integrals(phi, rows=order)
    rx, ry = quad.edge_integrals(quad.point_rows(model))
    for a, b in ((ex, rx), (ey, ry)):
        np.testing.assert_array_equal(a.toarray(), b.toarray())
    in_points = sp.csr_matrix(phi)[np.argsort(order)]
    for got, w in zip(quad.from_edges((rx, ry)), (quad.wx, quad.wy)):
        direct = (quad.to_cells @ w @ in_points).toarray()
        np.testing.assert_allclose(got.toarray(), direct, atol=1e-13 * abs(direct).max())
