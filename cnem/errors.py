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
    │   ├── ConvergenceError             an iteration out of budget (``.history``: its residuals)
    │   └── DivergenceError              a time integration whose state went non-finite
    ├── MissingExtraError (ImportError)  an optional dependency (an extra) is not installed
    └── PlotError                        `cnem.plot` cannot draw
        ├── PlotDependencyError (ImportError)    pyvista missing or unable to render
        └── PlotInputError (InputError)          a bad field name or view

    GrowthWarning (UserWarning)          a crack-growth event worth a look (not an error)
    StabilityWarning (UserWarning)       a time step above the guaranteed-stable one
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
from typing import TYPE_CHECKING, TypeVar

if TYPE_CHECKING:
    import numpy as np

_Value = TypeVar("_Value")

__all__ = ["CNEMError", "InputError", "OptionError", "GeometryError", "MaterialError",
           "FormError", "ConditionError", "SpatialError", "FractureError", "GrowthError",
           "FormatError", "HyperDualError", "LimitError", "UnsupportedError", "SolveError",
           "PlotError", "PlotDependencyError", "PlotInputError", "MissingExtraError", "GrowthWarning",
           "ConvergenceError", "DivergenceError", "StabilityWarning", "SIFWarning",
           "check_choice", "check_real", "check_count"]


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


class ConvergenceError(SolveError):
    """An iterative solve (Newton, dynamic relaxation) that ran out of iterations.

    Attributes
    ----------
    history : list of list of float
        The residual norms recorded so far, one list per load step (the last one
        is the step that did not converge).
    """

    def __init__(self, message: str, history: list | None = None):
        super().__init__(message)
        self.history = [] if history is None else history


class DivergenceError(SolveError):
    """A time integration whose state went non-finite.

    Attributes
    ----------
    step : int
        The first step with a non-finite displacement or velocity.
    point : int
        A point (global number) where it is not finite.
    """

    def __init__(self, message: str, step: int, point: int):
        super().__init__(message)
        self.step, self.point = step, point


class GrowthWarning(UserWarning):
    """A crack-growth event the user should look at (see `cnem.fracture.history.EVENT_KINDS`);
    a warning, not an error: with `StabilityWarning` and `SIFWarning` the only classes here
    outside `CNEMError`."""


class StabilityWarning(UserWarning):
    """An explicit time step above the guaranteed-stable one (it may still be stable)."""


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


#: NumPy dtype kinds that are no real numbers, and how a message names them (complex
#: numbers would lose their imaginary part, booleans and strings would become numbers).
_NOT_REAL = {"c": "complex numbers (their imaginary part would be dropped)",
             "b": "booleans", "U": "strings", "S": "bytes", "M": "dates", "m": "time spans",
             "V": "raw records"}


def check_count(name: str, value: object, *, minimum: int = 1,
                error: type[InputError] = InputError) -> int:
    """``value`` as an ``int`` of at least ``minimum``: a count (load steps, time steps,
    iterations). A float is refused even when whole (``steps=2.5`` used to run 2 steps).

    >>> check_count("steps", 3)
    3
    >>> try:
    ...     check_count("steps", 2.5)
    ... except InputError as exc:
    ...     print(exc)
    steps: expected a whole number >= 1, received 2.5 (float); pass e.g. 3
    """
    import operator

    try:
        count = None if isinstance(value, bool) else operator.index(value)
    except TypeError:
        count = None
    if count is None:
        raise error(f"{name}: expected a whole number >= {minimum}, received {value!r} "
                    f"({type(value).__name__}); pass e.g. {max(minimum, 3)}")
    if count < minimum:
        raise error(f"{name}: expected a whole number >= {minimum}, received {count}")
    return count


def check_real(name: str, value: object, *, error: type[InputError] = InputError,
               fix: str = "") -> object:
    """``value`` unchanged once it is known to hold real numbers: complex numbers (whose
    imaginary part a float conversion drops), booleans, strings, dates and ``None`` are
    refused by name, before a conversion to float could take them silently.

    >>> try:
    ...     check_real("points", [[0.0, 1j]])
    ... except InputError as exc:
    ...     print(str(exc)[:62])
    points: expected real numbers, received complex numbers (their
    """
    import numpy as np

    tail = f"; {fix}" if fix else ""
    if value is None:
        raise error(f"{name}: expected real numbers, received None{tail}")
    try:
        kind = value.dtype.kind if isinstance(value, np.ndarray) else np.asarray(value).dtype.kind
    except (TypeError, ValueError):          # ragged: the float conversion names it
        return value
    if kind in _NOT_REAL:
        raise error(f"{name}: expected real numbers, received {_NOT_REAL[kind]} (dtype kind "
                    f"{kind!r}){tail}")
    return value


