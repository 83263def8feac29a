"""Properties of cells, shape functions, families and SCNI on random domains, at any origin, in any units.

Hypothesis draws a star-shaped outline, optionally a hole or an inclusion (a second region:
its boundary is an interface), optionally a straight or kinked crack strictly inside, a node
spacing and a seed for an irregular cloud, and a similarity ``x -> s (R x + t)`` (a rotation,
a translation by 0 or 1e6 model sizes, a scale 1e-6, 1 or 1e6). The cloud built on the drawn
domain is mapped with it (`cnem.nodes.from_points`). Each property is checked on the mapped
model, and its results mapped back are compared with those of the original, to a tolerance
that grows with the round-off of the mapped coordinates (``eps * |t|`` relative: 2e-10 at
1e6 sizes). Profiles: tests/conftest.py (``--hypothesis-profile=thorough`` for more cases).
"""

from __future__ import annotations

import numpy as np
import shapely
from hypothesis import example, given, strategies as st

import reference
import cnem
from cnem.geometry import SegmentKind
from cnem.spatial import family_search

EPS = np.finfo(float).eps


def star(radii, jitter=None):
    """A star-shaped polygon: vertex ``i`` at angle ``2 pi (i + jitter_i) / k``, radius ``radii[i]``."""
    k = len(radii)
    angles = 2 * np.pi * (np.arange(k) + (0.0 if jitter is None else np.array(jitter))) / k
    return np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])


def turned(angle, far=0.0, direction=0.0, scale=1.0):
    """A similarity as `similarities` draws it."""
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    return rot, far * np.array([np.cos(direction), np.sin(direction)]), scale


def problem(shell, inner="none", r_in=0.2, phase=0.0, crack="none", theta=0.0, turn=0.0,
            h=0.1, seed=0):
    """``(regions, cracks, h, seed)``: outline ``shell``, optionally (``inner``: "hole" or
    "inclusion") a 10-gon of radius ``r_in`` turned by ``phase``, optionally (``crack``:
    "straight" or "kinked") a crack from ``0.32 (cos theta, sin theta)`` along the circle's
    tangent, 0.24 long, its second half turned by ``turn``."""
    ring = np.linspace(0.0, 2 * np.pi, 10, endpoint=False) + phase
    inner_ring = np.column_stack([r_in * np.cos(ring), r_in * np.sin(ring)])
    if inner == "none":
        regions = [shell]
    elif inner == "hole":
        regions = [(shell, [inner_ring])]
    else:
        regions = [(shell, [inner_ring]), inner_ring]
    cracks = []
    if crack != "none":
        start = 0.32 * np.array([np.cos(theta), np.sin(theta)])
        along = np.array([-np.sin(theta), np.cos(theta)])
        middle = start + 0.12 * along
        bend = np.array([np.cos(turn) * along[0] - np.sin(turn) * along[1],
                         np.sin(turn) * along[0] + np.cos(turn) * along[1]])
        end = middle + 0.12 * bend
        cracks = [np.array([start, end]) if crack == "straight" else np.array([start, middle, end])]
    return regions, cracks, h, seed


@st.composite
def problems(draw):
    """``(regions, cracks, h, seed)`` of a random valid domain about the origin (diameter ~2)."""
    k = draw(st.integers(6, 9))
    jitter = draw(st.lists(st.floats(-0.25, 0.25), min_size=k, max_size=k))
    shell = star(draw(st.lists(st.floats(0.8, 1.0), min_size=k, max_size=k)), jitter)
    inner = draw(st.sampled_from(["none", "hole", "inclusion"]))
    r_in, phase = draw(st.floats(0.15, 0.22)), draw(st.floats(0.0, 1.0))
    crack = draw(st.sampled_from(["none", "straight", "kinked"]))
    theta = draw(st.floats(0.0, 2 * np.pi)) if crack != "none" else 0.0
    turn = draw(st.floats(-0.5, 0.5)) if crack == "kinked" else 0.0
    h = draw(st.floats(0.1, 0.15))      # at most the inner ring's radius: nodes inside it
    return problem(shell, inner, r_in, phase, crack, theta, turn, h, draw(st.integers(0, 2 ** 16)))


@st.composite
def similarities(draw):
    """``(rotation (2, 2), translation (2,), scale)`` of ``x -> s (R x + t)``."""
    return turned(draw(st.floats(0.0, 2 * np.pi)), draw(st.sampled_from([0.0, 1e6])),
                  draw(st.floats(0.0, 2 * np.pi)), draw(st.sampled_from([1e-6, 1.0, 1e6])))


