"""Geometry, node generation and family search on degenerate inputs and in any units
(issue 19): no hang (time-boxed in a subprocess), no silent wrong answer, and
errors that name the real cause."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import reference as R
from cnem.spatial import family_search

FAMILY_METHODS = ["auto", "rtree", "cells", "kdtree", "brute"]


def run_boxed(code: str, timeout: float = 240.0) -> str:
    """Run ``code`` in a fresh interpreter with a time limit (a hang fails the test
    instead of hanging the suite); its standard output."""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=timeout)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def same_rows(fam, ref):
    offsets, indices = ref
    return all(set(fam.row(i).tolist()) == set(indices[offsets[i]:offsets[i + 1]].tolist())
               for i in range(len(fam)))


# ------------------------------------------------------------------ family search
@pytest.mark.parametrize("method", FAMILY_METHODS)
@pytest.mark.parametrize("unit", [1e-300, 1e300])
def test_family_in_extreme_units(method, unit):
    """Coordinates of order 1e-300 (squared distances below the smallest double) and
    1e300 (squared distances overflow) give the brute-force families of the same cloud
    in units where squares are representable (scaling by a power of two is exact)."""
    rng = np.random.default_rng(4)
    pts = rng.uniform(0, 1, (300, 2))
    power = 2.0 ** (-996 if unit < 1 else 996)       # about `unit`, and exact
    ref = R.brute_family(pts, 0.15)
    fam = family_search(pts * power, 0.15 * power, method=method)
    assert ref[1].size > 3000                  # the families are not empty
    assert same_rows(fam, ref)


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