def check_array(name: str, value: object, *, shape: tuple | None = None, broadcast: bool = False,
                finite: bool = True, positive: bool = False, nonnegative: bool = False,
                error: type[InputError] = InputError, fix: str = "") -> np.ndarray:
    """``value`` as a float64 array, checked at a public boundary: its shape, its dtype
    (numbers), finiteness (NaN and inf named with their first index) and sign.

    Parameters
    ----------
    name : str
        The argument's name, first in the message.
    value : array_like
    shape : tuple of int or None, optional
        The expected shape; None entries take any length (``(None, 2)``: rows of two).
    broadcast : bool
        Accept a scalar (or anything NumPy broadcasts) to ``shape`` (all ints), e.g. one
        horizon for every point.
    finite, positive, nonnegative : bool
        Reject NaN and inf (default); values ``<= 0``; values ``< 0``.
    error : type, optional
        The `InputError` subclass to raise.
    fix : str, optional
        How to fix it, appended to the message.

    Returns
    -------
    ndarray
        float64, C-contiguous (a copy when broadcast).

    >>> check_array("radii", [1.0, 2.0], shape=(2,)).tolist()
    [1.0, 2.0]
    >>> try:
    ...     check_array("radii", [1.0, float("nan")], shape=(2,))
    ... except InputError as exc:
    ...     print(exc)
    radii: expected finite values, received NaN at index 1 (shape (2,))
    """
    import numpy as np

    tail = f"; {fix}" if fix else ""
    check_real(name, value, error=error, fix=fix)
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        kind = type(value).__name__
        raise error(f"{name}: expected numbers{_shape_text(shape)}, received a {kind} that does "
                    f"not convert to one float array (ragged, or not numbers){tail}") from None
    if shape is not None:
        if broadcast:
            try:
                arr = np.broadcast_to(arr, shape)
            except ValueError:
                raise error(f"{name}: expected a number or an array of shape {shape}, received "
                            f"shape {arr.shape}{tail}") from None
        elif arr.ndim != len(shape) or any(want is not None and want != got
                                           for want, got in zip(shape, arr.shape)):
            raise error(f"{name}: expected{_shape_text(shape)}, received shape "
                        f"{arr.shape}{tail}")
    if not (arr.flags.c_contiguous and arr.flags.writeable):    # broadcast views too
        arr = arr.copy()
    if finite and not np.isfinite(arr).all():
        first = np.flatnonzero(~np.isfinite(arr.reshape(-1)))[0]
        where = np.unravel_index(first, arr.shape) if arr.ndim > 1 else first
        what = "NaN" if np.isnan(arr.reshape(-1)[first]) else f"{float(arr.reshape(-1)[first])}"
        at = f" at index {tuple(map(int, where)) if arr.ndim > 1 else int(where)}" \
            if arr.ndim else ""
        raise error(f"{name}: expected finite values, received {what}{at} (shape "
                    f"{arr.shape}){tail}")
    for flag, bad, text in ((positive, arr <= 0, "positive"), (nonnegative, arr < 0,
                                                                 "non-negative")):
        if flag and bad.any():
            first = np.flatnonzero(bad.reshape(-1))[0]
            at = f" at index {int(first)} (shape {arr.shape})" if arr.ndim else ""
            raise error(f"{name}: expected {text} values, received "
                        f"{float(arr.reshape(-1)[first])!r}{at}{tail}")
    return arr


def check_points(name: str, value: object, *, dims: tuple = (2, 3),
                 error: type[InputError] = InputError) -> np.ndarray:
    """``value`` as ``(n, d)`` float64 coordinates: `check_array` (finite, rows of
    ``d`` in ``dims``) and magnitudes below `cnem.config.COORDINATE_LIMIT` (whose squares,
    the squared distances and in-circle tests, stay representable).

    >>> try:
    ...     check_points("points", [[0.0, 0.0], [1e300, 0.0]])
    ... except InputError as exc:
    ...     print(str(exc)[:76])
    points: expected coordinates below 1e+150 in magnitude (their squared distan
    """
    from . import config

    arr = check_array(name, value, error=error, fix="drop or repair those rows")
    if arr.ndim != 2 or arr.shape[1] not in dims:
        raise error(f"{name}: expected an {' or '.join(f'(n, {d})' for d in dims)} array of "
                    f"coordinates, received shape {arr.shape}; pass one row per point")
    top = max(-float(arr.min(initial=0.0)), float(arr.max(initial=0.0)))   # max |x|, no temporary
    if top >= config.COORDINATE_LIMIT:
        raise error(f"{name}: expected coordinates below {config.COORDINATE_LIMIT:g} in "
                    f"magnitude (their squared distances must not overflow float64), received "
                    f"{top:g} (shape {arr.shape}); express the model in other units")
    return arr


def _shape_text(shape):
    """`` an array of shape (n, 2)`` for a message (None entries as letters)."""
    if shape is None:
        return ""
    names = iter("nmkpq")
    return " an array of shape (" + ", ".join(str(s) if s is not None else next(names)
                                              for s in shape) + (",)" if len(shape) == 1 else ")")
