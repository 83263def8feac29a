"""MPI through mpi4py (the ``cnem[mpi]`` extra) and the halo exchange of ghost values.

>>> from cnem.pd.distributed.comm import world
>>> world().size >= 1          # doctest: +SKIP
True
"""

from __future__ import annotations

import hashlib
from typing import TYPE_CHECKING

import numpy as np

from ...errors import CNEMError, InputError, MissingExtraError

if TYPE_CHECKING:
    from typing import Any, Callable

__all__ = ["mpi", "world", "collectively", "same_on_every_rank", "Halo", "INSTALL_HINT"]

INSTALL_HINT = 'pip install "cnem[mpi]"  (the mpi4py and mpich wheels)'


def mpi() -> Any:
    """The ``mpi4py.MPI`` module.

    Raises
    ------
    MissingExtraError
        mpi4py is not installed: the message names the ``cnem[mpi]`` extra.
    """
    try:
        from mpi4py import MPI
    except ImportError as exc:
        raise MissingExtraError(
            f"cnem.pd.distributed needs MPI through mpi4py, which could not be imported "
            f"({exc}); install the extra: {INSTALL_HINT}. Serial runs need nothing: use "
            f"cnem.pd instead") from exc
    return MPI


def world(comm: Any = None) -> Any:
    """``comm``, or ``MPI.COMM_WORLD`` when it is None (one rank under plain ``python``)."""
    return mpi().COMM_WORLD if comm is None else comm


def collectively(comm: Any, compute: Callable[[], Any]) -> Any:
    """``compute()`` on every rank, raising the same error on every rank when it fails on
    any: a `CNEMError` on one rank alone would leave the others waiting in their next
    collective call for ever (on a cluster, until the allocation runs out).

    Parameters
    ----------
    comm : mpi4py communicator
    compute : callable ``() -> value``
        The rank's own work (validating its arguments, ...).

    Returns
    -------
    The rank's value.

    Raises
    ------
    CNEMError
        Of the first rank that failed (its type and message, naming the rank when more
        than one rank runs).
    """
    value, failure = None, None
    try:
        value = compute()
    except CNEMError as err:
        failure = (type(err), str(err))
    failures = comm.allgather(failure)
    for rank, failed in enumerate(failures):
        if failed is not None:
            kind, message = failed
            where = f" (on rank {rank} of {comm.size})" if comm.size > 1 else ""
            raise kind(message + where)
    return value


def same_on_every_rank(comm: Any, name: str, value: np.ndarray) -> None:
    """Check that every rank was given the same ``value``: each rank of a distributed
    body must be handed the whole body, the same on all of them.

    Parameters
    ----------
    comm : mpi4py communicator
    name : str
        The argument, for the message.
    value : ndarray

    Raises
    ------
    InputError
        On every rank, naming the ranks whose ``value`` differs from rank 0's (shape or
        contents).
    """
    arr = np.ascontiguousarray(value)
    mine = (arr.shape, hashlib.sha256(arr.tobytes()).hexdigest())
    every = comm.allgather(mine)
    differ = [rank for rank, seen in enumerate(every) if seen != every[0]]
    if differ:
        shapes = ", ".join(f"rank {r}: {every[r][0]}" for r in [0] + differ)
        raise InputError(f"{name}: every rank must be given the same {name} (the whole body), "
                         f"but ranks {differ} differ from rank 0 ({shapes}); build them from "
                         f"the same data on every rank (the same file or seed)")


class Halo:
    """Copies owned values to the ranks holding them as ghosts.

    Parameters
    ----------
    comm : mpi4py communicator
    owned : (o,) int64 ndarray
        Global ids of this rank's points, increasing (local rows ``0..o-1``).
    ghosts : (g,) int64 ndarray
        Global ids of the ghosts (local rows ``o..o+g-1``).
    owner : (n,) int ndarray
        Rank owning each global point.

    Attributes
    ----------
    sends, receives : dict rank -> (k,) int64 ndarray
        Local rows sent to / received from each neighbouring rank.
    bytes : int
        Bytes this rank has sent so far.
    """

    def __init__(self, comm: Any, owned: np.ndarray, ghosts: np.ndarray, owner: np.ndarray):
        self.comm = comm
        size = comm.size
        ghost_rows = len(owned) + np.arange(len(ghosts))
        by_owner = owner[ghosts]
        wanted = [ghosts[by_owner == r] for r in range(size)]
        self.receives = {r: ghost_rows[by_owner == r] for r in range(size) if len(wanted[r])}
        asked = comm.alltoall(wanted)                # the ids each rank wants from this one
        self.sends = {r: np.searchsorted(owned, ids).astype(np.int64)
                      for r, ids in enumerate(asked) if len(ids)}
        self.bytes = 0

    def exchange(self, values: np.ndarray) -> np.ndarray:
        """Overwrite the ghost rows of ``values`` (``(o + g, ...)``, C-contiguous) with
        their owners' values."""
        return self.finish(self.start(values))

    def start(self, values: np.ndarray) -> tuple:
        """Post the receives and the sends of `exchange` and return at once; the ghost
        rows of ``values`` are current after `finish` (the owned rows must not change
        before then)."""
        tail = values.shape[1:]
        requests, inbox, outbox = [], [], []
        for r, rows in self.receives.items():
            buf = np.empty((len(rows),) + tail, dtype=values.dtype)
            requests.append(self.comm.Irecv(buf, source=r, tag=7))
            inbox.append((rows, buf))
        for r, rows in self.sends.items():
            buf = np.ascontiguousarray(values[rows])
            outbox.append(buf)                 # kept alive until the sends complete
            requests.append(self.comm.Isend(buf, dest=r, tag=7))
            self.bytes += buf.nbytes
        return values, requests, inbox, outbox

    def finish(self, pending: tuple) -> np.ndarray:
        """Wait for an exchange begun by `start`; copy the received ghost rows in and
        return the values."""
        values, requests, inbox, _ = pending
        mpi().Request.Waitall(requests)
        for rows, buf in inbox:
            values[rows] = buf
        return values

    @property
    def neighbours(self) -> list[int]:
        """Ranks this one exchanges with."""
        return sorted(set(self.sends) | set(self.receives))
