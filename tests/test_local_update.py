"""The local update after crack growth equals `discretize` of the same cloud from scratch.

Each case grows a crack by appending straight segments to its polyline (the new
vertex becomes a node through `cnem.nodes.from_points`), updates the model, B~
and K locally step after step, and compares them with a fresh `discretize` and
a fresh `Elasticity` of the same cloud: the same nodes, triangles, segments and
cells, and B~ and K to 1e-12 relative. It also checks that the update is local:
every recomputed cell belongs to a node near the new segments.
"""

import numpy as np
import pytest
import shapely

import cnem
from cnem.assembly.gradient_update import updated_gradient
from cnem.errors import CNEMError, GeometryError
from cnem.geometry.model_update import update

TOL = 1e-12
SQUARE = [[0.0, 0.0], [1.0, 0.0], [1.0, 2.0], [0.0, 2.0]]
LEFT = [[0.0, 0.0], [0.5, 0.0], [0.5, 2.0], [0.0, 2.0]]
RIGHT = [[0.5, 0.0], [1.0, 0.0], [1.0, 2.0], [0.5, 2.0]]


def _transform(points, scale, offset):
    return np.asarray(points, dtype=float) * scale + offset


def _grown(domain, crack, vertex, at_start=False):
    """``domain`` with ``vertex`` appended to (or put before) crack ``crack``."""
    cracks = [np.asarray(c) for c in domain.cracks]
    c = cracks[crack]
    cracks[crack] = np.vstack([[vertex], c]) if at_start else np.vstack([c, [vertex]])
    regions = [shapely.Polygon(r.exterior.coords, [h.coords for h in r.interiors])
               for r in domain.regions]
    return cnem.Domain(regions, cracks=cracks)


def _problem(model):
    prob = cnem.Elasticity(model, [(1.0, 0.3), (3.0, 0.25)][:len(model.domain.regions)],
                           plane="strain")
    return prob


def _rotated_max(p, q):
    """Largest vertex distance between two polygons, ``q`` rotated to start where ``p`` does."""
    k = int(np.argmin(np.abs(q - p[0]).sum(axis=1)))
    return np.abs(np.roll(q, -k, axis=0) - p).max()


def _relative(a, b):
    return abs(a - b).max() / abs(b).max()


def _assert_equal_models(got, ref):
    assert np.array_equal(got.nodes, ref.nodes)
    assert np.array_equal(got.node_of_point, ref.node_of_point)
    assert np.array_equal(got.triangles, ref.triangles)
    assert np.array_equal(got.triangle_region, ref.triangle_region)
    assert np.array_equal(got.segments, ref.segments)
    assert np.array_equal(got.segment_kind, ref.segment_kind)
    gc, rc = got.cells, ref.cells
    assert np.array_equal(gc.node, rc.node) and np.array_equal(gc.region, rc.region)
    assert np.array_equal(gc.offsets, rc.offsets)
    size = ref.domain.diameter
    np.testing.assert_allclose(gc.area, rc.area, rtol=0, atol=TOL * size ** 2)
    worst = max(_rotated_max(gc.polygon(c), rc.polygon(c)) for c in range(len(rc)))
    # far from the origin a vertex is known to a few units in the last place
    assert worst <= TOL * size + 4 * np.spacing(np.abs(ref.nodes).max())


def _grow_and_compare(domain, cloud, steps, *, edit=None, operators=True):
    """Grow ``domain`` by ``steps`` (``(crack, vertex, at_start)``), updating locally
    (B~ and K too, unless not ``operators``)."""
    model = cnem.discretize(cloud, progress=False)
    prob = _problem(model)
    if operators:
        prob.stiffness()
    h = float(np.median(cloud.spacing))
    for k, (crack, vertex, at_start) in enumerate(steps):
        tip = np.asarray(domain.cracks[crack][0 if at_start else -1])
        domain = _grown(domain, crack, vertex, at_start)
        points = cloud.points if edit is None else edit(cloud.points, tip, np.asarray(vertex), h)
        cloud = cnem.nodes.from_points(domain, points)
        change = update(model, cloud)
        ref = cnem.discretize(cloud, progress=False)
        _assert_equal_models(change.model, ref)
        # local: the recomputed cells' nodes lie near the new segment
        seg = shapely.LineString([tip, vertex])
        owners = change.model.nodes[change.model.cells.node[change.changed_cells]]
        far = shapely.distance(shapely.points(owners), seg).max()
        assert far < 12 * h, f"step {k}: a recomputed cell {far / h:.1f} spacings from the change"
        assert len(change.changed_cells) < 0.5 * len(ref.cells)
        model = change.model
        if not operators:
            continue
        new = _problem(change.model).update_from(prob, change)
        fresh = _problem(ref)
        assert _relative(new.basis.grad.x, fresh.basis.grad.x) < TOL
        assert _relative(new.basis.grad.y, fresh.basis.grad.y) < TOL
        assert _relative(new.stiffness(), fresh.stiffness()) < TOL
        prob = new
    return model


def _steps(tip, direction, length, count, kink=0.0, crack=0, at_start=False):
    """``count`` straight segments of ``length`` from ``tip``, turning by ``kink`` each."""
    out, x, angle = [], np.asarray(tip, dtype=float), np.arctan2(direction[1], direction[0])
    for _ in range(count):
        angle += kink
        x = x + length * np.array([np.cos(angle), np.sin(angle)])
        out.append((crack, x.copy(), at_start))
    return out


