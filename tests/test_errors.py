"""Bad input raises a `cnem.CNEMError` subclass (`cnem.GeometryError`, a `ValueError`, for
geometry) with a message saying what and where; no module raises a bare builtin error."""

from __future__ import annotations

import ast
import builtins
import dataclasses
import importlib
import inspect
import pathlib
import pkgutil
import re

import numpy as np
import pytest

import cnem
from cnem import geometry, nodes

UNIT = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
SQUARE = geometry.rectangle(1.0, 1.0)


def raises(match):
    """`pytest.raises` for a GeometryError whose message matches ``match``."""
    return pytest.raises(cnem.GeometryError, match=match)


def test_error_hierarchy():
    assert issubclass(cnem.GeometryError, ValueError)
    assert issubclass(cnem.GeometryError, cnem.CNEMError)
    assert issubclass(cnem.SolveError, cnem.CNEMError)
    with pytest.raises(ValueError):
        cnem.Domain([])


# ------------------------------------------------------------------ regions
def test_empty_region_list():
    with raises(r"expected at least one region, received an empty list"):
        cnem.Domain([])


def test_bow_tie_polygon():
    # lobes of different sizes: shapely reports the self-intersection
    with raises(r"region 0 is not a valid polygon: Self-intersection\[0\.66666\d* 0\.66666\d*\]"
                r".*bow-tie"):
        cnem.Domain([[0, 0], [2, 2], [2, 0], [0, 1]])


def test_symmetric_bow_tie_polygon():
    # both lobes of equal area: the signed area vanishes, but the polygon is a
    # bow-tie crossing itself at (0.5, 0.5), and the message must say so
    with raises(r"(?i)region 0.*(self-intersect|bow-tie|cross).*0\.5"):
        cnem.Domain([[0, 0], [1, 1], [1, 0], [0, 1]])


def test_bow_tie_in_the_second_region():
    with raises(r"region 1 is not a valid polygon: Self-intersection"):
        cnem.Domain([UNIT, [[1, 0], [3, 2], [3, 0], [1, 1]]])


def test_overlapping_regions():
    with raises(r"regions 0 and 1 overlap \(area 0\.25 around \(0\.75, 0\.75\)\)"):
        cnem.Domain([UNIT, [[0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]]])


def test_region_inside_another_overlaps():
    with raises(r"regions 0 and 1 overlap"):
        cnem.Domain([UNIT, [[0.2, 0.2], [0.4, 0.2], [0.4, 0.4], [0.2, 0.4]]])


def test_hole_pokes_out_of_the_shell():
    hole = [[0.5, 0.2], [1.5, 0.2], [1.5, 0.8], [0.5, 0.8]]
    with raises(r"region 0 is not a valid polygon: Self-intersection\[1 0\.2\].*holes must lie "
                r"strictly inside the shell"):
        cnem.Domain([(UNIT, [hole])])


def test_hole_outside_the_shell():
    # the hole lies entirely outside the shell: the message must blame the hole
    hole = [[2.0, 2.0], [3.0, 2.0], [3.0, 3.0], [2.0, 3.0]]
    with raises(r"(?i)hole"):
        cnem.Domain([(UNIT, [hole])])


def test_too_few_vertices():
    with raises(r"region 0 shell: expected a \(k, 2\) array of at least 3 vertices, received shape \(2, 2\)"):
        cnem.Domain([[0, 0], [1, 0]])


def test_non_finite_vertex():
    with raises(r"region 0 shell: vertices must be finite"):
        cnem.Domain([[0, 0], [1, 0], [np.nan, 1]])


def test_collinear_ring_has_zero_area():
    with raises(r"region 0 (is not a valid polygon|: polygon has zero area)"):
        cnem.Domain([[0, 0], [1, 0], [2, 0]])


# -------------------------------------------------------- zero-length segments
def test_repeated_vertex_in_a_ring():
    with raises(r"region 0 shell: zero-length segment between vertex 1 and vertex 2 at \(1, 0\); "
                r"remove the repeated vertex"):
        cnem.Domain([[0, 0], [1, 0], [1, 0], [1, 1], [0, 1]])


def test_nearly_repeated_vertex_in_a_ring():
    with raises(r"region 0 shell: zero-length segment .* at \(1, 0\)"):
        cnem.Domain([[0, 0], [1, 0], [1, 1e-13], [1, 1], [0, 1]])


