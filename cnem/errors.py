"""Exceptions raised by cnem.

Every error says what was expected, what was received and how to fix it.
"""

__all__ = ["CNEMError", "GeometryError", "SolveError"]


class CNEMError(Exception):
    """Base class of every error raised by cnem."""


class GeometryError(CNEMError, ValueError):
    """Invalid domain, node cloud or discretisation input."""


class SolveError(CNEMError, RuntimeError):
    """A linear or nonlinear system could not be solved."""


class MissingExtraError(CNEMError, ImportError):
    """An optional dependency is missing: the message names the extra to install."""