class Mapped:
    """The drawn problem and its image under a similarity."""

    def __init__(self, problem, similarity):
        regions, cracks, h, seed = problem
        self.rot, self.shift, self.scale = similarity
        self.h = h
        self.domain = cnem.Domain(regions, cracks=cracks)
        self.cloud = cnem.nodes.irregular(self.domain, h, seed=seed)
        self.mapped_domain = cnem.Domain(self._map_regions(regions),
                                         cracks=[self.forward(c) for c in cracks])
        self.mapped_cloud = cnem.nodes.from_points(self.mapped_domain,
                                                   self.forward(self.cloud.points))
        #: relative round-off of the mapped coordinates (and a floor for the rest)
        self.tol = 1e-10 + 1e4 * EPS * np.abs(self.shift).max()

    def forward(self, x):
        return self.scale * (np.asarray(x, dtype=float) @ self.rot.T + self.shift)

    def back(self, x):
        return (np.asarray(x, dtype=float) / self.scale - self.shift) @ self.rot

    def _map_regions(self, regions):
        out = []
        for r in regions:
            if isinstance(r, tuple):
                out.append((self.forward(r[0]), [self.forward(hole) for hole in r[1]]))
            else:
                out.append(self.forward(r))
        return out

    def models(self):
        return (cnem.discretize(self.cloud, progress=False),
                cnem.discretize(self.mapped_cloud, progress=False))


def _inside(domain, count, seed):
    """``count`` random points of the domain, away from its constraints by 1e-6 of its size."""
    rng = np.random.default_rng(seed)
    x0, y0, x1, y1 = domain.bounds
    pts = np.column_stack([rng.uniform(x0, x1, 4 * count), rng.uniform(y0, y1, 4 * count)])
    lines = shapely.union_all([shapely.LineString(c) for c in domain.cracks]
                              + [r.boundary for r in domain.regions])
    keep = domain.contains(pts) & (shapely.distance(shapely.points(pts), lines)
                                   > 1e-6 * domain.diameter)
    return pts[keep][:count]


def _base_node(case, base, mapped):
    """``(n,)``: the node of ``base`` that each node of ``mapped`` is (the same cloud point;
    for the two copies of a crack-face point, the one on the same face: which copy gets
    which index is not part of the contract)."""
    sides, mapped_sides = base.node_sides(), case.back(mapped.node_sides())
    match = np.empty(len(mapped.nodes), dtype=np.int64)
    for j, point in enumerate(mapped.node_of_point):
        copies = np.flatnonzero(base.node_of_point == point)
        match[j] = copies[np.argmin(np.hypot(*(sides[copies] - mapped_sides[j]).T))]
    assert np.array_equal(np.sort(match), np.arange(len(base.nodes)))
    return match


def _cell_areas(model, node=None):
    """Cell areas keyed by (node, region), ``node`` renumbering the nodes."""
    c = model.cells
    owner = c.node if node is None else node[c.node]
    return {(int(n), int(r)): a for n, r, a in zip(owner, c.region, c.area)}


#: Two domains where the union of the shadows that a boundary node's constraint edges cast
#: (rays from the node through the ends of adjacent edges, one shared ray apiece) lost
#: a whole shadow in GEOS 3.14 without a snapping grid, so the node's cell kept a piece
#: behind a boundary edge and was refused as "not connected" (hypothesis, thorough
#: profile, shrunk): a hexagon scaled by 1e-6, and a heptagon with a hole and a crack
#: (whose cloud at the origin already failed) moved by 1e6 sizes and scaled by 1e-6.
SCALED_HEXAGON = (problem(star([0.80078125, 0.875, 1.0, 0.80078125, 0.8046875, 0.8],
                               [0.0, 0.0, -0.25, 0.25, -0.25, -0.228515625]), h=0.1, seed=6),
                  turned(0.0, 0.0, 0.0, 1e-6))
MOVED_HOLE_AND_CRACK = (problem(star([1.0, 1.0, 1.0, 1.0, 1.0, 0.875, 0.9375]), "hole",
                                0.1875, 0.0, "straight", 0.0, h=0.1, seed=3),
                        turned(0.0, 1e6, 0.0, 1e-6))


@example(*SCALED_HEXAGON)
@example(*MOVED_HOLE_AND_CRACK)
@given(problems(), similarities())
def test_cells_partition_the_domain_at_any_origin_and_scale(problem, similarity):
    case = Mapped(problem, similarity)
    base, mapped = case.models()
    for model, dom in ((base, case.domain), (mapped, case.mapped_domain)):
        cells = model.cells
        assert abs(cells.area.sum() - dom.area) <= 1e-10 * dom.area
        assert (cells.area > 0).all()
    a, b = _cell_areas(base), _cell_areas(mapped, _base_node(case, base, mapped))
    assert a.keys() == b.keys()
    ref = np.array([a[k] for k in a])
    got = np.array([b[k] for k in a]) / case.scale ** 2
    assert np.abs(got - ref).max() <= case.tol * case.h ** 2 * 1e2


#: A regular-ish hexagon moved by 1e6 sizes and scaled by 1e-6, where a cell of a boundary
#: node once folded back along a boundary edge (shapely: "Ring Self-intersection") when
#: the local frame's origin was the box's centre: an example always run.
FOLDED_CELL = (([star([1.0, 1.0, 1.0, 1.0, 1.0, 0.875])], [], 0.12109375, 0),
               turned(0.0, 1e6, 2.0, 1e-6))


