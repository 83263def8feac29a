"""The public names resolve and the docstring examples run."""

from __future__ import annotations

import dataclasses
import doctest
import functools
import importlib
import inspect
import pkgutil

import numpy as np
import pytest

import cnem

def _modules():
    names = ["cnem"]
    for info in pkgutil.walk_packages(cnem.__path__, prefix="cnem."):
        names.append(info.name)
    return sorted(names)


def _public_modules():
    """Every module whose own name has no leading underscore (kernels are private)."""
    return [name for name in _modules() if not name.rpartition(".")[2].startswith("_")]


def _import(module):
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        if exc.name and not exc.name.startswith("cnem"):
            pytest.skip(f"optional dependency {exc.name} is not installed")
        raise


@pytest.mark.parametrize("package", _public_modules())
def test_all_names_resolve(package):
    mod = _import(package)
    assert hasattr(mod, "__all__"), f"{package} declares no __all__"
    assert mod.__all__, f"{package} declares an empty __all__"
    assert len(set(mod.__all__)) == len(mod.__all__), f"{package}.__all__ repeats a name"
    for name in mod.__all__:
        assert getattr(mod, name, None) is not None, f"{package}.{name} does not resolve"


def test_core_workflow_names():
    """The names API.md promises for the geometry layer."""
    for name in ["Domain", "NodeCloud", "Model", "discretize", "nodes", "geometry",
                 "CNEMError", "GeometryError", "SolveError"]:
        assert name in cnem.__all__
    for name in ["regular", "irregular", "graded", "from_points"]:
        assert callable(getattr(cnem.nodes, name))
    for name in ["rectangle", "plate_with_hole", "annulus", "l_shape"]:
        assert callable(getattr(cnem.geometry, name))
    assert cnem.nodes.NodeCloud is cnem.NodeCloud is cnem.geometry.NodeCloud
    assert cnem.Domain is cnem.geometry.Domain


@pytest.mark.parametrize("module", _modules())
def test_doctests(module):
    mod = _import(module)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    report = []
    for test in finder.find(mod, module):
        runner.run(test, out=report.append)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, "".join(report)


def test_layer_packages_have_runnable_docstrings():
    """Convention 2: each layer's __init__ shows its workflow in runnable lines."""
    for package in ["cnem", "cnem.geometry"]:
        mod = importlib.import_module(package)
        tests = doctest.DocTestFinder().find(mod, package)
        assert sum(len(t.examples) for t in tests if t.name == package) >= 2


def test_frozen_data_objects():
    dom = cnem.geometry.rectangle(cracks=[[[0.0, 0.5], [0.5, 0.5]]])
    cloud = cnem.nodes.regular(dom, 0.1)
    model = cnem.discretize(cloud, progress=False)
    for obj, field in [(cloud, "points"), (model, "nodes"), (model.cells, "node")]:
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(obj, field, np.zeros(1))
    assert "nodes" in repr(model) and "cells" in repr(model)


@pytest.mark.slow
def test_no_kernel_compiles_at_import():
    """Every numba kernel compiles (or loads from its cache) on its first call, not when
    its module is imported: a fresh interpreter imports every module and finds no kernel
    (nor serial or parallel copy of a `ParallelKernel`) with a compiled signature."""
    import subprocess
    import sys
    code = ("import importlib, pkgutil, sys, cnem\n"
            "from numba.core.dispatcher import Dispatcher\n"
            "from cnem._parallel import ParallelKernel\n"
            "for info in pkgutil.walk_packages(cnem.__path__, prefix='cnem.'):\n"
            "    try:\n"
            "        importlib.import_module(info.name)\n"
            "    except ImportError as exc:\n"
            "        if (exc.name or 'cnem').startswith('cnem'): raise\n"
            "kernels = [(n, k, d) for n, m in list(sys.modules.items()) if n.split('.')[0] == 'cnem'"
            " for k, v in vars(m).items() for d in ([v.serial, v.parallel]"
            " if isinstance(v, ParallelKernel) else [v]) if isinstance(d, Dispatcher)]\n"
            "print(len(kernels), sorted(f'{n}.{k}' for n, k, v in kernels if v.signatures))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split(maxsplit=1)
    assert int(out[0]) > 50, "the kernels were not found"
    assert out[1].strip() == "[]", f"kernels compiled at import: {out[1]}"


def _public_callables(mod):
    """(qualified name, function, is_init) for every function in ``mod.__all__`` and every
    public method, property, classmethod, staticmethod and ``__init__`` defined on each
    class in it. Names re-exported from other packages (scikit-fem's ``solve``) are not
    cnem's to annotate."""
    for name in mod.__all__:
        obj = getattr(mod, name)
        if getattr(obj, "__module__", "cnem").split(".")[0] != "cnem":
            continue
        if inspect.isfunction(obj):
            yield name, obj, False
        elif inspect.isclass(obj):
            for attr, member in vars(obj).items():
                if attr.startswith("_") and attr != "__init__":
                    continue
                if isinstance(member, (staticmethod, classmethod)):
                    member = member.__func__
                elif isinstance(member, property):
                    member = member.fget
                elif isinstance(member, functools.cached_property):
                    member = member.func
                if inspect.isfunction(member):
                    yield f"{name}.{attr}", member, attr == "__init__"


@pytest.mark.parametrize("module", _public_modules())
def test_public_signatures_are_annotated(module):
    """Every public signature annotates its parameters (but self/cls) and its return
    (but ``__init__``'s)."""
    mod = _import(module)
    offenders = []
    for qualname, func, is_init in _public_callables(mod):
        signature = inspect.signature(func)
        missing = [p.name for i, p in enumerate(signature.parameters.values())
                   if p.annotation is inspect.Parameter.empty
                   and not (i == 0 and p.name in ("self", "cls"))]
        if not is_init and signature.return_annotation is inspect.Signature.empty:
            missing.append("return")
        if missing:
            offenders.append(f"{qualname}({', '.join(missing)})")
    assert not offenders, f"{module}: unannotated " + "; ".join(offenders)
