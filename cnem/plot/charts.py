"""Charts with matplotlib, off-screen: the one place that chooses matplotlib's backend.

Every chart of the package and its demos draws through `offscreen_pyplot`, which
selects the Agg backend (no window, no display needed) before ``matplotlib.pyplot``
is imported; the caller saves its figure (``fig.savefig(path)``) and closes it.

>>> from cnem.plot.charts import offscreen_pyplot
>>> plt = offscreen_pyplot()                               # doctest: +SKIP
>>> fig, ax = plt.subplots(figsize=(4, 3))                 # doctest: +SKIP
>>> plt.get_backend().lower()                              # doctest: +SKIP
'agg'
"""

from __future__ import annotations

from types import ModuleType

from ..errors import PlotDependencyError
from .fields import INSTALL_HINT

__all__ = ["offscreen_pyplot"]


def offscreen_pyplot() -> ModuleType:
    """``matplotlib.pyplot`` drawing off-screen (the Agg backend).

    Returns
    -------
    module
        ``matplotlib.pyplot``, its figures rendered to files only.

    Raises
    ------
    PlotDependencyError
        matplotlib cannot be imported (install the plotting extra).
    """
    try:
        import matplotlib
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise PlotDependencyError(f"charts need matplotlib, which cannot be imported ({exc}); "
                                  f"{INSTALL_HINT}") from exc
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt
