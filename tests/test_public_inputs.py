"""Every public entry point refuses complex, boolean, NaN and wrongly shaped arrays with a
`cnem.CNEMError`, generated from the public names (issue 36).

The entry points are found by walking ``__all__`` from ``cnem`` down through every public
subpackage and module it names, so a new public name is covered by construction: each
callable needs an example call in `EXAMPLES` (or a reason in `NOT_ENTRY_POINTS`), and the
suite fails with "add an example call for X to the table" until it has one. Its array-like
parameters (the annotation names an array: ``ArrayLike``, ``ndarray``, ``Sequence[float]``,
a ``tuple`` of floats) are read from the signature; each in turn is replaced by a complex
array, a boolean array, an array holding a NaN, and an array of the wrong shape (a column
more, or one axis more for a vector, or a vector where a number is expected), and the call
must raise a `cnem.CNEMError` subclass whose message names the parameter — not a bare ``TypeError`` / ``ValueError`` /
``IndexError`` from deep inside, and not a silent result.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import inspect
import re
import types
import warnings
from collections.abc import Callable

import numpy as np
import scipy.spatial
import pytest

import cnem

BAD_KINDS = ("complex", "bool", "nan", "shape", "scalar")

#: Public callables that are not entry points a user calls with arrays, and why.
NOT_ENTRY_POINTS = {
    # results the library builds and hands back (frozen dataclasses of checked arrays)
    "cnem.NodeCloud": "a result of cnem.nodes.*",
    "cnem.Model": "a result of cnem.discretize",
    "cnem.ElasticSolution": "a result of Elasticity.solve",
    "cnem.elasticity.HyperelasticSolution": "a result of Hyperelasticity.solve",
    "cnem.geometry.Cells": "a result of cnem.discretize (model.cells)",
    "cnem.geometry.PSLG": "built by Domain from checked polygons",
    "cnem.geometry.SegmentKind": "an enumeration",
    "cnem.fracture.SIFResult": "a result of cnem.fracture.sif",
    "cnem.fracture.GrowthHistory": "a result of cnem.fracture.grow",
    "cnem.fracture.Step": "a record of cnem.fracture.grow",
    "cnem.fracture.GrowthEvent": "a record of cnem.fracture.grow",
    "cnem.io.CellMesh": "a result of cnem.io.read",
    "cnem.spatial.Family": "a result of cnem.spatial.family_search",
    "cnem.pd.StaticSolution": "a result of Problem.solve_static",
    "cnem.pd.DynamicRun": "a result of Problem.run_dynamic",
    "cnem.pd.Relaxation": "a result of Problem.relax",
    "cnem.fem.P1Solution": "a result of P1Elasticity.solve",
    "cnem.assembly.SmoothedGradient": "sparse operators built by smoothed_gradient",
    "cnem.shape.TetMesh": "a result of cnem.shape.tet_mesh",
    # callables that take functions, forms or sparse matrices, not arrays of numbers
    "cnem.assembly.BilinearForm": "wraps a Python function (a weak form)",
    "cnem.assembly.LinearForm": "wraps a Python function (a weak form)",
    "cnem.assembly.Functional": "wraps a Python function (a weak form)",
    "cnem.assembly.asm": "assembles a form on a basis (no array arguments)",
    "cnem.assembly.condense": "scikit-fem's condense on the user's sparse system",
    "cnem.assembly.solve": "scikit-fem's solve on the user's sparse system",
    "cnem.elasticity.elasticity_form": "a weak form: called by asm with fields",
    "cnem.heat.conduction_form": "a weak form: called by asm with fields",
    "cnem.heat.HeatSolution": "a result of HeatConduction.solve",
    "cnem.heat.HeatSolution.from_temperature": "plumbing: called by HeatConduction.solve",
    "cnem.plot.offscreen_pyplot": "no arguments",
    "cnem.material.Material": "an abstract base class",
    "cnem.material.Hyperelastic": "an abstract base class",
    **{f"cnem.material.Hyperelastic.{method}": "abstract (raises NotImplementedError): those "
       "of NeoHookean and SaintVenantKirchhoff are tried" for method in ("energy", "evaluate")},
    "cnem.material.check_plane": "a validator (takes a dimension and a plane name)",
    "cnem.material.check_stiffness": "a validator called on checked moduli",
    # methods that are plumbing: the library calls them with arrays it built and checked
    **{name: "plumbing: called by the library with the arrays it built" for name in (
        "cnem.Elasticity.body_forces_at", "cnem.Elasticity.preconditioner_matrix",
        "cnem.Elasticity.solver_options", "cnem.Hyperelasticity.solver_options",
        "cnem.ElasticSolution.from_dofs",
        "cnem.ElasticSolution.write_fields", "cnem.elasticity.HyperelasticSolution.from_dofs",
        "cnem.fem.P1Solution.from_dofs",
        "cnem.fem.P1Solution.write_fields", "cnem.pd.StaticSolution.write_fields",
        "cnem.geometry.Cells.subset", "cnem.assembly.CellBasis.at_points",
        "cnem.assembly.CellBasis.from_operators", "cnem.assembly.BilinearForm.assemble",
        "cnem.assembly.BilinearForm.assemble_over",
        "cnem.fracture.Enrichment.edge_loads", "cnem.fracture.Enrichment.evaluate",
        "cnem.fracture.Enrichment.in_support", "cnem.fracture.Enrichment.smoothed_gradient",
        "cnem.fracture.Enrichment.values", "cnem.spatial.RTree.from_points_in",
        "cnem.pd.CPD.measure_derivatives", "cnem.pd.Problem.energy_density",
        "cnem.pd.Problem.displacement_gradient", "cnem.pd.Problem.stress_tensor")},
    "cnem.pd.StaticSolution.stress_at": "refuses every call (the base Solution.stress_at: "
                                        "no pointwise stress but C-NEM's)",
    # hyper-dual arithmetic: elementwise NumPy semantics on any shape (NaN in, NaN out),
    # inside the energies of the PD and finite-strain materials
    **{f"cnem.hyperdual.{name}": "elementwise hyper-dual math (NumPy semantics)"
       for name in ("sqrt", "exp", "log", "sin", "cos", "tan", "arcsin", "arccos", "arctan",
                    "sinh", "cosh", "tanh", "power")},
}


def _public_callables():
    """``{qualified name: callable}`` over ``__all__`` from ``cnem`` down, each object once
    (under the first name met, breadth first), exceptions left out."""
    found, seen, queue, modules = {}, set(), ["cnem"], set()
    while queue:
        modname = queue.pop(0)
        if modname in modules:
            continue
        modules.add(modname)
        try:
            module = importlib.import_module(modname)
        except ImportError as exc:                      # an optional extra
            if exc.name and exc.name.startswith("cnem"):
                raise
            continue
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name)
            if isinstance(obj, types.ModuleType):
                queue.append(obj.__name__)
            elif callable(obj) and not (inspect.isclass(obj) and issubclass(obj, BaseException)):
                if id(obj) not in seen:
                    seen.add(id(obj))
                    found[f"{modname}.{name}"] = obj
    return found


def _public_methods(classes):
    """``{"<class name>.<method>": (class, method name)}``: the public methods (and class
    methods) of the public classes that take arrays, each function once, those already
    public as functions (``cnem.fracture.tip_frame`` is ``Domain.tip_frame``) left out."""
    seen = {id(obj) for obj in classes.values()}
    found = {}
    for name, cls in classes.items():
        if not inspect.isclass(cls):
            continue
        for method in dir(cls):
            attr = inspect.getattr_static(cls, method)
            func = attr.__func__ if isinstance(attr, (classmethod, staticmethod)) else attr
            if method.startswith("_") or not inspect.isfunction(func) \
                    or not func.__module__.startswith("cnem") or id(func) in seen:
                continue
            seen.add(id(func))
            if _array_parameters(func):
                found[f"{name}.{method}"] = (cls, method)
    return found


PUBLIC = _public_callables()

_ARRAY_WORDS = re.compile(r"ArrayLike|ndarray|Sequence\[float|tuple\[float")


def _without_callables(text):
    """An annotation's text without its ``Callable[...]`` parts (brackets matched, so that
    ``Callable[[str], np.ndarray]`` goes whole: a callable returning an array is no array)."""
    while (start := text.find("Callable[")) >= 0:
        depth, end = 0, start + len("Callable")
        for end in range(end, len(text)):
            depth += {"[": 1, "]": -1}.get(text[end], 0)
            if depth == 0:
                break
        text = text[:start] + text[end + 1:]
    return text


def _array_parameters(obj):
    """Names of the parameters of ``obj`` whose annotation names an array of numbers
    (a callable's return annotation does not count)."""
    try:
        signature = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    names = []
    for name, par in signature.parameters.items():
        text = par.annotation if isinstance(par.annotation, str) else str(par.annotation)
        if _ARRAY_WORDS.search(_without_callables(text)):
            names.append(name)
    return names


METHODS = _public_methods(PUBLIC)

#: What the test calls: public functions and classes, and the methods that take arrays.
ENTRY_POINTS = [name for name in [*PUBLIC, *METHODS] if name not in NOT_ENTRY_POINTS]


def _entry(name):
    """The entry point an example calls: ``"f (on a Domain3D)"`` is a second example of
    ``f``, with other arguments (the node clouds on a 3-D body)."""
    return name.split(" (")[0]


def _function(name):
    """The function behind an entry point (a method's, unbound)."""
    name = _entry(name)
    if name in METHODS:
        cls, method = METHODS[name]
        return getattr(cls, method)
    return PUBLIC[name]


# --------------------------------------------------------------------------- fixtures


@functools.cache
def _solid_solution():
    """A 3-D elasticity solution on the fixtures' box cloud (for 3-D pictures)."""
    prob = cnem.Elasticity(cnem.discretize(fx().cloud3), (1.0, 0.3))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_body_force([0.0, 0.0, -1.0])
    return prob.solve(progress=False)


@functools.cache
def fx():
    """Tiny models shared by the examples (built once, on first use)."""
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    crack = np.array([[0.0, 0.5], [0.5, 0.5]])
    dom = cnem.Domain(square, cracks=[crack])
    cloud = cnem.nodes.regular(dom, 0.25)
    model = cnem.discretize(cloud)
    prob = _setup(model)
    sol = prob.solve()
    lattice = np.array([(x, y) for x in np.arange(5) * 0.25 for y in np.arange(5) * 0.25])
    body = cnem.pd.Body(lattice, 0.0625, 0.76)
    pd_prob = cnem.pd.Problem(body, cnem.pd.BondBased(1.0))
    pd_prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    pd_prob.add_body_force([1.0, 0.0])
    pd_sol = pd_prob.solve_static()
    inside = np.array([[0.3, 0.3], [0.7, 0.8]])
    box = cnem.geometry.box((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))
    cloud3 = cnem.nodes.regular(box, 0.5)
    tet_nodes = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0.2, 0.2, 0.2]], float)
    p1 = cnem.fem.P1Elasticity(cnem.Domain(square), (1.0, 0.3), nodes=20)
    p1.add_dirichlet(lambda p: p[:, 1] < 1e-9, None)
    p1.add_traction(lambda x, n: x[:, 1] > 1 - 1e-9, [0.0, 1.0])
    return types.SimpleNamespace(p1_sol=p1.solve(), square=square, crack=crack, dom=dom, cloud=cloud, model=model,
                                 prob=prob, sol=sol, lattice=lattice, body=body,
                                 pd_prob=pd_prob, pd_sol=pd_sol, inside=inside,
                                 tip=np.array([0.5, 0.5]), box=box, cloud3=cloud3,
                                 inside3=np.array([[0.3, 0.3, 0.3], [0.7, 0.8, 0.6]]),
                                 named=cnem.Domain(square, boundaries={"bottom": square[:2]}),
                                 tet_nodes=tet_nodes, tets=scipy.spatial.Delaunay(tet_nodes).simplices)


