"""Other names of modules and attributes (`cnem._aliases`): every old name resolves to the
object that replaced it and warns; every public alias resolves without a warning."""

from __future__ import annotations

import functools
import importlib
import sys
import warnings

import pytest

import cnem
from cnem._aliases import MOVED_MODULES, PUBLIC_ALIASES


def _forget(name):
    """Drop ``name`` from the imported modules, so that importing it runs the finder again."""
    sys.modules.pop(name, None)


def _attribute(dotted):
    """``cnem.a.b`` by attribute access from the `cnem` package."""
    return functools.reduce(getattr, dotted.split(".")[1:], cnem)


@pytest.mark.parametrize("old, new", sorted(MOVED_MODULES.items()))
def test_moved_module_imports_as_the_new_one_with_a_warning(old, new):
    _forget(old)
    with pytest.warns(DeprecationWarning, match=f"{old} has moved to {new}"):
        module = importlib.import_module(old)
    assert module is importlib.import_module(new)


@pytest.mark.parametrize("old, new", sorted(MOVED_MODULES.items()))
def test_moved_module_is_an_attribute_of_its_old_parent(old, new):
    for name in (old, old.rpartition(".")[0]):
        if name in MOVED_MODULES:                # never a real package: its classes would
            _forget(name)                        # be defined twice in the session
    importlib.import_module(new)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        assert _attribute(old) is sys.modules[new]


@pytest.mark.parametrize("alias, module", sorted(PUBLIC_ALIASES.items()))
def test_public_alias_imports_without_a_warning(alias, module):
    _forget(alias)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        imported = importlib.import_module(alias)
        assert _attribute(alias) is imported
    assert imported is importlib.import_module(module)


def test_nodes_is_the_public_name_of_the_node_clouds():
    from cnem.geometry.nodes import regular
    from cnem.nodes import regular as public
    assert public is regular and cnem.nodes.regular is regular


#: Renamed attributes: (old module, old name, new module, new name).
RENAMED = [
    ("cnem.solvers.condensation", "condense", "cnem.solvers.condensation", "condensed_system"),
    ("cnem.fracture", "CrackPath", "cnem.fracture.history", "GrowthHistory"),
    ("cnem.assembly", "SmoothedGradients", "cnem.assembly.gradients", "GradientCache"),
    ("cnem.assembly.gradients", "SmoothedGradients", "cnem.assembly.gradients", "GradientCache"),
    ("cnem.fracture.history", "CrackPath", "cnem.fracture.history", "GrowthHistory"),
    ("cnem.assembly.quadrature", "subdivide", "cnem.assembly.subdivision", "subdivide"),
    ("cnem.assembly.quadrature", "tip_cells", "cnem.assembly.subdivision", "tip_cells"),
    ("cnem.elasticity", "elasticity", "cnem.elasticity", "linear"),
    ("cnem.elasticity", "local_update", "cnem.elasticity", "operator_update"),
]


@pytest.mark.parametrize("module, old, where, new", RENAMED)
def test_renamed_attribute_is_the_new_object_with_a_warning(module, old, where, new):
    # importing an old submodule name (`import cnem.models.elasticity`) sets the attribute
    # on the package that now stands for the old parent; the module's __getattr__ is tested
    vars(importlib.import_module(module)).pop(old, None)
    with pytest.warns(DeprecationWarning, match=f"{module}.{old} is now {where}.{new}"):
        value = getattr(importlib.import_module(module), old)
    expected = getattr(importlib.import_module(where), new, None)
    assert value is (expected or importlib.import_module(f"{where}.{new}"))


def test_unknown_names_still_fail():
    with pytest.raises(AttributeError, match="no attribute 'nothing_here'"):
        cnem.fracture.nothing_here
    with pytest.raises(ModuleNotFoundError), warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)          # for cnem.models itself
        importlib.import_module("cnem.models.nothing_here")
