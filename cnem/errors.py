"""Exceptions raised by cnem.

Every error says what was expected, what was received and how to fix it.
"""

__all__ = ["CNEMError", "GeometryError", "SolveError", "GrowthError", "GrowthWarning"]


class CNEMError(Exception):
    """Base class of every error raised by cnem."""


class GeometryError(CNEMError, ValueError):
    """Invalid domain, node cloud or discretisation input."""


class SolveError(CNEMError, RuntimeError):
    """A linear or nonlinear system could not be solved."""


class GrowthError(CNEMError, ValueError):
    """Invalid crack-growth input (criterion, increment, toughness, Paris constants)."""


class GrowthWarning(UserWarning):
    """A crack-growth event the user should look at (see `cnem.fracture.history.EVENT_KINDS`)."""
