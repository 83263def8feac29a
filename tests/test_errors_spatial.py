"""Family search on degenerate inputs and in any units: the same bonds in tiny units,
huge units refused by name, far from the origin in bounded time (a subprocess with a time
limit, so that a hang fails instead of hanging the suite)."""

from __future__ import annotations

import numpy as np
import pytest

import reference as R
from boxed import run_boxed
from cnem.errors import SpatialError
from cnem.spatial import family_search

FAMILY_METHODS = ["auto", "rtree", "cells", "kdtree", "brute"]


def same_rows(fam, ref):
    offsets, indices = ref
    return all(set(fam.row(i).tolist()) == set(indices[offsets[i]:offsets[i + 1]].tolist())
               for i in range(len(fam)))


# ------------------------------------------------------------------ family search
@pytest.mark.parametrize("method", FAMILY_METHODS)
def test_family_in_tiny_units(method):
    """Coordinates of order 1e-300 (squared distances below the smallest double) give
    the brute-force families of the same cloud in units where squares are representable
    (scaling by a power of two is exact)."""
    rng = np.random.default_rng(4)
    pts = rng.uniform(0, 1, (300, 2))
    power = 2.0 ** -996                        # about 1e-300, and exact
    ref = R.brute_family(pts, 0.15)
    fam = family_search(pts * power, 0.15 * power, method=method)
    assert ref[1].size > 3000                  # the families are not empty
    assert same_rows(fam, ref)


@pytest.mark.parametrize("method", FAMILY_METHODS)
def test_family_in_huge_units_is_refused_by_name(method):
    """Coordinates of order 1e300 are refused at the public boundary, as everywhere in
    the library (`cnem.config.COORDINATE_LIMIT`), with the fix in the message."""
    pts = np.random.default_rng(4).uniform(0, 1, (300, 2)) * 2.0 ** 996
    with pytest.raises(SpatialError, match="expected coordinates below .* other units"):
        family_search(pts, 0.15 * 2.0 ** 996, method=method)


def test_family_far_from_the_origin_in_bounded_time():
    """Points at 1e12 + [0, 1]^2: every method answers (it hung before the R-tree's
    boxes were rounded outwards in one step) with the families of the same cloud at
    the origin."""
    code = (
        "import numpy as np\n"
        "from cnem.spatial import family_search\n"
        "rng = np.random.default_rng(2); local = rng.uniform(0, 1, (300, 2)); pts = 1e12 + local\n"
        "ref = family_search(pts, 0.15, method='brute')\n"
        "d = np.hypot(*(pts[:, None, :] - pts[None, :, :]).transpose(2, 0, 1))\n"
        "want = [set(np.flatnonzero((d[k] > 0) & (d[k] < 0.15))) for k in range(300)]\n"
        "ok = []\n"
        "for m in ('auto', 'rtree', 'cells', 'kdtree', 'brute'):\n"
        "    f = family_search(pts, 0.15, method=m)\n"
        "    ok.append(all(set(f.row(k).tolist()) == want[k] for k in range(300)))\n"
        "print(all(ok), sum(map(len, want)))\n")
    ok, bonds = run_boxed(code).split()
    assert ok == "True" and int(bonds) > 3000


