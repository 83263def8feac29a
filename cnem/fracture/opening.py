"""Opening of a crack read off the nodes of its faces, and K_I from it.

A C-NEM model splits every crack node but the tips into one node per face
(`cnem.discretize`); a PD body made from the same cloud (`cnem.pd.Body.from_cloud`)
keeps both copies. The displacement jump between the two copies of a point is the
crack's opening, whatever solved for the displacement.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..errors import GeometryError
from ..material import effective_modulus

if TYPE_CHECKING:
    from typing import Literal
    from ..geometry.model import Model

__all__ = ["crack_opening", "k_from_opening"]


def crack_opening(model: Model, u: np.ndarray,
                  segment: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Normal opening and sliding of a straight crack at its split nodes.

    Parameters
    ----------
    model : cnem.Model
        The discretised domain (its ``node_of_point`` pairs the two copies of a
        crack-face point).
    u : (n, 2) array_like
        Displacement of the model's nodes.
    segment : (2, 2) array_like
        The crack's end points ``a, b``: the normal ``n`` is ``t = (b - a) / |b - a|``
        turned counter-clockwise, the ``+`` face the one ``n`` points to.

    Returns
    -------
    points : (k, 2) ndarray
        The split points on the segment, ordered from ``a`` to ``b``.
    opening : (k,) ndarray
        ``(u+ - u-) . n``.
    sliding : (k,) ndarray
        ``(u+ - u-) . t``.
    """
    a, b = np.asarray(segment, dtype=float)
    length = np.linalg.norm(b - a)
    if length == 0:
        raise GeometryError(f"segment: expected two distinct end points, received {a} twice")
    t = (b - a) / length
    n = np.array([-t[1], t[0]])
    u = np.asarray(u, dtype=float)
    copies = np.bincount(model.node_of_point)[model.node_of_point] == 2
    idx = np.flatnonzero(copies)
    rel = model.nodes[idx] - a
    tol = model.domain.tolerance            # far from the origin: the nodes' round-off
    on = np.abs(rel @ n) <= tol
    on &= (rel @ t >= -tol) & (rel @ t <= length + tol)
    idx = idx[on]
    plus = (model.node_sides()[idx] - a) @ n > 0
    pairs = {}
    for i, up in zip(idx, plus):
        pairs.setdefault(model.node_of_point[i], [None, None])[int(up)] = i
    if not pairs:
        return np.zeros((0, 2)), np.zeros(0), np.zeros(0)
    lower, upper = np.array(list(pairs.values())).T
    order = np.argsort((model.nodes[upper] - a) @ t)
    lower, upper = lower[order], upper[order]
    jump = u[upper] - u[lower]
    return model.nodes[upper], jump @ n, jump @ t


def k_from_opening(r: np.ndarray, opening: np.ndarray, E: float, nu: float,
                   plane: Literal["stress", "strain"], *, where: np.ndarray | None = None) -> float:
    """K_I fitted to a crack opening near a tip: ``opening = (8 K_I / E') sqrt(r / 2 pi)``.

    Parameters
    ----------
    r : (k,) array_like
        Distance of each opening sample from the tip.
    opening : (k,) array_like
    E, nu : float
    plane : {"stress", "strain"}
        ``E' = E`` in plane stress, ``E / (1 - nu^2)`` in plane strain.
    where : (k,) bool array_like, optional
        The samples fitted (default all); keep them near the tip but a few
        spacings away from it.

    Returns
    -------
    float
        The least-squares K_I; ``nan`` if no sample is fitted.
    """
    r, opening = np.asarray(r, dtype=float), np.asarray(opening, dtype=float)
    where = np.ones(len(r), bool) if where is None else np.asarray(where, dtype=bool)
    if not where.any():
        return float("nan")
    C = np.sum(opening[where] * np.sqrt(r[where])) / np.sum(r[where])
    return float(effective_modulus(E, nu, plane) * C * np.sqrt(2 * np.pi) / 8)