#: A regular hexagon with an inclusion and a crack moved by 1e6 sizes: cells kept
#: clusters of vertices closer than the coordinates' round-off, which folded once
#: mapped back (shapely: "Self-intersection"); an example always run.
ROUNDOFF_CLUSTER = (problem(star(np.ones(6)), "inclusion", 0.15625, 0.0, "kinked", 0.0, 0.0,
                            h=0.140625, seed=0),
                    turned(0.0, 1e6, 0.0, 1.0))


@example(*FOLDED_CELL)
@example(*ROUNDOFF_CLUSTER)
@given(problems(), similarities())
def test_cells_are_valid_polygons(problem, similarity):
    case = Mapped(problem, similarity)
    for model in case.models():
        cells = model.cells
        polys = np.array([shapely.Polygon(cells.polygon(i)) for i in range(len(cells))])
        invalid = np.flatnonzero(~shapely.is_valid(polys))
        assert invalid.size == 0, [shapely.is_valid_reason(polys[i]) for i in invalid[:3]]


@given(problems(), similarities())
def test_shape_functions_are_consistent_and_invariant(problem, similarity):
    case = Mapped(problem, similarity)
    base, mapped = case.models()
    queries = _inside(case.domain, 200, seed=len(base.nodes))
    phi = base.shape_functions(queries)
    phi_m = mapped.shape_functions(case.forward(queries))
    for model, p, x, size in ((base, phi, queries, case.domain.diameter),
                              (mapped, phi_m, case.forward(queries), case.mapped_domain.diameter)):
        assert np.abs(np.asarray(p.sum(axis=1)).ravel() - 1.0).max() < 1e-12
        assert p.min() >= -1e-12
        assert np.abs(p @ model.nodes - x).max() <= 1e-11 * size + 64 * EPS * np.abs(x).max()
        # Kronecker delta at the nodes not split by a crack
        single = np.flatnonzero(np.bincount(model.node_of_point)[model.node_of_point] == 1)
        at = model.shape_functions(model.nodes[single])
        assert np.array_equal(at.indices, single) and np.allclose(at.data, 1.0, rtol=0, atol=0)
    columns = _base_node(case, base, mapped)
    assert abs(phi_m[:, np.argsort(columns)] - phi).max() <= case.tol * 1e3


@given(problems(), similarities(), st.floats(1.6, 3.2))
def test_family_search_equals_brute_force_at_any_origin_and_scale(problem, similarity, factor):
    case = Mapped(problem, similarity)
    points = case.mapped_cloud.points
    fam = family_search(points, factor * case.h * case.scale)
    ref = reference.brute_family(points, factor * case.h * case.scale)
    assert reference.csr_row_differences(fam.offsets, fam.indices, *ref) == []
    base = family_search(case.cloud.points, factor * case.h)
    assert reference.csr_row_differences(fam.offsets, fam.indices, base.offsets,
                                         base.indices) == []


@given(problems(), similarities())
def test_scni_patch_test_at_any_origin_and_scale(problem, similarity):
    """A linear displacement imposed on every boundary and crack-face node is reproduced at
    every node (one material everywhere: the interface stays a constraint of the shape
    functions), and the solution mapped back is the original's."""
    case = Mapped(problem, similarity)
    grad = np.array([[1e-3, 2e-3], [-5e-4, 1.5e-3]])

    def field(x_original):
        return np.array([1e-3, -2e-3]) + x_original @ grad.T

    solutions = []
    models = case.models()
    for model, to_original, to_model in ((models[0], lambda x: x, lambda u: u),
                                         (models[1], case.back,
                                          lambda u: case.scale * u @ case.rot.T)):
        prob = cnem.Elasticity(model, [(1.0, 0.3)] * len(model.domain.regions), plane="stress")
        fixed = np.unique(model.segments[model.segment_kind != SegmentKind.INTERFACE])
        target = to_model(field(to_original(model.nodes)))
        prob.add_dirichlet(fixed, None, lambda p: target[fixed])
        u = prob.solve(progress=False).u
        err = np.abs(u - target).max() / np.abs(target).max()
        assert err < 1e-9 + case.tol * 1e3, f"patch test error {err:.2e}"
        solutions.append(u)
    back = (solutions[1] @ case.rot / case.scale)[np.argsort(_base_node(case, *models))]
    assert np.abs(back - solutions[0]).max() <= (1e-9 + case.tol * 1e3) * np.abs(solutions[0]).max()


def test_strategies_draw_valid_domains():
    """The drawn domains are what the properties claim to cover (cracks strictly inside)."""
    @given(problems())
    def check(problem):
        regions, cracks, _, _ = problem
        dom = cnem.Domain(regions, cracks=cracks)
        assert len(dom.tips) == 2 * len(cracks)
    check()
