"""Regular (lattice) 3-D clouds: their cospherical ties leave no flat tetrahedron, so the
models' shape functions work (`cnem.geometry.tetrahedra`, step 4).

Qhull's Delaunay tetrahedrisation of a lattice holds zero-volume slivers (four
cocircular nodes of a lattice square); `tet_mesh` refuses them.
"""

from __future__ import annotations

import numpy as np
import pytest

import cases3d
import cnem
from cnem.geometry.shapes3d import box_surface
from cnem.geometry.tetrahedra import conforming_tetrahedra, signed_volumes


def _l_block():
    p, f, _ = cases3d.l_block(2, jitter=0.0)
    used, f = np.unique(f, return_inverse=True)
    return cnem.Domain3D((p[used], f.reshape(-1, 3)))


DOMAINS = {
    "box": lambda: cnem.geometry.box((0.0, 0.0, 0.0), (1.0, 0.8, 0.6)),
    "l_block": _l_block,
    "cavity": lambda: cnem.Domain3D((box_surface((0.0, 0.0, 0.0), (1.0, 1.0, 1.0)),
                                     [box_surface((1 / 3, 1 / 3, 1 / 3), (2 / 3, 2 / 3, 2 / 3))])),
}


def _flat(points, tets):
    x = points[tets]
    longest = np.linalg.norm(x[:, None] - x[:, :, None], axis=3).max(axis=(1, 2))
    return np.abs(signed_volumes(points, tets)) <= 1e-8 * longest ** 3


@pytest.mark.parametrize("name", sorted(cases3d.__dict__.keys() & {
    "box", "l_block", "box_with_cavity", "stacked", "slotted"}))
def test_lattice_bodies_have_no_flat_tetrahedra(name):
    p, f, r = getattr(cases3d, name)(jitter=0.0)
    tet = conforming_tetrahedra(p, f, r)
    assert not _flat(tet.points, tet.tetrahedra).any()


@pytest.mark.parametrize("name", sorted(DOMAINS))
def test_shape_functions_on_regular_clouds(name):
    dom = DOMAINS[name]()
    model = cnem.discretize(cnem.nodes.regular(dom, 0.25))
    assert not _flat(model.nodes, model.tetrahedra).any()
    assert np.isclose(model.cells.volume.sum(), dom.volume, rtol=1e-12)
    model.tet_mesh()
    rng = np.random.default_rng(0)
    lo, hi = dom.bounds
    x = rng.uniform(lo, hi, (3000, 3))
    x = x[dom.contains(x)]
    phi = model.shape_functions(x)
    np.testing.assert_allclose(np.asarray(phi.sum(axis=1)).ravel(), 1.0, atol=1e-12)
    np.testing.assert_allclose(phi @ model.nodes, x, atol=1e-12)
    at = model.shape_functions(model.nodes).toarray()
    np.testing.assert_allclose(at, np.eye(len(model.nodes)), atol=1e-12)
