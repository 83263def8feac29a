"""Boundary nodes picked by a predicate: shared by the 2-D and 3-D models'
``boundary_nodes``."""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..errors import ConditionError

__all__ = ["boundary_subset"]


def boundary_subset(nodes: np.ndarray, on: np.ndarray,
                    predicate: Callable | None) -> np.ndarray:
    """The boundary nodes ``on`` at which ``predicate`` holds (all of them for None).

    Parameters
    ----------
    nodes : (n, d) ndarray
    on : (k,) int64 ndarray
        The boundary nodes, sorted.
    predicate : None or callable ``(p, d) -> (p,) bool``

    Returns
    -------
    (j,) int64 ndarray

    Raises
    ------
    ConditionError
        Anything but None or a callable, or a predicate that does not return one bool
        per boundary node.
    """
    if predicate is None:
        return on
    if not callable(predicate):
        raise ConditionError(f"name_or_predicate: expected None, a boundary name or a "
                             f"predicate (p, d) -> (p,) bool, received {type(predicate).__name__}")
    mask = np.asarray(predicate(nodes[on]))
    if mask.shape != on.shape or mask.dtype != bool:
        raise ConditionError(f"name_or_predicate: expected a predicate returning a "
                             f"({len(on)},) bool array for the {len(on)} boundary nodes, "
                             f"received dtype {mask.dtype} shape {mask.shape}")
    return on[mask]