def test_repeated_vertex_in_a_clockwise_ring():
    with raises(r"region 0 shell: zero-length segment .* at \(0\.5, 0\)"):
        cnem.Domain([[0, 0], [0, 1], [1, 1], [1, 0], [0.5, 0], [0.5, 0]])


def test_repeated_vertex_in_a_hole():
    hole = [[1, 1], [2, 1], [2, 2], [2, 2], [1, 2]]
    with raises(r"region 0 hole 0: zero-length segment .* at \(2, 2\)"):
        cnem.Domain([([[0, 0], [4, 0], [4, 4], [0, 4]], [hole])])


def test_repeated_vertex_in_a_crack():
    with raises(r"crack 0: zero-length segment between vertex 1 and vertex 2 at \(0\.4, 0\.5\)"):
        cnem.Domain(UNIT, cracks=[[[0.2, 0.5], [0.4, 0.5], [0.4, 0.5], [0.6, 0.5]]])


def test_single_point_crack():
    with raises(r"crack 0: expected a \(k, 2\) polyline with k >= 2"):
        cnem.Domain(UNIT, cracks=[[[0.2, 0.5]]])


# ------------------------------------------------------------------- cracks
def test_crack_leaving_the_domain():
    with raises(r"crack 0 leaves the domain near \(1, 0\.5\); cracks must lie inside"):
        cnem.Domain(UNIT, cracks=[[[0.5, 0.5], [1.5, 0.5]]])


def test_second_crack_leaving_the_domain():
    with raises(r"crack 1 leaves the domain"):
        cnem.Domain(UNIT, cracks=[[[0.2, 0.2], [0.3, 0.3]], [[0.5, 0.5], [0.5, -0.5]]])


def test_crack_inside_a_hole_leaves_the_domain():
    dom_args = ([(UNIT, [[[0.4, 0.4], [0.6, 0.4], [0.6, 0.6], [0.4, 0.6]]])],)
    with raises(r"crack 0 leaves the domain near \(0\.5, 0\.(45|5|55)\d*\)"):
        cnem.Domain(*dom_args, cracks=[[[0.5, 0.45], [0.5, 0.55]]])


def test_crossing_cracks():
    with raises(r"cracks 0 and 1 cross or touch near \(0\.5, 0\.5\)"):
        cnem.Domain(UNIT, cracks=[[[0.2, 0.5], [0.8, 0.5]], [[0.5, 0.2], [0.5, 0.8]]])


def test_touching_cracks():
    with raises(r"cracks 0 and 1 cross or touch near \(0\.5, 0\.5\)"):
        cnem.Domain(UNIT, cracks=[[[0.2, 0.5], [0.8, 0.5]], [[0.5, 0.5], [0.5, 0.8]]])


def test_self_crossing_crack():
    with raises(r"crack 0 crosses itself"):
        cnem.Domain(UNIT, cracks=[[[0.2, 0.2], [0.8, 0.8], [0.8, 0.2], [0.2, 0.8]]])


def test_crack_along_the_boundary():
    with raises(r"crack 0 touches the outer boundary or a hole away from its ends near \(1, 0\)"):
        cnem.Domain(UNIT, cracks=[[[0.0, 0.0], [1.0, 0.0]]])


def test_crack_along_an_interface():
    with raises(r"(?i)crack.*(boundary|interface)"):
        cnem.Domain([UNIT, [[1, 0], [2, 0], [2, 1], [1, 1]]], cracks=[[[1.0, 0.2], [1.0, 0.8]]])


# ----------------------------------------------------------------- spacing
GENERATORS = {
    "regular": lambda d, h: nodes.regular(d, h),
    "irregular": lambda d, h: nodes.irregular(d, h, seed=0),
    "graded": lambda d, h: nodes.graded(d, h, near=[[0.5, 0.5]], h_min=min(abs(h), 0.05) or 0.05),
}


@pytest.mark.parametrize("gen", list(GENERATORS))
@pytest.mark.parametrize("h, text", [(0.0, "0.0"), (-0.1, "-0.1"), (np.nan, "nan"),
                                     (np.inf, "inf")])
def test_non_positive_spacing(gen, h, text):
    with raises(rf"h must be a positive spacing, received {re.escape(text)}"):
        GENERATORS[gen](SQUARE, h)


@pytest.mark.parametrize("gen", list(GENERATORS))
@pytest.mark.parametrize("h", [np.sqrt(2.0), 2.0, 100.0])
def test_spacing_larger_than_the_domain(gen, h):
    with raises(rf"h = {h:g} is not smaller than the domain diameter 1\.41421"):
        GENERATORS[gen](SQUARE, h)