def _pd_problem(f):
    """A fresh PD problem on the lattice of `fx` (for calls that add conditions)."""
    prob = cnem.pd.Problem(f.body, cnem.pd.BondBased(1.0))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    return prob


def _heat(f):
    """A heat-conduction solution on the model of `fx`."""
    prob = cnem.HeatConduction(f.model, 1.0)
    prob.add_temperature(lambda p: p[:, 0] < 1e-9, 0.0)
    prob.add_flux(lambda x, nrm: nrm[:, 0] > 0.5, 1.0)
    return prob.solve()


def _setup(model):
    """The problem of `fx` on a grown model (for `cnem.fracture.grow`)."""
    prob = cnem.Elasticity(model, (1.0, 0.3))
    prob.add_dirichlet(lambda p: p[:, 1] < 1e-9, None)
    prob.add_traction(lambda x, n: x[:, 1] > 1 - 1e-9, [0.0, 1.0])
    return prob


@dataclasses.dataclass(frozen=True)
class Example:
    """A valid call: ``arguments(fx())`` gives the keyword arguments (by parameter name);
    ``skip`` maps ``(param, kind)``, ``param`` or ``kind`` to why that bad value is valid
    there."""

    arguments: Callable
    skip: dict = dataclasses.field(default_factory=dict)

    def skipped(self, param, kind):
        return self.skip.get((param, kind)) or self.skip.get(param) or self.skip.get(kind)


