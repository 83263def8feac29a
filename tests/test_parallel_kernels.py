"""Kernels with a serial and a parallel copy (`cnem._parallel.ParallelKernel`): the copy
is chosen by the work, the copies are cached apart, and they compute the same model."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from cnem import config
from cnem._parallel import ParallelKernel, always_parallel, job_size, parallel_kernel


def _doubled(x):
    out = np.empty_like(x)
    for i in numba.prange(x.shape[0]):
        out[i] = 2.0 * x[i]
    return out


def _first(count, x):
    out = np.zeros(count)
    for i in numba.prange(count):
        out[i] = x[i]
    return out


def test_the_work_chooses_the_copy(monkeypatch):
    monkeypatch.setattr(config, "PARALLEL_MIN", 4)
    kernel = parallel_kernel("x")(_doubled)
    x = np.arange(3.0)
    np.testing.assert_array_equal(kernel(x), 2 * x)
    assert kernel.serial.signatures and not kernel.parallel.signatures
    x = np.arange(4.0)
    np.testing.assert_array_equal(kernel(x=x), 2 * x)       # by keyword too
    assert kernel.parallel.signatures


def test_an_integer_counts_as_its_value(monkeypatch):
    monkeypatch.setattr(config, "PARALLEL_MIN", 5)
    kernel = ParallelKernel(_first, "count")
    x = np.arange(10.0)
    np.testing.assert_array_equal(kernel(np.int64(4), x), x[:4])      # a NumPy integer too
    assert not kernel.parallel.signatures
    with always_parallel():
        np.testing.assert_array_equal(kernel(2, x), x[:2])
    assert kernel.parallel.signatures and config.PARALLEL_MIN == 5


def test_a_job_size_makes_its_small_pieces_parallel(monkeypatch):
    monkeypatch.setattr(config, "PARALLEL_MIN", 10)
    kernel = parallel_kernel("x")(_doubled)
    x = np.arange(3.0)
    with job_size(5):                                   # a small job: serial pieces
        np.testing.assert_array_equal(kernel(x), 2 * x)
    assert not kernel.parallel.signatures
    with job_size(10), job_size(2):                     # the enclosing larger job counts
        np.testing.assert_array_equal(kernel(x), 2 * x)
    assert kernel.parallel.signatures
    kernel.parallel = None                              # left: a piece is serial again
    np.testing.assert_array_equal(kernel(x), 2 * x)


def test_copies_are_cached_apart_and_documented():
    kernel = ParallelKernel(_doubled, "x")
    assert kernel.parallel.targetoptions.get("parallel") is True
    assert not kernel.serial.targetoptions.get("parallel")
    assert kernel.serial.py_func.__qualname__ == "_doubled_serial"     # its own cache file
    assert kernel.parallel.py_func is _doubled and kernel.__name__ == "_doubled"


def test_an_unknown_work_parameter_is_refused():
    with pytest.raises(ValueError, match="no parameter 'y'"):
        ParallelKernel(_doubled, "y")


@pytest.mark.slow
def test_the_parallel_copies_compute_the_same_solution():
    """The bimaterial cylinder (147 nodes, irregular) through the serial copies and
    through the parallel ones (compiled for this test): the same cells, displacements
    and stresses to round-off."""
    import cnem
    from cnem.demos import bimaterial_cylinder as demo
    from cnem.shape import _kernels

    def solve():
        _, cloud = demo.build(7, 21, irregular=True)
        model = cnem.discretize(cloud, progress=False)
        sol = demo.pose(cnem.Elasticity(model, demo.MATERIALS, plane="stress")).solve(
            progress=False)
        return model.cells.area, model.cells.vertices, sol.u, sol.stress

    serial = solve()
    with always_parallel():
        parallel = solve()
    assert _kernels.natural.parallel.signatures, "the parallel copies did not run"
    for a, b in zip(serial, parallel):
        np.testing.assert_allclose(b, a, rtol=0, atol=1e-12 * np.abs(a).max())