def test_graded_h_min_not_positive():
    with raises(r"h_min must be a positive spacing, received 0\.0"):
        nodes.graded(SQUARE, 0.1, near=[[0.5, 0.5]], h_min=0.0)


def test_graded_h_min_above_h():
    with raises(r"h_min \(0\.2\) must not exceed h \(0\.1\)"):
        nodes.graded(SQUARE, 0.1, near=[[0.5, 0.5]], h_min=0.2)


@pytest.mark.parametrize("growth", [0.0, -0.5, 1.5])
def test_graded_growth_out_of_range(growth):
    with raises(rf"growth must lie in \(0, 1\], received {re.escape(repr(growth))}"):
        nodes.graded(SQUARE, 0.1, near=[[0.5, 0.5]], h_min=0.02, growth=growth)


def test_graded_without_centres():
    with raises(r"`near` is empty"):
        nodes.graded(SQUARE, 0.1, near=[], h_min=0.02)


# ------------------------------------------------------------- from_points
def test_duplicate_points():
    pts = [[0.1, 0.1], [0.5, 0.5], [0.2, 0.2], [0.5, 0.5]]
    with raises(r"1 pairs of duplicated points \(closer than 1\.41e-09\), first 1 and 3; "
                r"remove the duplicates"):
        nodes.from_points(SQUARE, pts)


def test_nearly_duplicate_points():
    pts = [[0.1, 0.1], [0.5, 0.5], [0.5 + 1e-12, 0.5]]
    with raises(r"duplicated points .* first 1 and 2"):
        nodes.from_points(SQUARE, pts)


def test_points_outside():
    pts = [[0.1, 0.1], [1.5, 0.5], [0.2, 0.2], [-0.1, 0.5]]
    with raises(r"2 of 4 points lie outside the domain, first \(index: point\) 1: \[1\.5, 0\.5\], "
                r"3: \[-0\.1, 0\.5\]"):
        nodes.from_points(SQUARE, pts)


def test_point_in_a_hole_is_outside():
    dom = geometry.plate_with_hole(1.0, 1.0, 0.2)
    with raises(r"1 of 2 points lie outside the domain, first \(index: point\) 1: \[0\.5, 0\.5\]"):
        nodes.from_points(dom, [[0.1, 0.1], [0.5, 0.5]])


def test_points_of_the_wrong_shape():
    with raises(r"points: expected a \(p, 2\) array, received shape \(3,\)"):
        nodes.from_points(SQUARE, [0.1, 0.2, 0.3])


def test_non_finite_points():
    with raises(r"points: 1 rows are not finite, first \[1\]"):
        nodes.from_points(SQUARE, [[0.1, 0.1], [np.nan, 0.5]])


# -------------------------------------------------------------- discretize
def test_discretize_needs_a_node_cloud():
    with raises(r"discretize expects a NodeCloud .* received Domain"):
        cnem.discretize(SQUARE)


def test_crossing_constraint_segments():
    cloud = nodes.from_points(SQUARE, [[0.25, 0.5], [0.75, 0.5], [0.5, 0.25], [0.5, 0.75]])
    bad = dataclasses.replace(
        cloud, segments=np.concatenate([cloud.segments, [[0, 1], [2, 3]]]),
        segment_kind=np.concatenate([cloud.segment_kind, [2, 2]]).astype(np.int8))
    with raises(r"constraint segments intersect away from nodes \(1 crossing points\): "
                r"at \(0\.5, 0\.5\)"):
        cnem.discretize(bad)


# ------------------------------------------------------------------ builders
def test_builder_errors():
    with raises(r"width must be a positive number, received -1"):
        geometry.rectangle(-1.0, 1.0)
    with raises(r"does not fit inside the plate"):
        geometry.plate_with_hole(1.0, 1.0, 0.6)
    with raises(r"radii must be >= 2 positive increasing numbers"):
        geometry.annulus([2.0, 1.0])
    with raises(r"angles must satisfy 0 < stop - start < 2 pi"):
        geometry.annulus([1.0, 2.0], angles=(0.0, 7.0))
    with raises(r"cut \(1\.0\) must be smaller than size \(1\.0\)"):
        geometry.l_shape(1.0, 1.0)


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
    assert {cls.__name__ for cls in classes} >= set(errors.__all__) - {"check_choice"}
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
    that say so, not numbers (issue 19)."""
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