def _offset_case(scale, offset):
    crack = _transform([[0.3, 1.0], [0.6, 1.05]], scale, offset)
    dom = cnem.Domain([_transform(SQUARE, scale, offset)], cracks=[crack])
    h = 0.06 * scale
    return dom, cnem.nodes.irregular(dom, h, seed=1), _steps(crack[-1], crack[-1] - crack[0],
                                                              1.3 * h, 2)


@pytest.mark.parametrize("scale, offset", [(1.0, 0.0), (1e-3, 0.0), (1e3, -5e3)])
def test_internal_crack_two_steps_equals_discretize(scale, offset):
    _grow_and_compare(*_offset_case(scale, offset))


def test_offset_1e6_model_equals_discretize():
    """Far from the origin: the model (B~ and K of the update and of a fresh model differ
    there by the round-off of the assembly's global coordinates, ~5e-10)."""
    _grow_and_compare(*_offset_case(1.0, 1e6), operators=False)


def test_offset_1e6_stiffness():
    """The stiffness of the origin's cloud moved by 1e6 is the origin's, to the
    round-off of the moved coordinates (eps * 1e6 / diameter ~ 1e-10)."""
    _, cloud, _ = _offset_case(1.0, 0.0)
    dom, _, _ = _offset_case(1.0, 1e6)
    moved = cnem.nodes.from_points(dom, cloud.points + 1e6)
    far = _problem(cnem.discretize(moved, progress=False)).stiffness()
    near = _problem(cnem.discretize(cloud, progress=False)).stiffness()
    assert _relative(far, near) < 1e-8


@pytest.mark.slow
def test_internal_crack_both_tips_kinked_several_steps():
    crack = [[0.35, 0.9], [0.55, 1.0]]
    dom = cnem.Domain([SQUARE], cracks=[crack])
    h = 0.05
    cloud = cnem.nodes.irregular(dom, h, seed=2)
    ahead = _steps(crack[-1], [1.0, 0.5], 1.1 * h, 3, kink=0.2)
    behind = _steps(crack[0], [-1.0, -0.5], 1.1 * h, 2, kink=-0.3, at_start=True)
    _grow_and_compare(dom, cloud, [ahead[0], behind[0], ahead[1], behind[1], ahead[2]])


@pytest.mark.slow
@pytest.mark.parametrize("kink", [0.0, 0.25])
def test_edge_crack_regular_cloud_several_steps(kink):
    crack = [[0.0, 1.0], [0.3, 1.0]]
    dom = cnem.Domain([SQUARE], cracks=[crack])
    h = 0.05
    cloud = cnem.nodes.regular(dom, h)
    # a lattice: the vertices fall between nodes, off the cocircular quads' diagonals
    _grow_and_compare(dom, cloud, _steps([0.3, 1.0], [1.0, 0.0], 1.37 * h, 3, kink=kink))


@pytest.mark.slow
def test_two_regions():
    crack = [[0.1, 0.8], [0.3, 0.9]]
    dom = cnem.Domain([LEFT, RIGHT], cracks=[crack])
    h = 0.05
    cloud = cnem.nodes.irregular(dom, h, seed=3)
    _grow_and_compare(dom, cloud, _steps(crack[-1], [1.0, 0.5], 1.2 * h, 2))


def test_points_moved_removed_and_added_near_the_tip():
    """A refinement ring follows the tip: nodes near the old tip go, nodes near the new come."""
    crack = [[0.0, 1.0], [0.4, 1.02]]
    dom = cnem.Domain([SQUARE], cracks=[crack])
    h = 0.05

    def edit(points, tip, vertex, h):
        d = np.linalg.norm(points - tip, axis=1)
        near = np.flatnonzero((d > 0.2 * h) & (d < 1.2 * h))
        keep = np.ones(len(points), dtype=bool)
        keep[near[:2]] = False                                  # two removed
        points = points[keep].copy()
        d = np.linalg.norm(points - tip, axis=1)
        moved = np.flatnonzero((d > 0.8 * h) & (d < 1.5 * h))[:1]
        points[moved] += 0.1 * h                                  # one moved
        angle = np.array([0.8, 1.9, 2.7, 4.2, 5.4])       # off the crack, ahead and behind
        ring = vertex + 0.45 * h * np.column_stack([np.cos(angle),
                                                    np.sin(angle)])
        return np.vstack([points, ring])                         # five added

    cloud = cnem.nodes.irregular(dom, h, seed=4)
    _grow_and_compare(dom, cloud, _steps(crack[-1], [1.0, 0.05], 1.5 * h, 2, kink=0.1), edit=edit)


def test_update_rejects_wrong_input():
    dom = cnem.Domain([SQUARE], cracks=[[[0.0, 1.0], [0.3, 1.0]]])
    cloud = cnem.nodes.irregular(dom, 0.1, seed=0)
    model = cnem.discretize(cloud, progress=False)
    with pytest.raises(GeometryError, match="old Model"):
        update(cloud, cloud)
    with pytest.raises(GeometryError, match="NodeCloud"):
        update(model, cloud.points)
    change = update(model, cloud)
    assert len(change.changed_cells) == 0          # nothing changed: every cell copied
    with pytest.raises(CNEMError, match="smoothed gradient of the old model"):
        grad = _problem(model).basis.grad
        small = type(grad)(grad.x[:-1], grad.y[:-1], 0)
        updated_gradient(small, change)
    other = cnem.Elasticity(change.model, (2.0, 0.3), plane="strain")
    with pytest.raises(CNEMError, match="differ in materials"):
        other.update_from(_problem(model), change)
