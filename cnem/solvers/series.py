"""`.pvd` series: a ParaView collection of ``.vtu`` files with their times.

A solution with several states (the load steps of `cnem.Hyperelasticity.solve`, the
frames of a peridynamic run) writes one ``.vtu`` per state beside the ``.pvd``
(`write_series`); ParaView opens the ``.pvd`` as one time-dependent data set whose
times are the load factors or the run's times.

>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> write_pvd(folder / "run.pvd", [(0.5, folder / "a.vtu"), (1.0, folder / "b.vtu")]).name
'run.pvd'
"""

from __future__ import annotations

import os
import pathlib
from collections.abc import Sequence
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

from ..errors import InputError

__all__ = ["write_pvd", "write_series"]


def write_pvd(path: str | os.PathLike, datasets: Sequence[tuple[float, str | os.PathLike]]
              ) -> pathlib.Path:
    """Write a ParaView collection (``.pvd``) of ``.vtu`` files with their times.

    Parameters
    ----------
    path : str or os.PathLike
        Suffix ``.pvd``.
    datasets : sequence of (float, path)
        ``(time, file)`` pairs, times strictly increasing; the files are named
        relative to ``path``'s folder when they are in it.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    InputError
        A suffix other than ``.pvd``, no datasets, or times not strictly increasing.
    """
    path = pathlib.Path(path)
    if path.suffix.lower() != ".pvd":
        raise InputError(f"path: expected a .pvd file, received {str(path)!r}; "
                         f"name the collection <stem>.pvd")
    times = np.array([float(t) for t, _ in datasets])
    if len(times) == 0 or not (np.isfinite(times).all() and np.all(np.diff(times) > 0)):
        raise InputError(f"datasets: expected one or more (time, file) pairs with strictly "
                         f"increasing finite times, received times {times.tolist()}")
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             "  <Collection>"]
    for time, file in datasets:
        file = pathlib.Path(file)
        name = os.path.relpath(file, path.parent) if file.is_absolute() == \
            path.is_absolute() else str(file)
        lines.append(f'    <DataSet timestep="{float(time)!r}" group="" part="0" '
                     f'file={quoteattr(pathlib.Path(name).as_posix())}/>')
    lines += ["  </Collection>", "</VTKFile>", ""]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines))
    return path


def write_series(path: str | os.PathLike, states: Sequence[tuple[float, Any]]) -> pathlib.Path:
    """Write each state's ``.vtu`` beside ``path`` and the ``.pvd`` collection of them.

    Parameters
    ----------
    path : str or os.PathLike
        ``<folder>/<stem>.pvd``; the states go to ``<folder>/<stem>_<i>.vtu``.
    states : sequence of (float, object with ``write(path)``)
        ``(time, state)`` pairs, times strictly increasing.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    path = pathlib.Path(path)
    width = len(str(max(len(states) - 1, 0)))
    files = [path.with_name(f"{path.stem}_{i:0{width}d}.vtu") for i in range(len(states))]
    write_pvd(path, [(time, file) for (time, _), file in zip(states, files)])
    for (_, state), file in zip(states, files):
        state.write(file)
    return path
