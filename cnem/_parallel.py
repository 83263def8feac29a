"""How parallel kernels cut their work and when they run in parallel at all: shared by
the spatial index, the shape functions and the assembly.

A kernel with ``numba.prange`` loops is declared ``@parallel_kernel("points")``
instead of ``@numba.njit(cache=True, parallel=True)``: it is compiled twice from
the one source, as a plain ``njit`` copy (``prange`` runs as ``range``) and as a
``parallel=True`` one, each only when first called. A call with fewer than
`cnem.config.PARALLEL_MIN` work items (the length of the named argument, or its
value if it is an integer) runs the serial copy. Compiling ``parallel=True``
costs several times more than a plain ``njit`` (about 28 of the 67 s of CPU the
main demo compiled, numba 0.68), and on small work a parallel region costs more
than it saves, so a first run on small models compiles and runs only the serial
copies; a large model compiles the parallel copies on its first call.

A large job done in small pieces (the smoothed gradients of a 1M-node model, pass by
pass over 10k cells) would run every piece on the serial copy; inside
``job_size(n)`` a call counts as ``n`` work items when that is more.
"""

from __future__ import annotations

import contextvars
import functools
import inspect
import types
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import numba

from . import _compile  # noqa: F401  (says once when the kernels compile)
from . import config
from .errors import InputError

__all__ = ["work_chunks", "one_thread", "parallel_kernel", "ParallelKernel", "always_parallel",
           "job_size"]

#: Work items of the job the calls in progress are pieces of (`job_size`).
_JOB_SIZE = contextvars.ContextVar("cnem_job_size", default=0)


def work_chunks() -> int:
    """Number of chunks a parallel loop is cut into (a few per thread)."""
    return 8 * numba.get_num_threads()


@contextmanager
def one_thread() -> Iterator[None]:
    """Run the parallel kernels called inside on the calling thread alone.

    For small work (a local update's few cells): a parallel region then waits
    for no other thread, which on a busy machine can cost more than the work.
    """
    before = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(before)


@contextmanager
def always_parallel() -> Iterator[None]:
    """Run the parallel copy of every `ParallelKernel` called inside, whatever its work
    (`cnem.config.PARALLEL_MIN` set to 0): for tests of the parallel copies on small
    inputs and for benchmark warm-ups that must compile them before timing."""
    before = config.PARALLEL_MIN
    config.PARALLEL_MIN = 0
    try:
        yield
    finally:
        config.PARALLEL_MIN = before


@contextmanager
def job_size(items: int) -> Iterator[None]:
    """Count every `ParallelKernel` call inside as at least ``items`` work items: the
    pieces of one large job (a model's passes) then run the parallel copies as the whole
    job would, while a small job's pieces stay on the serial ones.

    Parameters
    ----------
    items : int
        Work items of the whole job (cells, points: what its pieces' kernels count).
    """
    token = _JOB_SIZE.set(max(int(items), _JOB_SIZE.get()))
    try:
        yield
    finally:
        _JOB_SIZE.reset(token)


class ParallelKernel:
    """A kernel with a serial and a parallel compiled copy, chosen per call by its work.

    Parameters
    ----------
    py_func : function
        The kernel's Python source (``numba.prange`` loops, numba-compilable).
    work : str
        The parameter whose length (or integer value) counts the work items (at least
        the enclosing `job_size`).

    Attributes
    ----------
    serial, parallel : numba dispatchers
        ``njit(cache=True)`` and ``njit(cache=True, parallel=True)`` of ``py_func``;
        the serial copy's function is renamed ``<name>_serial`` so that the two are
        cached in different files.
    """

    def __init__(self, py_func: Callable, work: str) -> None:
        names = list(inspect.signature(py_func).parameters)
        if work not in names:
            raise InputError(f"parallel_kernel: {py_func.__qualname__} has no parameter "
                             f"{work!r} (parameters {names})")
        self._position = names.index(work)
        self._work = work
        self.parallel = numba.njit(cache=True, parallel=True)(py_func)
        self.serial = numba.njit(cache=True)(_renamed(py_func, f"{py_func.__name__}_serial"))
        functools.update_wrapper(self, py_func)

    def __call__(self, *args, **kwargs):
        item = args[self._position] if self._position < len(args) else kwargs[self._work]
        size = max(len(item) if hasattr(item, "__len__") else int(item), _JOB_SIZE.get())
        kernel = self.parallel if size >= config.PARALLEL_MIN else self.serial
        return kernel(*args, **kwargs)


def parallel_kernel(work: str) -> Callable[[Callable], ParallelKernel]:
    """Decorator: the function as a `ParallelKernel` whose work is counted by ``work``."""
    return lambda py_func: ParallelKernel(py_func, work)


def _renamed(func: types.FunctionType, name: str) -> types.FunctionType:
    """A copy of ``func`` (same code, globals, defaults) under another name."""
    copy = types.FunctionType(func.__code__, func.__globals__, name, func.__defaults__,
                              func.__closure__)
    copy.__qualname__ = func.__qualname__[: -len(func.__name__)] + name
    copy.__doc__, copy.__module__ = func.__doc__, func.__module__
    return copy
