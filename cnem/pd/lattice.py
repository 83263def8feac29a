"""Regular lattices of points for PD bodies, and the measures of their cells after a
deformation.

>>> import numpy as np
>>> x = lattice((3, 2), 0.5)
>>> x.shape, bool((x.reshape(3, 2, 2)[2, 1] == [1.0, 0.5]).all())
((6, 2), True)
>>> float(lattice_measure(2 * x, (3, 2)).sum())       # twice as long both ways: 4 x 0.5
2.0
"""

from __future__ import annotations

import itertools
import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["lattice", "lattice_measure"]


def lattice(counts: Sequence, spacing: float) -> np.ndarray:
    """Points of a regular lattice with its first point at the origin.

    Parameters
    ----------
    counts : sequence of d int
        Points along each axis.
    spacing : float

    Returns
    -------
    (prod(counts), d) ndarray
        In C order: ``points.reshape(*counts, d)`` is the grid.
    """
    axes = [spacing * np.arange(c) for c in counts]
    return np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, len(counts))


def lattice_measure(y: np.ndarray, counts: Sequence) -> np.ndarray:
    """Area (2-D) or volume (3-D) of every lattice cell after a deformation.

    Each cell is split into the d! simplices of its Kuhn triangulation (one per
    order of the axes), whose signed measures are summed: exact for a cell whose
    deformed edges are those of an affine map.

    Parameters
    ----------
    y : (prod(counts), d) array_like
        Deformed positions of the lattice points, in the order of `lattice`.
    counts : sequence of d int

    Returns
    -------
    (*(counts - 1),) ndarray
        Signed measure of each cell (negative where it is turned inside out).
    """
    d = len(counts)
    grid = np.asarray(y, dtype=float).reshape(*counts, d)

    def corner(offset):
        return grid[tuple(slice(o, c - 1 + o) for o, c in zip(offset, counts))]
    total = 0.0
    for order in itertools.permutations(range(d)):
        path = [np.zeros(d, dtype=int)]
        for axis in order:
            path.append(path[-1] + np.eye(d, dtype=int)[axis])
        origin = corner(path[0])
        edges = np.stack([corner(p) - origin for p in path[1:]], -1)
        sign = (-1) ** sum(a > b for a, b in itertools.combinations(order, 2))
        total = total + sign * np.linalg.det(edges)
    return total / math.factorial(d)
