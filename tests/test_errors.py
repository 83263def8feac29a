"""Every error of cnem is a `cnem.CNEMError` subclass (`cnem.GeometryError`, a `ValueError`,
for geometry) with a message saying what and where; no module raises a bare builtin error.
The errors of each area are tested beside it: ``test_errors_geometry.py``,
``test_errors_nodes.py``, ``test_errors_spatial.py``, ``test_errors_arrays.py``,
``test_errors_pd.py``, ``test_errors_solve.py``."""

from __future__ import annotations

import ast
import builtins
import importlib
import inspect
import pathlib
import pkgutil

import numpy as np
import pytest

import cnem
from cnem import geometry, nodes


def test_error_hierarchy():
    assert issubclass(cnem.GeometryError, ValueError)
    assert issubclass(cnem.GeometryError, cnem.CNEMError)
    assert issubclass(cnem.SolveError, cnem.CNEMError)
    with pytest.raises(ValueError):
        cnem.Domain([])


# ------------------------------------------------------------ one error family
PACKAGE = pathlib.Path(cnem.__file__).parent

#: Builtin exceptions a module may raise: they belong to Python's protocols, not to bad input.
PROTOCOL = {"SystemExit": "the command line's usage errors",
            "AttributeError": "assignment to an immutable object",
            "AssertionError": "an internal invariant (a bug in cnem, not bad input)"}

BUILTIN_ERRORS = {name for name, obj in vars(builtins).items()
                  if isinstance(obj, type) and issubclass(obj, BaseException)}


