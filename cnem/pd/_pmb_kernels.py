"""Numba kernels of the bond-based (PMB) force loop, one block of consecutive points at a time.

A block holds at most `BLOCK_BONDS` bonds (or one point). Each makes three passes over
scratch arrays that stay in the cache:

1. `_bond_vectors`: the deformed bond vectors ``y_b = xi_b + u_j - u_i`` and the partner
   volumes ``V_j``, gathered point by point; the reference vector ``xi_b = x_j - x_i`` is
   taken from the points as `bond_geometry` computes it (minimum image on periodic axes),
   so that per bond only the length, partner, stiffness and alive flag (21 bytes) stream
   from memory, not ``Body.xi`` as well;
2. `_bond_factors`: per bond, with no gather and no branch (the compiler vectorises the
   square root and the division), the break test and ``g_b y_b`` with
   ``g_b = c_b V_j (|y_b| - L_b) / (L_b |y_b|)``, zero for dead bonds;
3. `_row_sums`: the force density of each point, ``sum_b g_b y_b`` over its bonds.

The force of a point depends only on its own bonds, in their order, so every way of
cutting the points into blocks (`pmb_forces`, `pmb_forces_rows`) gives the same bits.
Indices are taken unsigned inside the passes (no index is negative), so that no
negative-index wrap-around is computed per bond.
"""

import numba
import numpy as np

from .. import _compile  # noqa: F401  (says once when the kernels compile)
from .._parallel import work_chunks
from ._kernels import periodic_image

# Bonds per block (a block of one point may hold more): 8192 x 33 B of scratch in 3-D stay in
# a core's L2. Measured (1M-point lattices, 2 threads): 128 points a block, 15.6k bonds in 3-D,
# gave 430-500 M bond updates/s there against 480-550 with this budget; 2-D about the same.
BLOCK_BONDS = 8192


@numba.njit(cache=True, error_model="numpy")
def _bond_vectors(start, stop, u, points, image, offsets, bond_j, volumes, y, w):
    """``y[:, k] = xi_b + u_j - u_i`` and ``w[k] = V_j`` for the bonds ``b`` of the points
    ``start .. stop - 1``, ``k = b - offsets[start]`` (``y (d, m)``, ``w (m,)``; ``image
    (2, d)`` from `image_factors`)."""
    d = u.shape[1]
    three = d == 3
    y0, y1, y2 = y[0], y[1], y[d - 1]
    p0, p1, p2 = image[0, 0], image[0, 1], image[0, d - 1]
    r0, r1, r2 = image[1, 0], image[1, 1], image[1, d - 1]
    periodic = (image[0] != 0.0).any()
    uf, xf = u.reshape(-1), points.reshape(-1)
    dim, one, two = np.uint64(d), np.uint64(1), np.uint64(2)
    last = np.uint64(d - 1)
    b0 = np.uint64(offsets[start])
    for row in range(start, stop):
        i = np.uint64(row)
        di = dim * i
        x0, x1, x2 = xf[di], xf[di + one], xf[di + last]
        u0, u1, u2 = uf[di], uf[di + one], uf[di + last]
        for b in range(np.uint64(offsets[i]), np.uint64(offsets[i + one])):
            j = np.uint64(bond_j[b])
            dj = dim * j
            k = b - b0
            v0, v1, v2 = xf[dj] - x0, xf[dj + one] - x1, xf[dj + last] - x2
            if periodic:
                v0 = periodic_image(v0, p0, r0)
                v1 = periodic_image(v1, p1, r1)
                v2 = periodic_image(v2, p2, r2)
            y0[k] = (v0 + uf[dj]) - u0
            y1[k] = (v1 + uf[dj + one]) - u1
            if three:
                y2[k] = (v2 + uf[dj + two]) - u2
            w[k] = volumes[j]


@numba.njit(cache=True, error_model="numpy")
def _bond_factors(y, w, length, stiffness, alive, grow, snapped):
    """Overwrite ``y[:, :m]`` with ``g_b y_b`` (see the module) and flag in ``snapped``
    the live bonds with ``|y_b| > L_b grow`` (every live bond when ``grow < 0``);
    ``length``, ``stiffness`` and ``alive`` are the block's ``(m,)`` slices. Returns the
    number of bonds flagged."""
    d = y.shape[0]
    m = length.shape[0]
    y0, y1, y2 = y[0], y[1], y[d - 1]
    three = d == 3
    every = grow < 0.0
    flagged = 0
    for k in range(m):
        yy = y0[k] * y0[k] + y1[k] * y1[k]
        if three:
            yy += y2[k] * y2[k]
        L = length[k]
        reach = L * grow
        snap = every or yy > reach * reach
        live = alive[k] != 0
        snapped[k] = live and snap
        flagged += live and snap
        ly = np.sqrt(yy)
        g = stiffness[k] * w[k] * (ly - L) / (L * ly)
        g = g if live and not snap else 0.0
        y0[k] *= g
        y1[k] *= g
        if three:
            y2[k] *= g
    return flagged


@numba.njit(cache=True, fastmath=True)
def _row_sums(start, stop, offsets, y, out):
    """``out[i] = sum_k y[:, k]`` over the bonds of each point ``i`` of the block."""
    d = y.shape[0]
    b0 = np.uint64(offsets[start])
    for i in range(start, stop):
        lo = np.uint64(offsets[i]) - b0
        hi = np.uint64(offsets[i + 1]) - b0
        for c in range(d):
            yc = y[c]
            s = 0.0
            for k in range(lo, hi):
                s += yc[k]
            out[i, c] = s


