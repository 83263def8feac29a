"""Sibson values against CGAL's, an independent implementation (when CGAL is installed).

The CGAL driver (``tests/cgal_coordinates.cpp``, built by ``tests/cgal_coordinates.py``; the
shape-function benchmark times it too) evaluates ``natural_neighbor_coordinates_2`` on a
Delaunay triangulation of the same nodes; without a crack cnem's triangulation is Delaunay, so the
two must give the same values.  Skipped when g++ or CGAL's headers are missing
(``apt-get install libcgal-dev``); CGAL is never a dependency of cnem.
"""
import numpy as np
import pytest

import cgal_coordinates
import cnem


def test_missing_compiler_is_a_skip_with_the_reason():
    out = cgal_coordinates.build(cxx="no-such-c++-compiler")
    assert "exe" not in out
    assert "no-such-c++-compiler" in out["skipped"] and "skipped" in out["skipped"]


@pytest.mark.slow
def test_sibson_values_equal_cgal_on_the_square(tmp_path):
    built = cgal_coordinates.build()
    if "exe" not in built:
        pytest.skip(built["skipped"])
    model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(), h=0.03, seed=3),
                            progress=False)
    rng = np.random.default_rng(7)
    points = np.vstack([rng.random((3000, 2)), model.nodes[:50],
                        [[0.5, 0.0], [1.0, 0.37], [0.0, 1.0]]])   # nodes, boundary, corner
    out = cgal_coordinates.run(built["exe"], model.nodes, points, 1, str(tmp_path))
    assert "error" not in out, out.get("error")
    assert out["outside"] == 0 and out["n_vertices"] == len(model.nodes)
    ours = model.shape_functions(points, kind="sibson")
    assert abs(ours - out["phi"]).max() <= 1e-12


@pytest.mark.slow
def test_laplace_3d_values_equal_cgal_in_a_box(tmp_path):
    """CGAL's ``laplace_natural_neighbor_coordinates_3`` on the Delaunay tetrahedrisation of
    the same nodes: in a convex box with no interface the constrained coordinates are the
    unconstrained ones, so the two must agree at random points (near the faces too), at
    nodes and on the faces."""
    built = cgal_coordinates.build(source=cgal_coordinates.LAPLACE_3D)
    if "exe" not in built:
        pytest.skip(built["skipped"])
    model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.box(), h=0.12, seed=3),
                            progress=False)
    rng = np.random.default_rng(7)
    points = np.vstack([rng.random((3000, 3)), model.nodes[:50]])
    out = cgal_coordinates.run(built["exe"], model.nodes, points, 1, str(tmp_path))
    assert "error" not in out, out.get("error")
    assert out["n_vertices"] == len(model.nodes)
    answered = np.diff(out["phi"].indptr) > 0
    assert answered.sum() >= 0.95 * len(points)          # CGAL declines unbounded cells only
    ours = model.shape_functions(points)
    assert abs(ours[answered] - out["phi"][answered]).max() <= 1e-12