def _raised_builtins(path):
    """``(line, name)`` of every ``raise`` of a builtin exception class in a file, but
    the abstract-method idiom: a bare ``raise NotImplementedError`` (no message)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Raise) and node.exc is not None:
            exc = node.exc.func if isinstance(node.exc, ast.Call) else node.exc
            abstract = isinstance(node.exc, ast.Name) and node.exc.id == "NotImplementedError"
            if isinstance(exc, ast.Name) and exc.id in BUILTIN_ERRORS and not abstract:
                found.append((node.lineno, exc.id))
    return found


def test_every_raise_uses_the_error_family():
    bad = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        for line, name in _raised_builtins(path):
            if name not in PROTOCOL:
                bad.append(f"cnem/{rel}:{line}: raise {name}")
    assert not bad, ("raise a cnem.errors class (a CNEMError subclass) instead of a builtin:\n"
                     + "\n".join(bad))


def test_the_scan_sees_bare_raises(tmp_path):
    # the walk above must not pass vacuously
    path = tmp_path / "sample.py"
    path.write_text("def f(x):\n    if x:\n        raise ValueError('no')\n    raise KeyError\n"
                    "def g():\n    raise NotImplementedError\n"
                    "def h():\n    raise NotImplementedError('no tractions')\n")
    assert sorted(_raised_builtins(path)) == [(3, "ValueError"), (4, "KeyError"),
                                              (8, "NotImplementedError")]


def _modules():
    names = ["cnem"] + [info.name for info in pkgutil.walk_packages(cnem.__path__, prefix="cnem.")]
    return sorted(name for name in names if name != "cnem.__main__")


def test_error_classes_live_in_errors():
    from cnem import errors
    classes = [obj for obj in vars(errors).values()
               if isinstance(obj, type) and issubclass(obj, BaseException)]
    assert {cls.__name__ for cls in classes} >= set(errors.__all__) - {"check_choice", "check_real", "check_count"}
    for cls in classes:
        assert issubclass(cls, errors.CNEMError) or issubclass(cls, Warning), cls
        assert cls.__module__ == "cnem.errors", cls
        assert getattr(cnem, cls.__name__) is cls, f"cnem.{cls.__name__} is not exported"
    for name in _modules():
        try:
            mod = importlib.import_module(name)
        except ImportError as exc:
            if exc.name and not exc.name.startswith("cnem"):
                continue                                    # an optional dependency
            raise
        own = [obj for _, obj in inspect.getmembers(mod, inspect.isclass)
               if issubclass(obj, BaseException) and obj.__module__ == name]
        assert name == "cnem.errors" or not own, f"{name} defines {own}: move them to cnem.errors"


def test_error_bases():
    # ValueError where the input is bad, the builtin a user would catch otherwise
    for cls in (cnem.InputError, cnem.OptionError, cnem.MaterialError, cnem.FormError,
                cnem.ConditionError, cnem.SpatialError, cnem.FractureError, cnem.GrowthError,
                cnem.FormatError,
                cnem.HyperDualError, cnem.LimitError, cnem.GeometryError, cnem.PlotInputError):
        assert issubclass(cls, ValueError) and issubclass(cls, cnem.InputError), cls
    assert issubclass(cnem.PlotDependencyError, ImportError)
    assert not issubclass(cnem.PlotDependencyError, ValueError)
    assert issubclass(cnem.PlotDependencyError, cnem.PlotError)
    assert issubclass(cnem.PlotInputError, cnem.PlotError)
    assert issubclass(cnem.UnsupportedError, NotImplementedError)
    assert issubclass(cnem.SolveError, RuntimeError)
    assert cnem.io.FormatError is cnem.FormatError
    assert cnem.plot.PlotError is cnem.PlotError
    assert cnem.hyperdual.HyperDualError is cnem.HyperDualError


def test_check_choice():
    from cnem.errors import check_choice
    assert check_choice("plane", "strain", ("stress", "strain")) == "strain"
    with pytest.raises(cnem.OptionError, match=r"plane must be one of 'stress', 'strain', "
                                                 r"received 'axi'; pass one of those"):
        check_choice("plane", "axi", ("stress", "strain"))
    with pytest.raises(cnem.OptionError, match=r"received array"):
        check_choice("kind", np.zeros(2), ("sibson",))
    with pytest.raises(cnem.FractureError):
        check_choice("functions", "cubic", {"sqrt": 1}, error=cnem.FractureError)


@pytest.fixture(scope="module")
def small_solution():
    cracked = geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.5, 0.5]]])
    model = cnem.discretize(nodes.regular(cracked, 0.25))
    prob = cnem.Elasticity(model, (1.0, 0.3))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_traction(lambda x, n: n[:, 0] > 0.5, [1.0, 0.0])
    return prob.solve(progress=False)


def _caught(call, cls):
    """``call()`` raises ``cls``, and ``except cnem.CNEMError`` catches it."""
    with pytest.raises(cls):
        call()
    try:
        call()
    except cnem.CNEMError as exc:
        return str(exc)
    raise AssertionError("no error raised")


def test_bad_input_through_public_calls(small_solution):
    from cnem import pd
    from skfem.helpers import dot, grad

    from cnem.assembly import BilinearForm, CellBasis
    model = small_solution.model
    msg = _caught(lambda: cnem.Elasticity(model, (1.0, 0.5)), cnem.MaterialError)
    assert "Poisson ratios must lie in (-1, 0.5), received [0.5]" in msg
    assert "expected an (E, nu) pair" in _caught(lambda: cnem.Elasticity(model, [1.0]),
                                                 cnem.MaterialError)
    _caught(lambda: pd.StateBased(1.0, 0.7), cnem.MaterialError)
    _caught(lambda: cnem.Elasticity(model, (1.0, 0.3), plane="axisymmetric"), cnem.OptionError)
    msg = _caught(lambda: cnem.fracture.sif(small_solution, (0.5, 0.5), radius=-1.0),
                  cnem.FractureError)
    assert "radius: expected a positive number, received -1.0" in msg
    msg = _caught(lambda: cnem.Elasticity(model, (1.0, 0.3), enrich=dict(radius=-1.0)),
                  cnem.FractureError)
    assert "radius: expected a positive number, received -1.0" in msg
    msg = _caught(lambda: cnem.spatial.family_search(model.nodes, -0.1), cnem.SpatialError)
    assert "horizon must be positive" in msg
    _caught(lambda: cnem.spatial.family_search(model.nodes, 0.1, method="octree"),
            cnem.OptionError)
    _caught(lambda: pd.Body(model.nodes, 1.0, 0.0), cnem.InputError)
    basis = CellBasis(model)
    msg = _caught(lambda: BilinearForm(lambda u, v, w: 1.0 + dot(grad(u), grad(v))).assemble(basis),
                  cnem.FormError)
    assert "not bilinear" in msg
    _caught(lambda: cnem.Elasticity(model, (1.0, 0.3)).add_dirichlet(lambda p: p[:, 0] < -1, 0),
            cnem.ConditionError)
    msg = _caught(lambda: cnem.plot.nodal_field(small_solution, "pressure"), cnem.PlotInputError)
    assert "field must be one of" in msg and "'pressure'" in msg
    with pytest.raises(ValueError):                        # and still a ValueError
        cnem.plot.nodal_field(small_solution, np.zeros(3))


def test_limits_name_their_config_bound(monkeypatch):
    from cnem import config
    pts = np.random.default_rng(0).random((30, 2))
    monkeypatch.setattr(config, "BRUTE_LIMIT", 20)
    msg = _caught(lambda: cnem.spatial.family_search(pts, 0.2, method="brute"), cnem.LimitError)
    assert "limited to 20 points, received 30" in msg and "cnem.config.BRUTE_LIMIT" in msg
    monkeypatch.setattr(config, "BRUTE_LIMIT", 30)
    assert len(cnem.spatial.family_search(pts, 0.2, method="brute").offsets) == 31


def test_non_finite_inputs_are_named():
    """A NaN crack tip, an exact stress with NaN and a PD body without bonds are errors
    that say so, not numbers."""
    dom = cnem.geometry.rectangle(2.0, 2.0, origin=(-1.0, -1.0), cracks=[[[-1.0, 0.0], [0.0, 0.0]]])
    with pytest.raises(cnem.GeometryError, match="finite"):
        dom.tip_frame((np.nan, 0.0))
    model = cnem.discretize(cnem.nodes.regular(dom, 0.25), progress=False)
    prob = cnem.Elasticity(model, (1.0, 0.3))
    prob.add_dirichlet(lambda p: p[:, 1] < -1 + 1e-9, None)
    prob.add_body_force([0.0, 1.0])
    sol = prob.solve(progress=False)
    with pytest.raises(cnem.InputError, match="finite"):
        sol.energy_error(lambda x: np.where(x[:, :1] > 0.5, np.nan, 0.0) * np.ones((1, 3)))
    assert np.isfinite(sol.energy_error(lambda x: np.zeros((len(x), 3))))
    g = np.arange(0.0, 1.0 + 1e-9, 0.1)
    pts = np.array([(x, y) for x in g for y in g])
    with pytest.raises(cnem.InputError, match="no bonds"):
        cnem.pd.Body(pts, 0.01, 0.05)
    assert len(cnem.pd.Body(pts, 0.01, 0.3).bond_j) > 0
