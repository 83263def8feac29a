"""Sibson values against CGAL's, an independent implementation (when CGAL is installed).

The CGAL driver (``tests/cgal_sibson.cpp``, built by ``tests/cgal_sibson.py``; the
shape-function benchmark times it too) evaluates ``natural_neighbor_coordinates_2`` on a
Delaunay triangulation of the same nodes; without a crack cnem's triangulation is Delaunay, so the
two must give the same values.  Skipped when g++ or CGAL's headers are missing
(``apt-get install libcgal-dev``); CGAL is never a dependency of cnem.
"""
import numpy as np
import pytest

import cgal_sibson
import cnem


def test_missing_compiler_is_a_skip_with_the_reason():
    out = cgal_sibson.build(cxx="no-such-c++-compiler")
    assert "exe" not in out
    assert "no-such-c++-compiler" in out["skipped"] and "skipped" in out["skipped"]


@pytest.mark.slow
def test_sibson_values_equal_cgal_on_the_square(tmp_path):
    built = cgal_sibson.build()
    if "exe" not in built:
        pytest.skip(built["skipped"])
    model = cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(), h=0.03, seed=3),
                            progress=False)
    rng = np.random.default_rng(7)
    points = np.vstack([rng.random((3000, 2)), model.nodes[:50],
                        [[0.5, 0.0], [1.0, 0.37], [0.0, 1.0]]])   # nodes, boundary, corner
    out = cgal_sibson.run(built["exe"], model.nodes, points, 1, str(tmp_path))
    assert "error" not in out, out.get("error")
    assert out["outside"] == 0 and out["n_vertices"] == len(model.nodes)
    ours = model.shape_functions(points, kind="sibson")
    assert abs(ours - out["phi"]).max() <= 1e-12
