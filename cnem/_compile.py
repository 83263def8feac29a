"""Say once when numba compiles cnem's kernels (an empty or stale cache: first run only).

The kernels are ``@numba.njit(cache=True)``: the first call in a fresh
environment compiles them (about 30 s of CPU for the main demo) and writes
them to numba's on-disk cache; later runs load them in a moment. Each kernel
module imports this one, which registers a numba compile listener: the first
time a cnem kernel is compiled rather than loaded, it logs `NOTICE` at INFO on
the ``cnem._compile`` logger; every compilation is logged at DEBUG with its
time. The command line and the demos (`cnem.cli`) show the INFO line on the
terminal; in a script, ``logging.basicConfig(level=logging.INFO)`` shows it.
"""

from __future__ import annotations

import logging
import time

from numba.core import event

__all__ = ["NOTICE", "compiled"]

#: The line logged once, at the first compilation of a cnem kernel.
NOTICE = ("compiling numba kernels, first run only (about 40 s of CPU for the main demo; "
          "cached on disk for the next runs; `cnem warmup` does it ahead)")

logger = logging.getLogger(__name__)

#: ``module.function`` of every cnem kernel compiled in this process (in order).
compiled: list[str] = []


class _Listener(event.Listener):
    """Logs the start of the first cnem compilation at INFO, each one at DEBUG with its time."""

    def __init__(self) -> None:
        self._started: list[float] = []
        self._announced = False

    def on_start(self, ev: event.Event) -> None:
        self._started.append(time.perf_counter())
        if not self._announced and _name(ev) is not None:
            self._announced = True
            logger.info(NOTICE)

    def on_end(self, ev: event.Event) -> None:
        seconds = time.perf_counter() - self._started.pop()
        name = _name(ev)
        if name is not None:
            compiled.append(name)
            logger.debug("compiled %s in %.2f s", name, seconds)


def _name(ev: event.Event) -> str | None:
    """``module.function`` of the kernel a compile event is about, ``None`` if not cnem's."""
    func = ev.data["dispatcher"].py_func
    return f"{func.__module__}.{func.__qualname__}" if func.__module__.startswith("cnem.") else None


event.register("numba:compile", _Listener())
