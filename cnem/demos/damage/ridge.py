"""The path of a crack through a damage (or any scalar) field sampled at points.

>>> import numpy as np
>>> g = np.arange(0.0, 10.0, 0.25)
>>> pts = np.array([(x, y) for x in g for y in g])
>>> damage = np.clip(1 - np.abs(pts[:, 1] - 5.0) / 1.0, 0, 1) * (pts[:, 0] <= 8)
>>> path = ridge_path(pts, damage, (1.0, 5.0))
>>> bool(np.abs(path[:, 1] - 5.0).max() < 1e-9), bool(abs(path[-1, 0] - 8.0) < 0.6)
(True, True)
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy import sparse
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from cnem.errors import GeometryError
from ..._sets import distinct, isin

__all__ = ["ridge_path", "ridge_bands"]


def _spacing(points):
    """Median distance of a point to its ``2 d``-th nearest neighbour (the lattice spacing
    on a lattice, the typical spacing of a scattered cloud)."""
    k = 2 * points.shape[1]
    distance, _ = cKDTree(points).query(points, k=k + 1)
    return float(np.median(distance[:, k]))


def _band(points, field, threshold, h):
    """The indices of the points with ``field >= threshold`` and their links (distances,
    CSR) to those of them within ``1.5 h``."""
    band = np.flatnonzero(field >= threshold)
    if len(band) == 0:
        raise GeometryError(f"field: expected some values >= threshold = {threshold:g}, "
                            f"received a largest value of {field.max():g}; lower the threshold")
    where = points[band]
    links = cKDTree(where).sparse_distance_matrix(cKDTree(where), 1.5 * h, output_type="coo_matrix")
    return band, sparse.csr_matrix((links.data, (links.row, links.col)), shape=links.shape)


def ridge_bands(points: ArrayLike, field: ArrayLike, *, threshold: float = 0.5,
                spacing: float | None = None) -> np.ndarray:
    """The separate bands of ``field >= threshold``: the cracks of a damage field.

    Two points of the band belong to the same crack when a chain of band points, each
    within 1.5 spacings of the next, joins them (the links of `ridge_path`).

    Parameters
    ----------
    points : (n, d) array_like
        Where the field is sampled.
    field : (n,) array_like
        Damage (or any scalar whose high values mark the crack).
    threshold : float
        The band is ``field >= threshold``.
    spacing : float, optional
        Point spacing (default as in `ridge_path`).

    Returns
    -------
    (n,) ndarray of int
        The band of every point, numbered from 0 by decreasing size; -1 outside the band.

    Raises
    ------
    GeometryError
        If no point has ``field >= threshold``, or the shapes do not match.

    >>> import numpy as np
    >>> g = np.arange(0.0, 10.0, 0.25)
    >>> pts = np.array([(x, y) for x in g for y in g])
    >>> damage = ((np.abs(pts[:, 1] - 2.0) < 0.1) & (pts[:, 0] < 6)) * 1.0
    >>> damage[(np.abs(pts[:, 1] - 7.0) < 0.1) & (pts[:, 0] > 3)] = 1.0
    >>> bands = ridge_bands(pts, damage)
    >>> [int((bands == k).sum()) for k in range(bands.max() + 1)], int(bands.min())
    ([27, 24], -1)
    """
    points = np.asarray(points, dtype=float)
    field = np.asarray(field, dtype=float)
    if points.ndim != 2 or field.shape != (len(points),):
        raise GeometryError(f"expected points (n, d) and field (n,), received shapes "
                            f"{points.shape} and {field.shape}")
    h = _spacing(points) if spacing is None else float(spacing)
    band, links = _band(points, field, threshold, h)
    _, piece = csgraph.connected_components(links, directed=False)
    rank = np.argsort(np.argsort(-np.bincount(piece), kind="stable"), kind="stable")
    labels = np.full(len(points), -1)
    labels[band] = rank[piece]
    return labels


def ridge_path(points: ArrayLike, field: ArrayLike, start: ArrayLike, *, threshold: float = 0.5,
               spacing: float | None = None, step: float | None = None) -> np.ndarray:
    """The polyline along the ridge of ``field >= threshold`` from ``start`` to its far end.

    The points where ``field >= threshold`` are linked to those within 1.5
    spacings; along these links the path runs from the point nearest ``start``
    to the one farthest from it (geodesically). The points are binned by their
    geodesic distance from the start in bins of length ``step``; the vertex of
    each bin is the ``field``-weighted centroid of the points of the bin that
    are connected (within the bin) to the farthest point's geodesic: the middle
    of the band across its direction, wherever it runs. Where the band
    branches, the path follows the longer branch.

    Parameters
    ----------
    points : (n, d) array_like
        Where the field is sampled (any cloud; d = 2 or 3).
    field : (n,) array_like
        Damage (or any scalar whose high values mark the crack).
    start : (d,) array_like
        Where the crack starts (e.g. a notch tip).
    threshold : float
        The band is ``field >= threshold``.
    spacing : float, optional
        Point spacing (default the median distance of a point to its ``2 d``-th
        nearest neighbour: the lattice spacing on a lattice).
    step : float, optional
        Length of the bins, the polyline's vertex spacing (default 3 spacings;
        about the band's width gives a smooth path).

    Returns
    -------
    (k, d) ndarray
        The vertices, from the start; a single vertex (the point nearest
        ``start``) if the band there has no extent.

    Raises
    ------
    GeometryError
        If no point has ``field >= threshold``, or the shapes do not match.
    """
    points = np.asarray(points, dtype=float)
    field = np.asarray(field, dtype=float)
    start = np.asarray(start, dtype=float)
    if points.ndim != 2 or field.shape != (len(points),) or start.shape != points.shape[1:]:
        raise GeometryError(f"expected points (n, d), field (n,) and start (d,), received "
                            f"shapes {points.shape}, {field.shape} and {start.shape}")
    h = _spacing(points) if spacing is None else float(spacing)
    band, links = _band(points, field, threshold, h)
    step = 3.0 * h if step is None else float(step)
    where, weight = points[band], field[band]
    seed = int(np.argmin(np.linalg.norm(where - start, axis=1)))
    geodesic, previous = csgraph.dijkstra(links, indices=seed, return_predecessors=True)
    far = int(np.argmax(np.where(np.isfinite(geodesic), geodesic, -1.0)))
    spine = [far]
    while spine[-1] != seed:
        spine.append(int(previous[spine[-1]]))
    reached = np.flatnonzero(np.isfinite(geodesic))
    bins = np.full(len(where), -1)
    bins[reached] = np.floor(geodesic[reached] / step).astype(int)
    links = links.tocoo()
    same = (bins[links.row] == bins[links.col]) & (bins[links.row] >= 0)
    pieces = sparse.csr_matrix((np.ones(same.sum()), (links.row[same], links.col[same])),
                               shape=links.shape)
    _, piece = csgraph.connected_components(pieces, directed=False)
    on_spine = distinct(piece[spine])
    keep = isin(piece, on_spine) & (bins >= 0)
    vertices = []
    for b in range(bins[far] + 1):
        sel = keep & (bins == b)
        if sel.any():
            vertices.append((weight[sel, None] * where[sel]).sum(axis=0) / weight[sel].sum())
    return np.array(vertices) if vertices else where[[seed]]
