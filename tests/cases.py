"""Shared catalogue of geometry cases for the test suite.

Each case is a function returning ``(domain, cloud)``; `CASES` maps names to
them and `model(name)` discretises a case once per session (cached).
Cases are small (100-900 nodes) so the suite stays fast, but they cover the
degenerate situations the geometry layer must handle: cocircular lattices,
collinear boundary nodes, reflex corners, holes, interfaces, edge and
internal (kinked) cracks, graded clouds and the user's own random points.
"""

from __future__ import annotations

import functools

import numpy as np
from skfem import condense

import cnem
from cnem import geometry, nodes
from cnem.solvers import linsolve

#: Edge crack of the square (ends on the boundary at x = 0, tip at (0.5, 0.5)).
EDGE_CRACK = [[0.0, 0.5], [0.5, 0.5]]
#: Kinked internal crack (two tips).
KINKED_CRACK = [[0.2, 0.3], [0.5, 0.5], [0.8, 0.45]]
#: Three regions whose shared boundaries have different vertices on each side.
THREE_RECTANGLES = [
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
    [[1.0, 0.0], [2.0, 0.0], [2.0, 0.5], [1.0, 0.5]],
    [[1.0, 0.5], [1.3, 0.5], [2.0, 0.5], [2.0, 1.0], [1.0, 1.0]],
]
#: Inclined internal crack (two tips) for the graded cloud.
INCLINED_CRACK = [[0.3, 0.35], [0.7, 0.62]]


def square_regular():
    dom = geometry.rectangle(1.0, 1.0)
    return dom, nodes.regular(dom, 0.08)


def square_irregular():
    dom = geometry.rectangle(1.0, 1.0)
    return dom, nodes.irregular(dom, 0.07, seed=3)


def lshape_regular():
    dom = geometry.l_shape(1.0, 0.5)
    return dom, nodes.regular(dom, 0.0625)


def lshape_irregular():
    dom = geometry.l_shape(1.0, 0.4)
    return dom, nodes.irregular(dom, 0.06, seed=7)


def plate_hole_irregular():
    dom = geometry.plate_with_hole(1.0, 1.0, 0.2, spacing=0.05)
    return dom, nodes.irregular(dom, 0.06, seed=11)


def annulus_full_irregular():
    dom = geometry.annulus([1.0, 1.5, 2.0], spacing=0.15)
    return dom, nodes.irregular(dom, 0.15, seed=5)


def annulus_sector_regular():
    dom = geometry.annulus([1.0, 1.5, 2.0], angles=(0.0, np.pi / 2), spacing=0.1)
    return dom, nodes.regular(dom, 0.1)


def edge_crack_regular():
    # crack on lattice lines: many cocircular quadruples along the crack
    dom = geometry.rectangle(1.0, 1.0, cracks=[EDGE_CRACK])
    return dom, nodes.regular(dom, 0.05)


def kinked_crack_irregular():
    dom = geometry.rectangle(1.0, 1.0, cracks=[KINKED_CRACK])
    return dom, nodes.irregular(dom, 0.06, seed=2)


def graded_inclined_crack():
    dom = geometry.rectangle(1.0, 1.0, cracks=[INCLINED_CRACK])
    return dom, nodes.graded(dom, 0.1, near=dom.tips, h_min=0.02, growth=0.3, seed=1)


def three_rectangles_irregular():
    # interfaces given with different vertices on each side: (1, 0.5) and
    # (1.3, 0.5) lie inside edges of the other regions; (1, 0.5) is a triple point
    dom = cnem.Domain(THREE_RECTANGLES)
    return dom, nodes.irregular(dom, 0.07, seed=4)


#: Points put exactly on the boundary of the unit square by `random_points`.
RANDOM_ON_BOUNDARY = np.array([[0.3, 0.0], [0.71, 0.0], [1.0, 0.45], [0.5, 1.0],
                               [0.0, 0.62], [0.0, 0.2]])


def random_points():
    dom = geometry.rectangle(1.0, 1.0)
    rng = np.random.default_rng(1234)
    pts = rng.uniform(0.02, 0.98, (250, 2))
    pts = np.concatenate([pts, RANDOM_ON_BOUNDARY])
    return dom, nodes.from_points(dom, pts)


CASES = {f.__name__: f for f in [
    square_regular, square_irregular, lshape_regular, lshape_irregular,
    plate_hole_irregular, annulus_full_irregular, annulus_sector_regular,
    three_rectangles_irregular, edge_crack_regular, kinked_crack_irregular,
    graded_inclined_crack, random_points,
]}

NAMES = list(CASES)
#: Cases with cracks, and with material interfaces.
CRACKED = ["edge_crack_regular", "kinked_crack_irregular", "graded_inclined_crack"]
INTERFACES = ["annulus_full_irregular", "annulus_sector_regular", "three_rectangles_irregular"]


@functools.lru_cache(maxsize=None)
def case(name):
    """``(domain, cloud)`` of a case, built once."""
    return CASES[name]()


@functools.lru_cache(maxsize=None)
def model(name):
    """``(domain, cloud, model)`` of a case, discretised once."""
    dom, cloud = case(name)
    return dom, cloud, cnem.discretize(cloud, progress=False)


def enriched_centre_crack_system(h, radius=0.1):
    """The condensed system of the centre-cracked square ``[-0.5, 0.5]^2`` (crack from
    (-0.1, 0) to (0.1, 0)), branch-enriched within ``radius`` of the tips, E = 1, nu = 0.3,
    clamped at the bottom and pulled to v = 1e-3 at the top, on a regular cloud of spacing
    ``h`` (used by ``tests/test_errors_solve.py`` and ``benchmarks/enriched_solve.py``).

    Returns
    -------
    A : (k, k) scipy.sparse.csr_matrix
        The stiffness on the free dofs.
    b : (k,) ndarray
    nodal : (k,) bool ndarray
        Which free dofs are nodal (not enriched).
    modes : (k, 3) ndarray
        The rigid-body modes on the free dofs.
    """
    dom = cnem.Domain([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]],
                      cracks=[[[-0.1, 0.0], [0.1, 0.0]]])
    model = cnem.discretize(cnem.nodes.regular(dom, h))
    prob = cnem.Elasticity(model, (1.0, 0.3), enrich=dict(radius=radius, functions="branch"))
    prob.add_dirichlet(lambda p: p[:, 1] < -0.5 + 1e-9, None)
    prob.add_dirichlet(lambda p: p[:, 1] > 0.5 - 1e-9, 1, 1e-3)
    K, f = prob.stiffness(), prob.load()
    D, values = prob.prescribed()
    x = np.zeros(K.shape[0])
    x[D] = values
    A, b, _, interior = condense(K, f, x=x, D=D)
    n2 = 2 * len(model.nodes)
    modes = np.zeros((K.shape[0], 3))
    modes[:n2] = linsolve.rigid_modes(model.nodes)
    return A.tocsr(), b, prob.solver_options(interior)["nodal"], modes[interior]