_ELEMENTWISE = "elementwise: any shape is valid"
_SCALAR_OK = "a number is valid (one value for every point)"
_MASK = "a boolean mask is a valid selection"
#: The solution classes and the fixture holding one of each.
_SOLUTIONS = {"cnem.ElasticSolution": "sol", "cnem.pd.StaticSolution": "pd_sol",
              "cnem.fem.P1Solution": "p1_sol"}
_THREE_D = "(n, 3) points are valid: a 3-D body"
_ONE_PERIOD = "one number is a valid period (the same length along every axis)"
_NAN_IN_NAN_OUT = "elementwise formula: NaN entries give NaN, as in NumPy"
_NAN_PER_MATRIX = "a formula per matrix: NaN entries give NaN, as in numpy.linalg"
_NAN_PER_POINT = ("a law per point: a NaN gradient gives NaN energy and stress there, as an "
                  "inverted one does, and Newton names the non-finite residual")
#: Deformation gradients ``(q, d, d)`` for the hyperelastic laws and hyper-dual matrices.
_GRADIENTS = np.array([[[1.1, 0.2], [0.0, 0.9]], [[1.0, 0.0], [0.1, 1.2]]])
#: Two 3-D vectors ``(2, 3)`` for the hyper-dual vector functions.
_VECTORS = np.array([[1.0, 2.0, 2.0], [0.5, -1.0, 3.0]])
_WIDE = np.array([[[1.0, 0.5, 0.0], [0.0, 1.0, 0.3]]] * 2)     # (2, 2, 3): not square
_FIELDS = {("point_data", "nan"): "NaN is the VTU fill value of a field",
           ("cell_data", "nan"): "NaN is the VTU fill value of a field",
           ("point_data", "bool"): "a boolean mask is a valid field (written 0 / 1)",
           ("cell_data", "bool"): "a boolean mask is a valid field (written 0 / 1)"}

