"""Smoothed gradients computed pass by pass over runs of cells (bounded memory).

A pass takes at most ``config.CELLS_PER_PASS`` cells: their quadrature points
and shape functions live while it runs, and a small pass works in cache. The
passes of a large model run the kernels' parallel copies, as one pass over all its
cells would (`cnem._parallel.job_size`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .. import config
from .._memory import release_free_memory
from .._parallel import job_size
from ..shape.natural import path_order
from . import _sparse_kernels as SK
from .csr import csr_pair

if TYPE_CHECKING:
    from typing import Callable, Sequence
    from ..geometry.model import Cells, Model
    from .edge_quadrature import BoundaryQuadrature

__all__ = ["cell_runs", "gradients_in_passes"]


def cell_runs(model: Model, cells: Cells) -> list[np.ndarray] | None:
    """Runs of at most ``config.CELLS_PER_PASS`` cells, one pass each, as index
    arrays into ``cells`` (None when one pass takes them all).

    A pass bounds the memory of the quadrature points and their shape functions,
    and a small one works in cache; the edges between runs are integrated in both.
    The cells are taken tile by tile along a serpentine path (by their nodes), a
    run about four tiles, so that every run is a compact block whatever the order
    of the nodes.

    Parameters
    ----------
    model : Model
    cells : Cells
        ``m`` cells.

    Returns
    -------
    list of (r,) int64 ndarray, or None
    """
    m, per_pass = len(cells), config.CELLS_PER_PASS
    if m <= per_pass:
        return None
    size = -(-m // -(-m // per_pass))          # runs of equal size, none tiny
    order = path_order(model.nodes[cells.node], model.domain.bounds, per_tile=size / 4)
    return [order[lo:lo + size] for lo in range(0, m, size)]


def gradients_in_passes(model: Model, sets: list,
                        quadratures: Callable[..., Sequence[BoundaryQuadrature]],
                        runs: list | None = None,
                        wanted: list[bool] | None = None) -> tuple[list, int]:
    """Smoothed gradients of several sets of cells, pass by pass.

    Parameters
    ----------
    model : Model
    sets : list of Cells
    quadratures : callable
        ``quadratures(subsets, index)``: one `BoundaryQuadrature` per set, with
        one set of points, for the cells ``subsets`` (``index``: their indices
        into ``sets``, one array per set; None when they are the sets).
    runs : list of lists of (r,) int arrays, optional
        For each pass, the cells of every set it takes (the runs of a set cover
        it once); by default one pass takes them all.
    wanted : list of bool, optional
        The sets whose gradients are computed (default all; the others only
        serve the quadrature of the rest).

    Returns
    -------
    gradients : list of (x, y) or None
        One per set (None where not wanted): ``x, y`` CSR ``(m_set, n)``.
    points : int
        Quadrature points evaluated in all the passes.
    """
    wanted = [True] * len(sets) if wanted is None else wanted
    if runs is None:
        parts, points = _passes(model, quadratures, [(sets, None)], wanted)
        return [part[0] if want else None for part, want in zip(parts, wanted)], points
    with job_size(sum(len(cells) for cells in sets)):
        # a generator: one pass's cells alive at a time
        parts, points = _passes(model, quadratures,
                                (([cells.subset(i) for cells, i in zip(sets, run)], run)
                                 for run in runs), wanted)
        out = [_place_runs(parts[i], [run[i] for run in runs]) if wanted[i] else None
               for i in range(len(sets))]
    del parts                # the passes' arrays are freed, but the C heap keeps them
    release_free_memory()
    return out, points


def _passes(model, quadratures, runs, wanted):
    """The cell integrals of every run ``(subsets, index)``: ``parts[set][run] = (x, y)``
    (for the ``wanted`` sets), and the number of quadrature points (the runs' cells
    are dropped pass by pass)."""
    parts, points = None, 0
    for run, index in runs:
        if parts is None:
            parts = [[] for _ in run]
        quads = quadratures(run, index)
        edges = quads[0].edge_integrals(quads[0].point_rows(model))
        for part, quad, want in zip(parts, quads, wanted):
            if want:
                part.append(quad.from_edges(edges))
        points += len(quads[0].points)
    return parts, points


def _place_runs(part, targets):
    """The x and y parts of the runs of one set of cells put together, run ``r``'s
    rows going to rows ``targets[r]``: two CSR with their own index arrays."""
    m, n = sum(len(t) for t in targets), part[0][0].shape[1]
    indptr = np.zeros(m + 1, dtype=np.int64)
    for (x, _), target in zip(part, targets):
        indptr[np.asarray(target) + 1] = np.diff(x.indptr)
    np.cumsum(indptr, out=indptr)
    indices = np.empty(indptr[-1], dtype=np.int32)
    vx, vy = np.empty(indptr[-1]), np.empty(indptr[-1])
    for (x, y), target in zip(part, targets):
        SK.place_rows(x.indptr, x.indices, x.data, y.data, np.asarray(target, dtype=np.int64),
                      indptr, indices, vx, vy)
    return csr_pair(indptr, indices, vx, vy, (m, n))
