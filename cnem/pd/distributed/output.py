"""Frames of a distributed run: one VTU piece per rank and one ``.pvtu`` per frame.

ParaView opens ``stem_<step>.pvtu`` as one data set (the pieces
``stem_r<rank>_<step>.vtu`` hold each rank's owned points), and the numbered
``.pvtu`` files as a time series.
"""

from __future__ import annotations

from xml.sax.saxutils import quoteattr
from typing import TYPE_CHECKING

import numpy as np

from ..frames import FrameWriter

if TYPE_CHECKING:
    import os
    from pathlib import Path
    from typing import Any

__all__ = ["PieceWriter"]


class PieceWriter:
    """Write point data of the owned points of every rank, with rank 0's ``.pvtu`` index.

    Parameters
    ----------
    output : str or os.PathLike
        As in `cnem.pd.frames.FrameWriter` (a folder or a path stem).
    comm : mpi4py communicator
    points : (o, d) ndarray
        This rank's owned points.
    last : int
        The largest step number (zero-padding width).
    """

    def __init__(self, output: str | os.PathLike, comm: Any, points: np.ndarray, last: int):
        self.comm = comm
        stem = FrameWriter(output, points[:0], last).stem
        self.stem, self.width = stem, len(str(int(last)))
        self.piece = FrameWriter(stem.with_name(f"{stem.name}_r{comm.rank:04d}"), points, last)

    def _piece_name(self, rank, step):
        return f"{self.stem.name}_r{rank:04d}_{step:0{self.width}d}.vtu"

    def write(self, step: int, **point_data: Any) -> Path | None:
        """Write this rank's piece (and, on rank 0, the index) of frame ``step``.

        Returns
        -------
        pathlib.Path
            The ``.pvtu`` file.
        """
        self.piece.write(step, **point_data)
        path = self.stem.with_name(f"{self.stem.name}_{step:0{self.width}d}.pvtu")
        if self.comm.rank == 0:
            arrays = "".join(
                f'      <PDataArray type="Float64" Name={quoteattr(name)} '
                f'NumberOfComponents="{1 if np.ndim(v) == 1 else np.shape(v)[1]}"/>\n'
                for name, v in point_data.items())
            pieces = "".join(f'    <Piece Source={quoteattr(self._piece_name(r, step))}/>\n'
                             for r in range(self.comm.size))
            path.write_text(
                '<?xml version="1.0"?>\n'
                '<VTKFile type="PUnstructuredGrid" version="0.1" byte_order="LittleEndian" '
                'header_type="UInt64">\n'
                '  <PUnstructuredGrid GhostLevel="0">\n'
                f'    <PPointData>\n{arrays}    </PPointData>\n'
                '    <PPoints>\n'
                '      <PDataArray type="Float64" NumberOfComponents="3"/>\n'
                '    </PPoints>\n'
                f'{pieces}'
                '  </PUnstructuredGrid>\n'
                '</VTKFile>\n')
        return path