EXAMPLES = {
    "cnem.Domain": Example(lambda f: dict(regions=f.square, cracks=[f.crack])),
    "cnem.discretize": Example(lambda f: dict(cloud=f.cloud)),
    "cnem.Elasticity": Example(lambda f: dict(model=f.model, materials=(1.0, 0.3))),
    "cnem.geometry.nodes.regular": Example(lambda f: dict(domain=f.dom, h=0.25)),
    "cnem.geometry.nodes.irregular": Example(lambda f: dict(domain=f.dom, h=0.25)),
    "cnem.geometry.nodes.graded": Example(
        lambda f: dict(domain=f.dom, h=0.25, near=f.tip[None, :], h_min=0.1)),
    "cnem.geometry.nodes.from_points": Example(lambda f: dict(domain=f.dom, points=f.inside)),
    "cnem.geometry.rectangle": Example(
        lambda f: dict(width=1.0, height=1.0, origin=np.array([0.0, 0.0]), cracks=[f.crack])),
    "cnem.geometry.plate_with_hole": Example(
        lambda f: dict(center=np.array([0.5, 0.5]), cracks=[np.array([[0.0, 0.5],
                                                                      [0.2, 0.5]])])),
    "cnem.geometry.annulus": Example(
        lambda f: dict(radii=np.array([1.0, 2.0]), angles=np.array([0.0, 1.5]),
                       center=np.array([0.0, 0.0]), cracks=[np.array([[1.2, 0.2],
                                                                      [1.6, 0.2]])])),
    "cnem.geometry.l_shape": Example(
        lambda f: dict(cracks=[np.array([[0.0, 0.25], [0.2, 0.25]])])),
    "cnem.geometry.arc": Example(
        lambda f: dict(center=np.array([0.0, 0.0]), radius=1.0, start=0.0, stop=1.0,
                       spacing=0.2)),
    "cnem.assembly.CellBasis": Example(lambda f: dict(model=f.model)),
    "cnem.assembly.GradientCache": Example(lambda f: dict(model=f.model)),
    "cnem.assembly.smoothed_gradient": Example(lambda f: dict(model=f.model)),
    "cnem.assembly.fan_gradient": Example(lambda f: dict(model=f.model)),
    "cnem.assembly.cell_edges": Example(lambda f: dict(cells=f.model.cells)),
    "cnem.assembly.select_nodes": Example(
        lambda f: dict(nodes=f.model.nodes, where=np.array([0, 1])),
        skip={("where", "bool"): _MASK, ("nodes", "shape"): _THREE_D}),
    "cnem.elasticity.lame": Example(lambda f: dict(E=np.array([1.0, 2.0]),
                                                   nu=np.array([0.3, 0.2]), plane="stress"),
                                    skip={"shape": _ELEMENTWISE, "scalar": _ELEMENTWISE}),
    "cnem.elasticity.stiffness_matrix": Example(lambda f: dict(E=1.0, nu=0.3, plane="stress"),
                                                skip={"shape": _ELEMENTWISE}),
    "cnem.elasticity.von_mises": Example(lambda f: dict(stress=f.sol.stress),
                                         skip={"nan": _NAN_IN_NAN_OUT}),
    "cnem.exact.LayeredCylinder": Example(
        lambda f: dict(radii=np.array([1.0, 2.0]), materials=np.array([[1.0, 0.3]]),
                       center=np.array([0.0, 0.0]))),
    "cnem.exact.ThickSphere": Example(
        lambda f: dict(inner=0.5, outer=1.0, E=1.0, nu=0.3, center=np.zeros(3))),
    "cnem.exact.CentralCrack": Example(lambda f: dict(half_length=1.0)),
    "cnem.exact.rayleigh_speed": Example(lambda f: dict(E=1.0, nu=0.3, density=1.0)),
    "cnem.exact.inflated_sphere_pressure": Example(
        lambda f: dict(inner_stretch=np.array([1.5, 2.0]), inner=1.0, outer=2.0, mu=1.0),
        skip={"shape": _ELEMENTWISE, "scalar": _ELEMENTWISE}),
    "cnem.exact.rivlin_torsion": Example(
        lambda f: dict(twist=np.array([0.5, 1.0]), radius=1.0, mu=1.0),
        skip={"shape": _ELEMENTWISE, "scalar": _ELEMENTWISE}),
    "cnem.fracture.sif": Example(lambda f: dict(sol=f.sol, tip=f.tip)),
    "cnem.fracture.Enrichment": Example(
        lambda f: dict(model=f.model, tips=f.tip[None, :], radius=0.3)),
    "cnem.fracture.tip_frame": Example(lambda f: dict(self=f.dom, tip=f.tip)),
    "cnem.fracture.williams": Example(
        lambda f: dict(r=np.array([0.1, 0.2]), theta=np.array([0.0, 1.0]), KI=1.0, KII=0.0,
                       E=1.0, nu=0.3, plane="stress"),
        skip={"shape": _ELEMENTWISE, "scalar": _ELEMENTWISE}),
    "cnem.fracture.nodal_williams": Example(
        lambda f: dict(model=f.model, tip=f.tip, KI=1.0, KII=0.0, E=1.0, nu=0.3,
                       plane="stress")),
    "cnem.fracture.polar": Example(
        lambda f: dict(points=f.inside, tip=f.tip, direction=np.array([1.0, 0.0]))),
    "cnem.fracture.kappa": Example(lambda f: dict(nu=np.array([0.3, 0.2]), plane="stress"),
                                   skip={"shape": _ELEMENTWISE, "scalar": _ELEMENTWISE}),
    "cnem.fracture.effective_modulus": Example(
        lambda f: dict(E=np.array([1.0, 2.0]), nu=np.array([0.3, 0.2]), plane="stress"),
        skip={"shape": _ELEMENTWISE, "scalar": _ELEMENTWISE}),
    "cnem.fracture.grow": Example(
        lambda f: dict(domain=f.dom, cloud=f.cloud, setup=_setup, increment=0.1, steps=1,
                       paris=np.array([1.0, 3.0]), progress=False)),
    "cnem.fracture.Refinement": Example(lambda f: dict(spacing=0.05)),
    "cnem.fracture.kink": Example(lambda f: dict(criterion="max_hoop", KI=1.0, KII=0.5)),
    "cnem.io.write": Example(
        lambda f: dict(model=f.model, path=f.tmp / "m.vtu",
                       point_data=dict(u=f.sol.u), cell_data=dict(s=f.sol.stress)),
        skip=_FIELDS),
    "cnem.io.write_nodes": Example(
        lambda f: dict(model=f.model, path=f.tmp / "n.vtu", point_data=dict(u=f.sol.u)),
        skip=_FIELDS),
    "cnem.io.write_points": Example(
        lambda f: dict(points=f.lattice, path=f.tmp / "p.vtu",
                       cells=np.array([[0, 1, 5]]),
                       point_data=dict(u=f.lattice), cell_data=dict(a=np.ones(1))),
        skip={**_FIELDS, ("points", "shape"): _THREE_D}),
    "cnem.io.read": Example(lambda f: dict(path=cnem.io.write(f.model, f.tmp / "r.vtu"))),
    "cnem.io.cell_points": Example(lambda f: dict(model=f.model)),
    "cnem.io.crack_face_ids": Example(lambda f: dict(model=f.model)),
    "cnem.plot.solution3d": Example(
        lambda f: dict(sol=_solid_solution(), path=f.tmp / "s3.png", window_size=(200, 150),
                       clip=(0.0, -1.0, 0.0), origin=(0.5, 0.5, 0.5))),
    "cnem.plot.model": Example(
        lambda f: dict(model=f.model, path=f.tmp / "m.png", window_size=(200, 200),
                       bounds=(0.0, 0.0, 1.0, 1.0))),
    "cnem.plot.solution": Example(
        lambda f: dict(sol=f.sol, path=f.tmp / "s.png", window_size=(200, 200),
                       field=f.sol.von_mises, bounds=(0.2, 0.2, 0.8, 0.8)),
        skip={("field", "nan"): "NaN values are drawn in the colour map's NaN colour"}),
    "cnem.plot.scalar_field": Example(
        lambda f: dict(model=f.model, values=f.model.nodes[:, 0], path=f.tmp / "t.png",
                       window_size=(200, 200), bounds=(0.0, 0.0, 1.0, 1.0)),
        skip={("values", "nan"): "NaN values are drawn in the colour map's NaN colour"}),
    "cnem.HeatConduction": Example(lambda f: dict(model=f.model, conductivity=1.0)),
    "cnem.heat.HeatSolution.temperature": Example(lambda f: dict(self=_heat(f), points=f.inside)),
    "cnem.heat.HeatSolution.flux_at": Example(lambda f: dict(self=_heat(f), points=f.inside)),
    "cnem.assembly.h1_error": Example(
        lambda f: dict(basis=cnem.assembly.CellBasis(f.model), values=f.model.nodes[:, 0],
                       exact_gradient=lambda x: np.tile([1.0, 0.0], (len(x), 1)))),
    "cnem.plot.cells_polydata": Example(lambda f: dict(model=f.model)),
    "cnem.plot.region_color": Example(lambda f: dict(region=np.array([0, 1]))),
    "cnem.shape.shape_functions": Example(lambda f: dict(model=f.model, points=f.inside,
                                                         triangles=np.array([-1, -1]))),
    "cnem.shape.tet_mesh": Example(
        lambda f: dict(nodes=f.tet_nodes, tetrahedra=f.tets, tet_region=np.zeros(len(f.tets)),
                       constraint_faces=f.tets[:1, :3])),
    "cnem.shape.shape_functions_3d": Example(
        lambda f: dict(mesh=cnem.shape.tet_mesh(f.tet_nodes, f.tets),
                       points=np.array([[0.1, 0.3, 0.2], [0.2, 0.2, 0.1]]))),
    "cnem.spatial.RTree": Example(lambda f: dict(lo=f.lattice, hi=f.lattice + 0.1,
                                                 period=np.array([2.0, 2.0])),
                                  skip={("lo", "shape"): _THREE_D, ("hi", "shape"): _THREE_D,
                                        ("period", "scalar"): _ONE_PERIOD}),
    "cnem.spatial.family_search": Example(
        lambda f: dict(points=f.lattice, horizon=0.3, period=np.array([2.0, 2.0])),
        skip={("points", "shape"): _THREE_D, ("period", "scalar"): _ONE_PERIOD}),
    "cnem.spatial.remove_crossing": Example(
        lambda f: dict(family=cnem.spatial.family_search(f.lattice, 0.3), points=f.lattice,
                       segments=np.array([[[0.1, -0.1], [0.1, 0.6]]]))),
    "cnem.hyperdual.HyperDual": Example(lambda f: dict(re=np.array([1.0, 2.0]), e1=1.0),
                                        skip={"shape": _ELEMENTWISE, "scalar": _ELEMENTWISE,
                                              "nan": _NAN_IN_NAN_OUT}),
    "cnem.hyperdual.derivatives": Example(
        lambda f: dict(f=cnem.hyperdual.norm, x=np.array([[3.0, 4.0]])),
        skip={"shape": "any number k of variables", "nan": _NAN_IN_NAN_OUT}),
    "cnem.hyperdual.derivative": Example(
        lambda f: dict(f=cnem.hyperdual.sin, x=np.array([1.0, 2.0])),
        skip={"shape": _ELEMENTWISE, "scalar": _ELEMENTWISE, "nan": _NAN_IN_NAN_OUT}),
    **{f"cnem.hyperdual.{name}": Example(lambda f: dict(a=_GRADIENTS),
                                         skip={("a", "nan"): _NAN_PER_MATRIX})
       for name in ("trace", "det", "inv")},
    "cnem.hyperdual.transpose": Example(
        lambda f: dict(a=_WIDE),
        skip={("a", "nan"): _NAN_PER_MATRIX,
              ("a", "shape"): "matrices (..., d, e) of any d and e are valid"}),
    "cnem.hyperdual.matmul": Example(
        lambda f: dict(a=_WIDE, b=np.swapaxes(_WIDE, 1, 2)),
        skip={"nan": _NAN_PER_MATRIX,
              ("b", "shape"): "b of shape (..., e, f) is valid for any number f of columns"}),
    "cnem.pd.Body": Example(
        lambda f: dict(points=f.lattice, volumes=np.full(len(f.lattice), 0.0625),
                       horizon=0.76, period=np.array([1.25, 1.25])),
        skip={("volumes", "scalar"): _SCALAR_OK, ("points", "shape"): _THREE_D,
              ("period", "scalar"): _ONE_PERIOD}),
    "cnem.pd.BondBased": Example(lambda f: dict(E=1.0)),
    "cnem.pd.StateBased": Example(lambda f: dict(E=1.0, nu=0.25)),
    "cnem.pd.CPD": Example(lambda f: dict(C1=1.0)),
    "cnem.pd.Problem": Example(lambda f: dict(body=f.body, material=cnem.pd.BondBased(1.0))),
    "cnem.fem.P1Elasticity": Example(
        lambda f: dict(domain=cnem.Domain(f.square), materials=(1.0, 0.3), nodes=20)),
    "cnem.fem.P1Elasticity.from_model": Example(
        lambda f: dict(model=f.model, materials=(1.0, 0.3))),
    "cnem.fem.mesh_domain": Example(lambda f: dict(domain=cnem.Domain(f.square), nodes=20)),
    "cnem.material.LinearElastic": Example(lambda f: dict(E=1.0, nu=0.3)),
    "cnem.material.parse_materials": Example(
        lambda f: dict(materials=np.array([[1.0, 0.3]]), nregions=1, plane="stress")),
    "cnem.material.moduli": Example(
        lambda f: dict(materials=(cnem.material.LinearElastic(1.0, 0.3),))),
    "cnem.material.NeoHookean": Example(lambda f: dict(mu=1.0, lam=1.5)),
    "cnem.material.SaintVenantKirchhoff": Example(lambda f: dict(E=1.0, nu=0.3)),
    "cnem.Hyperelasticity": Example(
        lambda f: dict(model=f.model, materials=cnem.material.NeoHookean(1.0, 1.5))),
    "cnem.Domain3D": Example(lambda f: dict(regions=cnem.geometry.shapes3d.box_surface(
        np.zeros(3), np.ones(3)))),
    "cnem.geometry.box": Example(lambda f: dict(lo=np.array([0.0, 0.0, 0.0]),
                                                hi=np.array([1.0, 2.0, 3.0]))),
    "cnem.geometry.sphere": Example(
        lambda f: dict(radius=1.0, center=np.array([1.0, 2.0, 3.0]), subdivisions=1)),
    "cnem.geometry.hollow_sphere": Example(
        lambda f: dict(inner=0.5, outer=1.0, center=np.array([1.0, 2.0, 3.0]),
                       subdivisions=1)),
    "cnem.geometry.cylinder": Example(
        lambda f: dict(radius=1.0, height=2.0, base=np.array([1.0, 2.0, 3.0]), segments=8)),
    # methods ("self" is the object called)
    "cnem.Domain.on_boundary": Example(
        lambda f: dict(self=f.named, points=f.inside, name="bottom")),
    **{f"cnem.Domain3D.{method}": Example(lambda f: dict(self=f.box, points=f.inside3))
       for method in ("contains", "region_of", "to_local")},
    "cnem.Domain3D.to_global": Example(
        lambda f: dict(self=f.box, local=f.box.to_local(f.cloud3.points))),
    "cnem.Domain3D.near_surface": Example(
        lambda f: dict(self=f.box, points=f.inside3, distance=0.35)),
    "cnem.Domain.contains": Example(lambda f: dict(self=f.dom, points=f.inside)),
    "cnem.Domain.region_of": Example(lambda f: dict(self=f.dom, points=f.inside)),
    "cnem.Model.shape_functions": Example(
        lambda f: dict(self=f.model, points=f.inside, triangles=np.array([-1, -1]))),
    **{f"cnem.material.{law.__name__}.{method}": Example(
        lambda f, law=law: dict(self=law(1.0, 0.3), F=_GRADIENTS),
        skip={("F", "nan"): _NAN_PER_POINT})
       for law in (cnem.material.NeoHookean, cnem.material.SaintVenantKirchhoff)
       for method in ("energy", "evaluate")},
    "cnem.Elasticity.add_body_force": Example(
        lambda f: dict(self=_setup(f.model), b=np.array([0.0, -1.0]))),
    "cnem.Elasticity.add_dirichlet": Example(
        lambda f: dict(self=_setup(f.model), where=np.array([0]), component=None,
                       value=np.array([0.1, 0.2])),
        skip={("value", "scalar"): "a number is valid: the same value on every component"}),
    "cnem.Hyperelasticity.add_dirichlet": Example(
        lambda f: dict(self=cnem.Hyperelasticity(f.model, cnem.material.NeoHookean(1.0, 1.5)),
                       where=np.array([0]), component=None, value=np.array([0.1, 0.2])),
        skip={("value", "scalar"): "a number is valid: the same value on every component"}),
    "cnem.Elasticity.add_traction": Example(
        lambda f: dict(self=_setup(f.model), where=lambda x, n: x[:, 1] > 1 - 1e-9,
                       t=np.array([0.0, 1.0]))),
    **{f"{cls}.displacement": Example(lambda f, a=attr: dict(self=getattr(f, a),
                                                             points=f.inside))
       for cls, attr in _SOLUTIONS.items()},
    **{f"{cls}.nodal_average": Example(
        lambda f, a=attr: dict(self=getattr(f, a), values=getattr(f, a).stress),
        skip={("values", "shape"): "values of any trailing shape, one row per place",
              ("values", "nan"): _NAN_IN_NAN_OUT})
       for cls, attr in _SOLUTIONS.items()},
    "cnem.ElasticSolution.displacement_gradient": Example(
        lambda f: dict(self=f.sol, points=f.inside)),
    "cnem.ElasticSolution.stress_at": Example(lambda f: dict(self=f.sol, points=f.inside)),
    "cnem.assembly.CellBasis.get_dofs": Example(
        lambda f: dict(self=cnem.assembly.CellBasis(f.model), where=np.array([0, 1])),
        skip={("where", "bool"): _MASK}),
    "cnem.assembly.CellBasis.interpolate": Example(
        lambda f: dict(self=cnem.assembly.CellBasis(f.model), u=np.zeros(len(f.model.nodes)))),
    **{f"cnem.exact.LayeredCylinder.{method}": Example(
        lambda f: dict(self=cnem.exact.LayeredCylinder([1.0, 2.0], [[1.0, 0.3]]),
                       r=np.array([1.2, 1.5])),
        skip={"shape": _ELEMENTWISE, "scalar": _ELEMENTWISE})
       for method in ("hoop_stress", "layer", "radial_displacement", "radial_stress")},
    **{f"cnem.exact.ThickSphere.{method}": Example(
        lambda f: dict(self=cnem.exact.ThickSphere(0.5, 1.0, 1.0, 0.3), r=np.array([0.6, 0.9])),
        skip={"shape": _ELEMENTWISE, "scalar": _ELEMENTWISE})
       for method in ("hoop_stress", "radial_displacement", "radial_stress")},
    **{f"cnem.exact.ThickSphere.{method}": Example(
        lambda f: dict(self=cnem.exact.ThickSphere(0.5, 1.0, 1.0, 0.3),
                       points=np.array([[0.6, 0.0, 0.0], [0.0, 0.5, 0.5]])))
       for method in ("displacement", "stress")},
    "cnem.exact.LayeredCylinder.displacement": Example(
        lambda f: dict(self=cnem.exact.LayeredCylinder([1.0, 2.0], [[1.0, 0.3]]),
                       points=np.array([[1.2, 0.0], [0.0, 1.5]]))),
    "cnem.exact.LayeredCylinder.stress": Example(
        lambda f: dict(self=cnem.exact.LayeredCylinder([1.0, 2.0], [[1.0, 0.3]]),
                       points=np.array([[1.2, 0.0], [0.0, 1.5]]), layer=np.array([0, 0]))),
    "cnem.exact.CentralCrack.opening": Example(
        lambda f: dict(self=cnem.exact.CentralCrack(1.0), x=np.array([0.2, 0.5]), E=1.0),
        skip={"shape": _ELEMENTWISE, "scalar": _ELEMENTWISE}),
    "cnem.exact.CentralCrack.normal_stress_ahead": Example(
        lambda f: dict(self=cnem.exact.CentralCrack(1.0), r=np.array([0.2, 0.5])),
        skip={"shape": _ELEMENTWISE, "scalar": _ELEMENTWISE}),
    "cnem.spatial.RTree.from_points": Example(
        lambda f: dict(points=f.lattice, period=np.array([2.0, 2.0])),
        skip={("points", "shape"): _THREE_D, ("period", "scalar"): _ONE_PERIOD}),
    "cnem.spatial.RTree.nearest": Example(
        lambda f: dict(self=cnem.spatial.RTree.from_points(f.lattice), points=f.inside)),
    "cnem.spatial.RTree.query": Example(
        lambda f: dict(self=cnem.spatial.RTree.from_points(f.lattice), qlo=f.inside,
                       qhi=f.inside + 0.1)),
    "cnem.spatial.RTree.query_ball": Example(
        lambda f: dict(self=cnem.spatial.RTree.from_points(f.lattice), points=f.inside,
                       r=0.3)),
    "cnem.hyperdual.dot": Example(lambda f: dict(a=_VECTORS, b=_VECTORS[::-1]),
                                  skip={"nan": _NAN_IN_NAN_OUT}),
    "cnem.hyperdual.cross": Example(lambda f: dict(a=_VECTORS, b=_VECTORS[::-1]),
                                    skip={"nan": _NAN_IN_NAN_OUT}),
    "cnem.hyperdual.norm": Example(lambda f: dict(a=_VECTORS),
                                   skip={"nan": _NAN_IN_NAN_OUT,
                                         "shape": "vectors of any length d are valid"}),
    **{f"cnem.hyperdual.{name}": Example(
        lambda f: dict(items=[_VECTORS[0], _VECTORS[1]]),
        skip={"nan": _NAN_IN_NAN_OUT, "shape": "items of any one shape are valid"})
       for name in ("stack", "concatenate")},
    "cnem.pd.Problem.add_velocity": Example(
        lambda f: dict(self=_pd_problem(f), where=np.array([24]), component=0, value=1.0)),
    "cnem.pd.Problem.add_traction": Example(
        lambda f: dict(self=_pd_problem(f), where=np.arange(20, 25),         # the row x = 1
                       t=np.array([1.0, 0.0]), area=np.full(5, 0.25), normal=np.array([1.0, 0.0])),
        skip={("area", "scalar"): "a number is valid (the same area at every loaded point)"}),
    "cnem.pd.Problem.run_dynamic": Example(
        lambda f: dict(self=_pd_problem(f), dt=1e-3, steps=2,
                       velocity=np.zeros((len(f.lattice), 2)), progress=False)),
    "cnem.pd.Problem.solve": Example(
        lambda f: dict(self=f.pd_prob, initial=np.zeros((len(f.lattice), 2)))),
    "cnem.pd.Problem.solve_static": Example(
        lambda f: dict(self=f.pd_prob, initial=np.zeros((len(f.lattice), 2)))),
}