@numba.njit(cache=True)
def _pmb_block(start, stop, u, points, image, length, offsets, bond_j, stiffness, volumes,
               alive, grow, out, y, w, snapped):
    """The three passes (see the module) on the points ``start .. stop - 1``, in the
    scratch ``y (d, s)``, ``w (s,)``, ``snapped (s,)`` (``s`` at least the block's
    bonds); returns the number of bonds broken."""
    b0, b1 = offsets[start], offsets[stop]
    _bond_vectors(start, stop, u, points, image, offsets, bond_j, volumes, y, w)
    broken = _bond_factors(y, w, length[b0:b1], stiffness[b0:b1], alive[b0:b1], grow, snapped)
    if broken:
        alive[b0:b1][snapped[:b1 - b0]] = 0
    _row_sums(start, stop, offsets, y, out)
    return broken


@numba.njit(cache=True)
def _runs(rows):
    """The runs of consecutive points of the sorted, distinct ``rows``: ``(start, stop)``
    pairs ``(r, 2)``."""
    runs = np.empty((len(rows), 2), dtype=np.int64)
    r = 0
    k = 0
    while k < len(rows):
        start = rows[k]
        k += 1
        while k < len(rows) and rows[k] == rows[k - 1] + 1:
            k += 1
        runs[r, 0] = start
        runs[r, 1] = rows[k - 1] + 1
        r += 1
    return runs[:r]


@numba.njit(cache=True)
def _blocks(offsets, runs):
    """Each run ``(start, stop)`` of consecutive points cut into blocks of at most
    `BLOCK_BONDS` bonds (at least one point each): ``(start, stop)`` pairs ``(k, 2)``."""
    count = 0
    for pass_ in range(2):
        blocks = np.empty((count, 2), dtype=np.int64)
        count = 0
        for r in range(len(runs)):
            start, stop = runs[r, 0], runs[r, 1]
            while start < stop:
                end = np.searchsorted(offsets[start:stop + 1], offsets[start] + BLOCK_BONDS,
                                      side="right") - 1 + start
                end = min(max(end, start + 1), stop)
                if pass_ == 1:
                    blocks[count, 0] = start
                    blocks[count, 1] = end
                count += 1
                start = end
    return blocks


@numba.njit(cache=True, parallel=True)
def _pmb_blocks(blocks, u, points, image, length, offsets, bond_j, stiffness, volumes, alive,
                limit, out, chunks):
    """`_pmb_block` on every block ``(k, 2)``, in ``chunks`` groups of consecutive blocks
    (a few per thread), each group with its own scratch (allocated once, not per block);
    returns the bonds broken."""
    groups = min(len(blocks), chunks)
    broken = np.zeros(groups, dtype=np.int64)
    for g in numba.prange(groups):
        first, last = g * len(blocks) // groups, (g + 1) * len(blocks) // groups
        most = 0
        for k in range(first, last):
            most = max(most, offsets[blocks[k, 1]] - offsets[blocks[k, 0]])
        y = np.empty((u.shape[1], most))
        w = np.empty(most)
        snapped = np.empty(most, dtype=np.bool_)
        for k in range(first, last):
            broken[g] += _pmb_block(blocks[k, 0], blocks[k, 1], u, points, image, length,
                                    offsets, bond_j, stiffness, volumes, alive, 1.0 + limit, out,
                                    y, w, snapped)
    return broken.sum()


def pmb_forces(u, points, image, length, offsets, bond_j, stiffness, volumes, alive, limit,
               out):
    """Bond-based PMB force density at every point, breaking bonds beyond ``limit``.

    ``out[i] = sum_j c_b s_b (y_b / |y_b|) V_j`` over the live bonds ``b`` of ``i``, with
    ``y_b = xi_b + u_j - u_i``, ``xi_b`` from ``points (n, d)`` (minimum image on the
    periodic axes of ``image (2, d)``, see `image_factors`) and the stretch
    ``s_b = |y_b| / L_b - 1``. A bond whose stretch exceeds ``limit`` is marked dead
    (``alive[b] = 0``) and carries no force from then on. ``u``, ``points`` and ``out``
    C-contiguous. Returns the number of bonds broken.
    """
    everything = np.array([[0, u.shape[0]]], dtype=np.int64)
    return _run_blocks(_blocks(offsets, everything), u, points, image, length, offsets, bond_j,
                       stiffness, volumes, alive, limit, out)


def pmb_forces_rows(rows, u, points, image, length, offsets, bond_j, stiffness, volumes, alive,
                    limit, out):
    """`pmb_forces` at the sorted, distinct points ``rows`` only (``out`` written at those
    rows), with the same bits at each of them."""
    return _run_blocks(_blocks(offsets, _runs(rows)), u, points, image, length, offsets, bond_j,
                       stiffness, volumes, alive, limit, out)


def _run_blocks(blocks, *arrays):
    """`_pmb_blocks` with the groups handed out one at a time (a thread takes the next group
    when done): on a shared machine a core the host slows takes fewer (2-D lattice, 1M
    points, 2 threads, eight rounds: 469-654 M bond updates/s handed out in equal shares,
    499-654 one at a time). Returns the number of bonds broken."""
    with numba.parallel_chunksize(1):
        return int(_pmb_blocks(blocks, *arrays, work_chunks()))
