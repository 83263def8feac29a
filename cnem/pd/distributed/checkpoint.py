"""Checkpoints of a distributed dynamic run: one ``.npz`` file per rank.

A checkpoint holds the step, the owned points' displacements and velocities
and the live flags of their bonds (and of the reverse bonds), so that a
resumed run repeats the uninterrupted one exactly. It is read back on the same
number of ranks (the partition is checked).
"""

from __future__ import annotations

import os
import pathlib

import numpy as np

from ...errors import InputError

__all__ = ["checkpoint_path", "save", "load"]


def checkpoint_path(stem, rank, size):
    """``<stem>.rank<r>-of-<size>.npz``."""
    stem = pathlib.Path(os.fspath(stem))
    return stem.with_name(f"{stem.name}.rank{rank}-of-{size}.npz")


def save(stem, comm, **arrays):
    """Write this rank's file (folders created); returns its path."""
    path = checkpoint_path(stem, comm.rank, comm.size)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp.npz")
    np.savez(tmp, **arrays)
    os.replace(tmp, path)
    return path


def load(stem, comm, owned):
    """This rank's arrays; ``owned`` (global ids) must match the saved ones.

    Raises
    ------
    ValueError
        No file for this rank and rank count, or another partition.
    """
    path = checkpoint_path(stem, comm.rank, comm.size)
    if not path.exists():
        raise InputError(f"restart: expected the checkpoint {path} (written by a run on "
                         f"{comm.size} ranks), found none; restart on the rank count of the "
                         f"run that wrote it")
    with np.load(path) as data:
        arrays = dict(data)
    if not np.array_equal(arrays["owned"], owned):
        raise InputError(f"restart: {path} holds another partition of the points; restart "
                         f"the same body on the same number of ranks")
    return arrays