_3D = " (on a Domain3D)"
EXAMPLES.update({
    f"cnem.geometry.nodes.{kind}{_3D}": Example(lambda f: dict(domain=f.box, h=0.5))
    for kind in ("regular", "irregular")})
EXAMPLES.update({
    f"cnem.geometry.nodes.graded{_3D}": Example(
        lambda f: dict(domain=f.box, h=0.5, near=f.inside3[:1], h_min=0.25)),
    f"cnem.geometry.nodes.from_points{_3D}": Example(
        lambda f: dict(domain=f.box, points=f.cloud3.points)),
})

#: What the tests call: every entry point, and the second examples of some.
CALLS = ENTRY_POINTS + [name for name in EXAMPLES if _entry(name) != name]


def _cases():
    """``(entry point, parameter, bad kind)`` for every array parameter of every entry point;
    an entry point without an example gives one case that fails."""
    cases = []
    for name in CALLS:
        if name not in EXAMPLES:
            cases.append(pytest.param(name, None, None, id=f"{name}-missing-example"))
            continue
        for param in _array_parameters(_function(name)):
            for kind in BAD_KINDS:
                cases.append(pytest.param(name, param, kind, id=f"{name}-{param}-{kind}"))
    return cases


def _bad(kind, value):
    """``value`` (a valid array argument) made bad in one way; None if ``kind`` has no bad
    form for it. A dict (fields by name) has its first field made bad (its wrong shape: a
    row missing, as fields may have any number of components)."""
    if isinstance(value, dict):
        key = next(iter(value))
        if kind == "shape":                              # fields: a row missing
            return {**value, key: np.asarray(value[key])[:-1]}
        bad = _bad(kind, value[key])
        return None if bad is None else {**value, key: bad}
    arr = np.asarray(value)
    if kind == "complex":
        return arr.astype(complex) + 1e-3j
    if kind == "bool":
        return np.ones(arr.shape, dtype=bool)
    if kind == "nan":
        out = arr.astype(float).copy()
        out.reshape(-1)[0] = np.nan
        return out
    if kind == "shape":
        if arr.ndim == 0:                                # a vector where a number is expected
            return np.full(3, float(arr))
        if arr.ndim == 1:                                # one axis more
            return np.stack([arr, arr], axis=1)
        return np.concatenate([arr, arr[..., :1]], axis=-1)   # a column more
    if kind == "scalar":                                 # a number where an array is expected
        return None if arr.ndim == 0 else float(arr.reshape(-1)[0])
    raise AssertionError(kind)


