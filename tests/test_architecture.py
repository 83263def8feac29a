"""The layer order of the package (see ``cnem/__init__.py`` and ``docs/architecture.md``).

Every ``import`` statement of every module is read with ``ast`` — at module level and
inside functions alike — and resolved to the module it loads. A module may import
only from its own layer or lower ones, and the modules' import graph has no cycle.
"""

from __future__ import annotations

import ast
import pathlib
import subprocess
import sys

import pytest

import cnem

ROOT = pathlib.Path(cnem.__file__).resolve().parent

#: The layers, lowest first: the first part of a module's name below ``cnem`` -> rank.
LAYERS = [
    ("core", {"errors", "config", "_compile", "_parallel", "_memory", "_machine_load", "_predicates",
              "_sets", "hyperdual", "material", "exact", "_aliases"}),
    ("spatial", {"spatial"}),
    ("shape", {"shape"}),
    ("geometry", {"geometry"}),
    ("output", {"io", "plot"}),
    ("solvers", {"solvers"}),
    ("assembly", {"assembly"}),
    ("fracture", {"fracture"}),
    ("problems", {"elasticity", "heat", "fem", "pd"}),
    ("front", {"cli", "__main__", "demos"}),
]
RANK = {part: rank for rank, (_, parts) in enumerate(LAYERS) for part in parts}


def module_files():
    """Every module of the package: dotted name -> file."""
    files = {}
    for path in sorted(ROOT.rglob("*.py")):
        parts = ("cnem",) + path.relative_to(ROOT).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        files[".".join(parts)] = path
    return files


MODULES = module_files()


def _is_package(name):
    return MODULES[name].name == "__init__.py"


def _target(name):
    """The module an import of dotted ``name`` loads (the longest known prefix)."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def imports_of(name):
    """The cnem modules that module ``name`` imports anywhere in its source."""
    tree = ast.parse(MODULES[name].read_text(), filename=str(MODULES[name]))
    package = name if _is_package(name) else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "cnem":
                    found.add(_target(alias.name))
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            if source.split(".")[0] != "cnem":
                continue
            for alias in node.names:                 # `from pkg import submodule` loads it
                full = f"{source}.{alias.name}"
                found.add(full if full in MODULES else _target(source))
    found.discard(None)
    found.discard(name)
    return found


GRAPH = {name: imports_of(name) for name in MODULES}


def _rank(name):
    parts = name.split(".")
    return None if len(parts) == 1 else RANK.get(parts[1])


def test_every_module_has_a_layer():
    missing = sorted(name for name in MODULES if name != "cnem" and _rank(name) is None)
    assert not missing, f"modules outside the layer table of this test: {missing}"


def test_no_upward_import():
    upward = []
    for name, targets in GRAPH.items():
        if name == "cnem":
            continue                                 # the lazy facade re-exports every layer
        for target in targets:
            if target == "cnem":                     # the facade stands above every layer
                if _rank(name) < RANK["cli"]:
                    upward.append(f"{name} imports the package facade `cnem`: import the "
                                  "module that defines the name")
            elif _rank(target) > _rank(name):
                upward.append(f"{name} ({LAYERS[_rank(name)][0]}) imports {target} "
                              f"({LAYERS[_rank(target)][0]})")
    assert not upward, "imports against the layer order:\n" + "\n".join(sorted(upward))


def _cycles(graph):
    """Strongly connected components with more than one module (Tarjan, iterative)."""
    index, low, on_stack, stack, found = {}, {}, set(), [], []
    for start in graph:
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = set()
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.add(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        found.append(sorted(component))
            elif child not in index:
                index[child] = low[child] = len(index)
                stack.append(child)
                on_stack.add(child)
                work.append((child, iter(sorted(graph[child]))))
            elif child in on_stack:
                low[node] = min(low[node], index[child])
    return found


def test_no_import_cycle():
    cycles = _cycles({k: v - {"cnem"} for k, v in GRAPH.items() if k != "cnem"})
    assert not cycles, f"import cycles between modules: {cycles}"


def test_the_checks_can_fail():
    """The cycle finder and the resolver see what they are meant to see."""
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []
    assert _rank("cnem.geometry.model") < _rank("cnem.fracture.sif") < _rank("cnem.pd.body")
    assert "cnem.material" in GRAPH["cnem.fracture.williams"]
    assert "cnem.shape" in GRAPH["cnem.geometry.model"] or \
        "cnem.shape.natural" in GRAPH["cnem.geometry.model"]


@pytest.mark.slow
def test_import_is_lazy():
    """``import cnem`` loads no subpackage (and no numba, scipy or shapely); each one
    loads on first use."""
    code = ("import sys, cnem; heavy = sorted(m for m in sys.modules if m.split('.')[0] in "
            "('numba', 'scipy', 'shapely', 'triangle', 'skfem', 'pyvista', 'matplotlib') or "
            "m.startswith('cnem.') and m not in ('cnem.errors', 'cnem._aliases')); print(heavy); "
            "body = cnem.pd.Body; print(body.__module__, 'cnem.fracture' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.splitlines()
    assert out[0] == "[]", f"import cnem loaded {out[0]}"
    assert out[1].startswith("cnem.pd.body")


@pytest.mark.parametrize("name", ["pd", "fracture", "spatial", "Domain", "discretize"])
def test_names_reachable_after_import(name):
    assert getattr(cnem, name) is not None
    assert name in dir(cnem)
