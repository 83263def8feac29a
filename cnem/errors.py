"""Exceptions raised by cnem: one family under `CNEMError`.

Every error says what was expected, what was received and how to fix it. Each class
is also the builtin exception a Python user would expect (`ValueError` for a bad
value, `ImportError` for a missing optional dependency, ...), so ``except ValueError``
keeps working while ``except cnem.CNEMError`` catches everything cnem raises.

::

    CNEMError
    ├── InputError (ValueError)          a bad argument: shape, range, non-finite values
    │   ├── OptionError                  a named kind that is not one of the choices
    │   ├── GeometryError                domain, node cloud, triangulation, cells
    │   ├── MaterialError                elastic constants, PD and CPD materials
    │   ├── FormError                    weak forms, their coefficients and groups
    │   ├── ConditionError               supports and loads: `where`, components, values
    │   ├── SpatialError                 boxes, periodic cells, radii, families
    │   ├── FractureError                crack tips, integration radii, enrichment
    │   ├── GrowthError                  crack-growth criterion, increment, toughness, Paris law
    │   ├── FormatError                  files that `cnem.io` cannot write or read
    │   ├── HyperDualError               hyper-dual shapes and outputs
    │   └── LimitError                   a problem larger than a bound in `cnem.config`
    ├── UnsupportedError (NotImplementedError)   a valid request cnem does not implement
    ├── SolveError (RuntimeError)        a system that cannot be solved
    ├── MissingExtraError (ImportError)  an optional dependency (an extra) is not installed
    └── PlotError                        `cnem.plot` cannot draw
        ├── PlotDependencyError (ImportError)    pyvista missing or unable to render
        └── PlotInputError (InputError)          a bad field name or view

    GrowthWarning (UserWarning)          a crack-growth event worth a look (not an error)
    SIFWarning (UserWarning)             stress intensity factors that do not check out

>>> from cnem import errors
>>> errors.check_choice("plane", "strain", ("stress", "strain"))
'strain'
>>> try:
...     errors.check_choice("plane", "axisymmetric", ("stress", "strain"))
... except errors.CNEMError as exc:
...     print(type(exc).__name__, isinstance(exc, ValueError))
OptionError True
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TypeVar

_Value = TypeVar("_Value")

__all__ = ["CNEMError", "InputError", "OptionError", "GeometryError", "MaterialError",
           "FormError", "ConditionError", "SpatialError", "FractureError", "GrowthError",
           "FormatError", "HyperDualError", "LimitError", "UnsupportedError", "SolveError",
           "PlotError", "PlotDependencyError", "PlotInputError", "MissingExtraError", "GrowthWarning",
           "SIFWarning",
           "check_choice"]


class CNEMError(Exception):
    """Base class of every error raised by cnem."""


class InputError(CNEMError, ValueError):
    """An argument with the wrong shape, type, range or non-finite values."""


class OptionError(InputError):
    """A named kind (a method, a plane, a shape-function kind ...) not among the choices."""


class GeometryError(InputError):
    """Invalid domain, node cloud or discretisation input."""


class MaterialError(InputError):
    """Invalid material: elastic constants out of range, or the wrong kind of material."""


class FormError(InputError):
    """A weak form, or its coefficients and groups, that cannot be assembled."""


class ConditionError(InputError):
    """A support or a load that selects nothing or has values of the wrong shape."""


class SpatialError(InputError):
    """Invalid input to the spatial index: boxes, periodic cells, radii, families."""


class FractureError(InputError):
    """Invalid crack-tip input: no tip, a bad integration radius, a bad enrichment."""


class GrowthError(InputError):
    """Invalid crack-growth input (criterion, increment, toughness, Paris constants)."""


class FormatError(InputError):
    """A file name or a file's contents that `cnem.io` cannot handle."""


class HyperDualError(InputError):
    """Invalid hyper-dual input: shapes that do not broadcast, wrong vector lengths or outputs."""


class LimitError(InputError):
    """A problem larger than a bound in `cnem.config` (raise the bound or shrink the problem)."""


class UnsupportedError(CNEMError, NotImplementedError):
    """A well-formed request that cnem does not implement (the message names what does)."""


class SolveError(CNEMError, RuntimeError):
    """A linear or nonlinear system could not be solved."""


class GrowthWarning(UserWarning):
    """A crack-growth event the user should look at (see `cnem.fracture.history.EVENT_KINDS`);
    a warning, not an error (like `SIFWarning`, outside `CNEMError`)."""


class SIFWarning(UserWarning):
    """Stress intensity factors that do not check themselves: K differs between the nested
    integration discs, or a user's disc reaches past an obstacle (`cnem.fracture.sif`)."""


class MissingExtraError(CNEMError, ImportError):
    """An optional dependency is missing: the message names the extra to install."""


class PlotError(CNEMError):
    """Base class of the errors of `cnem.plot`."""


class PlotDependencyError(PlotError, ImportError):
    """pyvista is missing, or its VTK cannot render off-screen (install the plotting extra)."""


class PlotInputError(PlotError, InputError):
    """A field name, field values or view bounds that `cnem.plot` cannot draw."""


def check_choice(name: str, value: _Value, choices: Iterable[object], *,
                 error: type[InputError] = OptionError) -> _Value:
    """``value`` if it is one of ``choices``, else ``error`` naming the choices.

    Parameters
    ----------
    name : str
        The argument's name, first in the message.
    value : object
        The argument received.
    choices : iterable
        The accepted values (the keys of a dict).
    error : type, optional
        The `InputError` subclass to raise (default `OptionError`).

    Returns
    -------
    object
        ``value``, unchanged.
    """
    choices = tuple(choices)
    try:
        accepted = value in choices
    except (TypeError, ValueError):       # an array or an incomparable value
        accepted = False
    if not accepted:
        raise error(f"{name} must be one of {', '.join(map(repr, choices))}, received "
                    f"{value!r}; pass one of those")
    return value