@pytest.fixture(scope="module")
def fixtures(tmp_path_factory):
    f = fx()
    f.tmp = tmp_path_factory.mktemp("public_inputs")
    return f


def _arguments(name, fixtures):
    if name not in EXAMPLES:
        pytest.fail(f"add an example call for {name} to the table EXAMPLES in "
                    f"tests/test_public_inputs.py (or list it in NOT_ENTRY_POINTS with the "
                    f"reason it takes no arrays)")
    return EXAMPLES[name].arguments(fixtures)


def _call(name, kwargs):
    """The entry point ``name`` called with ``kwargs`` (a method on ``kwargs["self"]``, or
    on its class for a class method), positional-only parameters passed by position."""
    name = _entry(name)
    if name in METHODS:
        cls, method = METHODS[name]
        obj = getattr(kwargs.pop("self"), method) if "self" in kwargs else getattr(cls, method)
    else:
        obj = PUBLIC[name]
    signature = inspect.signature(obj)
    args = [kwargs.pop(n) for n, p in signature.parameters.items()
            if p.kind is p.POSITIONAL_ONLY and n in kwargs]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return obj(*args, **kwargs)


@pytest.mark.parametrize("name", CALLS)
def test_example_call_is_valid(name, fixtures):
    """The table's call runs: a bad value refused below is refused for itself, not because
    the example was wrong."""
    _call(name, _arguments(name, fixtures))


