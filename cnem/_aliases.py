"""Other names of modules and attributes: old ones kept for one release, and public aliases.

These tables are the only place such a name lives:

* `MOVED_MODULES`: old dotted module name -> new one. ``import cnem.assembly.linsolve``
  still works (it loads ``cnem.solvers.linsolve`` and warns once with a
  `DeprecationWarning` naming the new place); so does the attribute access
  ``cnem.assembly.linsolve`` once the old parent package is imported.
* `PUBLIC_ALIASES`: a public module name that is not where the code lives
  (``cnem.nodes`` is ``cnem.geometry.nodes``): served the same way, without a warning.
* `RENAMED_DEMOS`: old command-line names of the demos (``cnem demo bimaterial-cylinder``).
* `renamed_attributes`: for a name that changed inside a module, the module's
  ``__getattr__`` returns the new object and warns.

>>> import warnings
>>> with warnings.catch_warnings(record=True) as caught:
...     warnings.simplefilter("always")
...     import cnem.assembly.linsolve as old
>>> import cnem.solvers.linsolve as new
>>> old is new and caught[0].category is DeprecationWarning
True

Remove an entry of `MOVED_MODULES` one release after the move it records.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings
from typing import Callable

__all__ = ["MOVED_MODULES", "PUBLIC_ALIASES", "RENAMED_DEMOS", "install", "renamed_attributes"]

#: Old module name -> the module that replaced it (one release of grace).
MOVED_MODULES = {
    "cnem.assembly.conditions": "cnem.solvers.conditions",
    "cnem.assembly.solution": "cnem.solvers.solution",
    "cnem.assembly.linsolve": "cnem.solvers.linsolve",
    "cnem.assembly.multigrid": "cnem.solvers.multigrid",
    "cnem.assembly.condensation": "cnem.solvers.condensation",
    "cnem.models": "cnem.elasticity",
    "cnem.models.elasticity": "cnem.elasticity.linear",
    "cnem.models.solution": "cnem.elasticity.solution",
    "cnem.models.local_update": "cnem.elasticity.operator_update",
    "cnem.geometry.update": "cnem.geometry.model_update",
    "cnem.assembly.update": "cnem.assembly.gradient_update",
    "cnem.geometry.ridge": "cnem.demos.damage.ridge",
}

#: Old command-line names of the demos (one release): ``cnem <command> <old>`` runs
#: ``cnem <command> <new>`` with a notice on stderr (`cnem.cli.current_name`).
RENAMED_DEMOS = {
    "demo": {"cylinder": "bimaterial-cylinder", "pd-crack": "pd-vs-cnem-crack",
             "cracked-plate": "cracked-plate-geometry"},
    "pd": {"crack": "pd-vs-cnem-crack", "branching": "pd-crack-branching",
           "cpd": "cpd-examples"},
}

#: Public module name -> the module that holds the code (served without a warning).
PUBLIC_ALIASES = {
    "cnem.nodes": "cnem.geometry.nodes",
}


def _warn_moved(old: str, new: str, stacklevel: int) -> None:
    warnings.warn(f"{old} has moved to {new}; import it from there ({old} goes in the next "
                  f"release)", DeprecationWarning, stacklevel=stacklevel)


class _MovedModuleFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds a module name of `MOVED_MODULES` or `PUBLIC_ALIASES` and loads the module it
    names in its place (warning for a moved one)."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname in MOVED_MODULES or fullname in PUBLIC_ALIASES:
            return importlib.util.spec_from_loader(fullname, self)
        return None

    def create_module(self, spec):
        return None

    def exec_module(self, module):
        new = PUBLIC_ALIASES.get(module.__name__)
        if new is None:
            new = MOVED_MODULES[module.__name__]
            _warn_moved(module.__name__, new, stacklevel=4)
        # the import system hands out whatever sys.modules holds under the old name
        sys.modules[module.__name__] = importlib.import_module(new)


def install() -> None:
    """Put the finder of moved modules first on ``sys.meta_path`` (once; `cnem` does it on
    import): the tables decide where these names live, before any other finder (an
    editable install of another checkout, a stale file) is asked."""
    if not any(isinstance(finder, _MovedModuleFinder) for finder in sys.meta_path):
        sys.meta_path.insert(0, _MovedModuleFinder())


def moved_submodule(package: str, name: str):
    """The module that ``package.name`` stands for, or None when it is in neither table.

    For a package's ``__getattr__``: ``cnem.assembly.linsolve`` as an attribute.
    """
    old = f"{package}.{name}"
    if old not in MOVED_MODULES and old not in PUBLIC_ALIASES:
        return None
    return importlib.import_module(old)


def renamed_attributes(module: str, renames: dict[str, tuple[str, str]]) -> Callable:
    """A module ``__getattr__`` that serves old names of `renames` with a warning.

    Parameters
    ----------
    module : str
        The module's ``__name__`` (for the message).
    renames : dict
        Old name -> ``(module of the new object, new name)``; the new object may be a
        submodule of that module.

    Returns
    -------
    callable
        ``__getattr__(name)``; unknown names raise `AttributeError` as usual.
    """

    def __getattr__(name: str):
        if name in renames:
            where, new = renames[name]
            warnings.warn(f"{module}.{name} is now {where}.{new}; use that name ({name} goes in "
                          f"the next release)", DeprecationWarning, stacklevel=2)
            owner = importlib.import_module(where)
            if not hasattr(owner, new):                  # a submodule not imported yet
                return importlib.import_module(f"{where}.{new}")
            return getattr(owner, new)
        moved = moved_submodule(module, name)
        if moved is not None:
            return moved
        raise AttributeError(f"module {module!r} has no attribute {name!r}")

    return __getattr__
