"""Frames of a peridynamic run as numbered VTU files (meshio, one ``vertex`` cell per point).

ParaView opens a series ``stem_000000.vtu, stem_000010.vtu, ...`` as one
time-dependent data set; given the frames' times, the writer also keeps
``stem.pvd``, the collection with the real times, up to date after every frame. Show the
points as spheres or with "Point Gaussian".
"""

from __future__ import annotations

import os
import pathlib
from typing import TYPE_CHECKING

import meshio
import numpy as np

from ..solvers.series import write_pvd

if TYPE_CHECKING:
    from pathlib import Path
    from typing import Any

__all__ = ["FrameWriter"]


class FrameWriter:
    """Write point data at the points of a body, one VTU file per frame.

    Parameters
    ----------
    output : str or os.PathLike
        A folder (an existing one, or a path ending in a separator): files
        ``pd_<step>.vtu`` in it; otherwise a path stem: files
        ``<stem>_<step>.vtu`` (a ``.vtu`` suffix of the stem is dropped).
        Missing folders are created.
    points : (n, 2) or (n, 3) array_like
        Written with ``z = 0`` in 2-D.
    last : int
        The largest step number, to zero-pad the numbers to one width.
    """

    def __init__(self, output: str | os.PathLike, points: np.ndarray, last: int):
        text = os.fspath(output)
        path = pathlib.Path(text)
        if path.is_dir() or text.endswith((os.sep, "/")):
            path = path / "pd"
        elif path.suffix.lower() == ".vtu":
            path = path.with_suffix("")
        path.parent.mkdir(parents=True, exist_ok=True)
        self.stem, self.width = path, len(str(int(last)))
        pts = np.asarray(points, dtype=np.float64)
        self.points = np.zeros((len(pts), 3))
        self.points[:, :pts.shape[1]] = pts
        self.cells = [meshio.CellBlock("vertex", np.arange(len(pts), dtype=np.int64)[:, None])]
        self.written = []

    def write(self, step: int, time: float | None = None, **point_data: Any) -> Path | None:
        """Write ``point_data`` (arrays of ``n`` rows, as given) for ``step``; with its
        ``time``, also list the frame in ``<stem>.pvd``.

        Returns
        -------
        pathlib.Path
        """
        path = self.stem.with_name(f"{self.stem.name}_{step:0{self.width}d}.vtu")
        data = {name: np.asarray(value) for name, value in point_data.items()}
        meshio.write(path, meshio.Mesh(self.points, self.cells, point_data=data),
                     file_format="vtu", binary=True)
        if time is not None:
            self.written.append((float(time), path))
            write_pvd(self.stem.with_suffix(".pvd"), self.written)
        return path