def test_table_names_only_public_callables():
    stale = sorted({_entry(name) for name in [*EXAMPLES, *NOT_ENTRY_POINTS]} - set(PUBLIC)
                   - set(METHODS))
    assert not stale, f"the table names callables that are not public (any more): {stale}"


@pytest.mark.parametrize("name, param, kind", _cases())
def test_bad_array_is_refused_by_name(name, param, kind, fixtures):
    kwargs = _arguments(name, fixtures)
    example = EXAMPLES[name]
    if example.skipped(param, kind):
        pytest.skip(example.skipped(param, kind))
    if param not in kwargs:
        default = inspect.signature(_function(name)).parameters[param].default
        if default is inspect.Parameter.empty or default is None:
            pytest.fail(f"add a valid value of {param!r} to the example call of {name} in "
                        f"EXAMPLES (tests/test_public_inputs.py), so that its bad values "
                        f"are tried")
        kwargs[param] = default
    bad = _bad(kind, kwargs[param])
    if bad is None:
        pytest.skip(f"{param} is a number: no {kind} form")
    kwargs[param] = bad
    try:
        result = _call(name, kwargs)
    except cnem.CNEMError as exc:
        singular = param[:-1] if param.endswith("s") else param      # "crack 0" for cracks
        assert singular in str(exc), (f"{name}({param}=<{kind}>) raised {type(exc).__name__} "
                                      f"without naming {param!r}: {exc}")
        return
    except Exception as exc:        # noqa: BLE001 - the point: which error leaked
        pytest.fail(f"{name}({param}=<{kind}>) raised {type(exc).__name__}: {exc}; expected "
                    f"a cnem.CNEMError naming {param!r}")
    pytest.fail(f"{name}({param}=<{kind}>) returned {type(result).__name__} instead of "
                f"raising a cnem.CNEMError")
