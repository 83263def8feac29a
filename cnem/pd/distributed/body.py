"""`Body` on MPI ranks: each rank holds its owned points' bonds and their ghosts."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...spatial import family_search, remove_crossing
from .._kernels import bond_geometry, image_factors
from ..body import bond_reach, checked_input, crack_segments
from . import _kernels as K
from .comm import Halo, collectively, same_on_every_rank, world
from .partition import bisect, ghost_candidates
from ..._sets import distinct

if TYPE_CHECKING:
    from typing import Any
    from numpy.typing import ArrayLike

__all__ = ["Body"]


class Body:
    """The points of `cnem.pd.Body` cut into one block per rank by recursive coordinate
    bisection (weighted by family size), with ghost points one horizon wide.

    Every rank is given the same arguments as `cnem.pd.Body` (the points of the whole
    body) and keeps the bonds of its own points only, in the same families as the serial
    body (cracks cut the same bonds); the members of each family are sorted by global
    point number, so that every rank count sums the bonds in one order.

    Parameters
    ----------
    points, volumes, horizon, thickness, period, cracks, crossing_points
        As in `cnem.pd.Body`.
    comm : mpi4py communicator, optional
        Default ``MPI.COMM_WORLD`` (one rank under plain ``python``).

    Attributes
    ----------
    global_points : (n, d) ndarray
        All points (every rank), for the point predicates of the conditions.
    part : (n,) int64 ndarray
        Rank owning each point.
    owned, ghosts : (o,), (g,) int64 ndarray
        Global ids of the local rows: owned first, then ghosts (both increasing).
    points, volumes : (o + g, d), (o + g,) ndarray
        Local rows.
    offsets : (o + g + 1,) int64 ndarray
        Bonds of the owned points (ghost rows are empty).
    bond_i, bond_j, xi, length, beta
        As in `cnem.pd.Body`, for the bonds of the owned points (local numbering).
    period, image
        As in `cnem.pd.Body`.
    halo : Halo
    interior, boundary : int64 ndarray
        Owned rows without / with a ghost in their family: the forces of the interior
        ones need no exchanged value.
    """

    def __init__(self, points: np.ndarray, volumes: float | ArrayLike, horizon: float, *,
                 thickness: float = 1.0, period: ArrayLike | None = None, cracks: tuple = (),
                 crossing_points: int | None = None, comm: Any = None):
        self.comm = world(comm)
        pts, vol, horizon, self.thickness = collectively(
            self.comm, lambda: checked_input(points, volumes, horizon, thickness))
        for name, value in (("points", pts), ("volumes", vol),
                            ("horizon and thickness", np.array([horizon, self.thickness]))):
            same_on_every_rank(self.comm, name, value)
        n, d = pts.shape
        self.global_points, self.horizon, self.dim = pts, horizon, d
        self.global_size = n
        self._cracks = crack_segments(cracks)
        self._crossing = pts if crossing_points is None else \
            np.asarray(crossing_points, dtype=float)
        self.period = np.full(d, np.inf) if period is None else \
            np.broadcast_to(np.asarray(period, dtype=float), (d,)).copy()
        self.image = image_factors(self.period)
        self._period_arg = period
        self.reach = bond_reach(pts, horizon)
        rank, size = self.comm.rank, self.comm.size
        weights = np.ones(n)
        if size > 1:        # a first cut by point count gives the family sizes to weigh by
            first = bisect(pts, weights, size)
            counts = np.diff(self._owned_rows(first, rank)[0])
            weights = np.zeros(n)
            for ids, c in self.comm.allgather((np.flatnonzero(first == rank), counts)):
                weights[ids] = c
        self.part = bisect(pts, weights, size)
        owned = np.flatnonzero(self.part == rank)
        offsets, members = self._owned_rows(self.part, rank)
        ghosts = np.setdiff1d(distinct(members), owned)
        self.owned, self.ghosts = owned, ghosts
        local = np.concatenate([owned, ghosts])
        index = np.int32 if len(local) < 2 ** 31 - 1 else np.int64
        row_of = np.full(n, -1, dtype=index)          # global id -> local row
        row_of[local] = np.arange(len(local), dtype=index)
        self.bond_j = row_of[members]
        del members, row_of
        self.offsets = np.concatenate([offsets, np.full(len(ghosts), offsets[-1])])
        self.bond_i = np.repeat(np.arange(len(owned), dtype=index), np.diff(offsets))
        self.points, self.volumes = np.ascontiguousarray(pts[local]), vol[local]
        nb = len(self.bond_j)
        self.xi, self.length, self.beta = np.empty((nb, d)), np.empty(nb), np.empty(nb)
        spacing = (self.volumes / self.thickness) ** (1.0 / d)
        bond_geometry(self.points, self.offsets, self.bond_j, self.image, spacing, horizon,
                      self.xi, self.length, self.beta)
        self.halo = Halo(self.comm, owned, ghosts, self.part)
        near_ghost = np.bincount(self.bond_i[self.bond_j >= len(owned)], minlength=len(owned)) > 0
        self.interior = np.flatnonzero(~near_ghost)
        self.boundary = np.flatnonzero(near_ghost)

    def _owned_rows(self, part, rank):
        """Families of the points of ``part == rank``: CSR offsets and global member ids,
        each row sorted by id."""
        owned = np.flatnonzero(part == rank)
        candidates = ghost_candidates(self.global_points, part, rank, self.reach,
                                      self._period_arg)
        local = np.concatenate([owned, candidates])
        pts = self.global_points[local]
        fam = family_search(pts, self.reach, period=self._period_arg)
        if self._cracks is not None:
            fam = remove_crossing(fam, self._crossing[local], self._cracks)
        offsets = np.ascontiguousarray(fam.offsets[:len(owned) + 1])
        members = local[fam.indices[:offsets[-1]]].astype(np.int64)
        K.sort_rows(offsets, members)
        return offsets, members

    @property
    def n_owned(self) -> int:
        """Points owned by this rank."""
        return len(self.owned)

    def __len__(self):
        return self.global_size

    def __repr__(self):
        return (f"<distributed Body {self.global_size} points ({self.dim}-D), rank "
                f"{self.comm.rank} of {self.comm.size}: {self.n_owned} owned, "
                f"{len(self.ghosts)} ghosts, {len(self.bond_j)} bonds>")
