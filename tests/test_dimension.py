"""Dimension as data: the variational core (gradients, `CellBasis`, forms and their
block kernels, the elastic solution, materials) in 3-D on synthetic cells, and the
2-D paths unchanged.

The 3-D cells are the tetrahedra of a jittered cube lattice, with the exact (P1)
gradients of the linear interpolant on each: a basis that reproduces linear fields,
on which linear elasticity must pass the patch test to round-off. The 3-D elasticity
matrix is checked against Hooke's law written from its index formula.
"""

from __future__ import annotations

import itertools
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.spatial import Delaunay

import cnem
from cnem.assembly import CellBasis
from cnem.assembly import _sparse_kernels as SK
from cnem.assembly.gradients import SmoothedGradient
from cnem.material import LinearElastic, Material, parse_materials
from cnem.elasticity.linear import elasticity_form
from cnem.elasticity.solution import ElasticSolution
from cnem.solvers.constrained import solve_constrained
from cnem.solvers.solution import VOIGT, engineering_strain, voigt, von_mises

#: A linear displacement field u = A x + b (3-D).
A3 = np.array([[0.3, -0.2, 0.1], [0.05, -0.4, 0.25], [0.15, 0.2, 0.35]])
B3 = np.array([0.1, -0.3, 0.2])


def _tetrahedral_patch(k=4, seed=0):
    """Nodes of a jittered ``k^3`` lattice in the unit cube (boundary nodes kept on their
    faces) and the P1 operators of its Delaunay tetrahedra: values at the centroids,
    the three derivatives, volumes and centroids."""
    rng = np.random.default_rng(seed)
    axis = np.linspace(0.0, 1.0, k)
    nodes = np.array(list(itertools.product(axis, axis, axis)))
    inside = np.all((nodes > 0.0) & (nodes < 1.0), axis=1)
    nodes[inside] += rng.uniform(-0.15, 0.15, (inside.sum(), 3)) / (k - 1)
    tets = Delaunay(nodes).simplices
    corners = nodes[tets]                                     # (t, 4, 3)
    edges = corners[:, 1:] - corners[:, :1]                   # (t, 3, 3)
    volume = np.abs(np.linalg.det(edges)) / 6.0
    keep = volume > 1e-12
    tets, corners, edges, volume = tets[keep], corners[keep], edges[keep], volume[keep]
    inv = np.linalg.inv(edges)                                # rows: d lambda_{1..3} / dx
    grad = np.concatenate([-inv.sum(axis=2)[:, None, :], np.transpose(inv, (0, 2, 1))], axis=1)
    t, n = len(tets), len(nodes)
    indptr = np.arange(0, 4 * t + 1, 4)

    def op(values):
        return sp.csr_matrix((values.reshape(-1), tets.reshape(-1), indptr), shape=(t, n))

    value = op(np.full((t, 4), 0.25))
    gradients = tuple(op(grad[:, :, i]) for i in range(3))
    return nodes, value, gradients, volume, corners.mean(axis=1)


@pytest.fixture(scope="module")
def patch():
    nodes, value, gradients, volume, centroids = _tetrahedral_patch()
    model = SimpleNamespace(nodes=nodes)
    basis = CellBasis.from_operators(model, value, gradients, volume, centroids, vector=True)
    return SimpleNamespace(model=model, nodes=nodes, basis=basis, value=value,
                           gradients=gradients, volume=volume)


def _reference_C(lam, mu):
    """The 6 x 6 Voigt matrix from ``C_ijkl = lam d_ij d_kl + mu (d_ik d_jl + d_il d_jk)``,
    slowly: with engineering shears, ``C_IJ = C_ijkl`` for ``I = (i, j)``, ``J = (k, l)``."""
    d = np.eye(3)
    C = np.zeros((6, 6))
    for I, (i, j) in enumerate(VOIGT[3]):
        for J, (k, l) in enumerate(VOIGT[3]):
            C[I, J] = lam * d[i, j] * d[k, l] + mu * (d[i, k] * d[j, l] + d[i, l] * d[j, k])
    return C


def _strain_displacement(gradients, cell, n):
    """``B`` ``(6, 3 n)`` of one cell, Voigt ``[xx, yy, zz, yz, xz, xy]``, written out."""
    B = np.zeros((6, 3 * n))
    g = [np.asarray(op[cell].todense()).ravel() for op in gradients]
    for I, (i, j) in enumerate(VOIGT[3]):
        B[I, i::3] += g[j]
        if i != j:
            B[I, j::3] += g[i]
    return B


# -- materials ---------------------------------------------------------------------------
def test_3d_elasticity_matrix_is_hookes_law():
    mat = LinearElastic(210.0, 0.27)
    lam, mu = mat.lame(3)
    np.testing.assert_allclose(mat.elasticity_matrix(3), _reference_C(lam, mu), rtol=1e-15)
    assert mat.tangent(3).shape == (6, 6)
    # sigma = lam tr(eps) I + 2 mu eps for a random symmetric strain, through Voigt
    rng = np.random.default_rng(1)
    g = rng.normal(size=(3, 3))
    eps = 0.5 * (g + g.T)
    sigma = lam * np.trace(eps) * np.eye(3) + 2.0 * mu * eps
    np.testing.assert_allclose(mat.elasticity_matrix(3) @ engineering_strain(g), voigt(sigma),
                               rtol=1e-13)
    # E and nu of the 3-D law back from lam, mu
    assert np.isclose(mu * (3 * lam + 2 * mu) / (lam + mu), 210.0)
    assert np.isclose(lam / (2 * (lam + mu)), 0.27)


def test_2d_elasticity_matrix_is_the_plane_law():
    mat = LinearElastic(3.0, 0.25)
    for plane in cnem.material.PLANES:
        np.testing.assert_array_equal(mat.elasticity_matrix(2, plane),
                                      cnem.material.stiffness_matrix(3.0, 0.25, plane))
    # plane strain: the 3-D law with ezz = eyz = exz = 0
    C3 = mat.elasticity_matrix(3)
    np.testing.assert_allclose(mat.elasticity_matrix(2, "strain"), C3[np.ix_([0, 1, 5], [0, 1, 5])])
    # plane stress: the 3-D law's compliance restricted to the plane, inverted
    S3 = np.linalg.inv(C3)
    np.testing.assert_allclose(mat.elasticity_matrix(2, "stress"),
                               np.linalg.inv(S3[np.ix_([0, 1, 5], [0, 1, 5])]), rtol=1e-13)


def test_plane_must_suit_the_dimension():
    mat = LinearElastic(1.0, 0.3)
    with pytest.raises(cnem.OptionError, match="3-D body has no plane"):
        mat.elasticity_matrix(3, "stress")
    with pytest.raises(cnem.OptionError, match="plane"):
        mat.lame(2)
    with pytest.raises(cnem.MaterialError, match=r"Poisson ratios must lie in \(-1, 0.5\)"):
        LinearElastic(1.0, 0.5)
    with pytest.raises(cnem.MaterialError, match="Young's moduli must be positive"):
        LinearElastic(-1.0, 0.2)


def test_parse_materials_pairs_objects_and_lists():
    steel, alu = LinearElastic(210.0, 0.3), LinearElastic(70.0, 0.33)
    assert parse_materials((210.0, 0.3), 2) == (steel, steel)
    assert parse_materials(steel, 2, "stress") == (steel, steel)
    assert parse_materials([steel, alu], 2) == (steel, alu)
    assert parse_materials([(210.0, 0.3), (70.0, 0.33)], 2, dim=3) == (steel, alu)
    E, nu = alu                                  # unpacks as the pair it replaces
    assert (E, nu) == (70.0, 0.33)
    assert isinstance(steel, Material)
    with pytest.raises(cnem.MaterialError, match="one material per region"):
        parse_materials([steel], 2)


def test_elasticity_takes_material_objects(small_model):
    mats = [(1000.0, 0.3)] * len(small_model.domain.regions)
    by_pairs = cnem.Elasticity(small_model, mats, stabilization=0.0)
    by_objects = cnem.Elasticity(small_model, LinearElastic(1000.0, 0.3), stabilization=0.0)
    np.testing.assert_array_equal(by_objects.materials, by_pairs.materials)
    assert by_objects.region_materials[0] == LinearElastic(1000.0, 0.3)
    assert by_objects.dim == 2
    diff = by_objects.stiffness() - by_pairs.stiffness()
    assert diff.nnz == 0 or np.abs(diff.data).max() == 0.0


@pytest.fixture(scope="module")
def small_model():
    return cnem.discretize(cnem.nodes.irregular(cnem.geometry.rectangle(2.0, 1.0), 0.25, seed=1))


# -- gradients and shape functions --------------------------------------------------------
def test_smoothed_gradient_carries_its_dimension(patch):
    g = SmoothedGradient(*patch.gradients, points=0)
    assert g.dim == 3 and g.z is patch.gradients[2] and tuple(g) == patch.gradients
    assert SmoothedGradient(*patch.gradients, 5).points == 5            # points last, as in 2-D
    flat = SmoothedGradient(*patch.gradients[:2], points=0)
    assert flat.dim == 2 and flat.y is patch.gradients[1]
    with pytest.raises(cnem.GeometryError, match="2 or 3 derivative matrices"):
        SmoothedGradient(patch.gradients[0], 0)
    with pytest.raises(AttributeError):
        flat.z


def test_shape_gradients_unpack_as_before(small_model):
    pts = np.array([[0.33, 0.41], [1.27, 0.58]])
    out = small_model.shape_functions(pts, gradient=True)
    phi, dx, dy = out
    assert out.dim == 2 and out.value is phi and out.gradient == (dx, dy)
    np.testing.assert_allclose(dx @ small_model.nodes, [[1.0, 0.0]] * 2, atol=1e-12)
    np.testing.assert_allclose(dy @ small_model.nodes, [[0.0, 1.0]] * 2, atol=1e-12)


# -- the 3-D basis, forms and patch test ------------------------------------------------
def test_3d_basis_descriptors(patch):
    basis, nodes = patch.basis, patch.nodes
    n = len(nodes)
    assert (basis.dim, basis.ncomp, basis.N, len(basis.operators)) == (3, 3, 3 * n, 12)
    u = (nodes @ A3.T + B3).reshape(-1)
    field = basis.interpolate(u)
    assert field.shape == (3, len(basis.dx)) and field.grad.shape == (3, 3, len(basis.dx))
    np.testing.assert_allclose(np.moveaxis(field.grad, -1, 0), np.broadcast_to(A3, (len(basis.dx), 3, 3)),
                               atol=1e-12)
    np.testing.assert_array_equal(basis.get_dofs([0, 5], 2), [2, 17])
    np.testing.assert_array_equal(basis.get_dofs([1]), [3, 4, 5])
    with pytest.raises(cnem.ConditionError, match="0, 1, 2 or None"):
        basis.get_dofs([1], 3)


def test_3d_stiffness_is_the_sum_of_bt_c_b(patch):
    """The block kernel (3 x 3 node blocks) and the general path both give
    ``sum_k V_k B_k^T C B_k`` written out with the 6 x 6 Hooke matrix."""
    basis, n = patch.basis, len(patch.nodes)
    mat = LinearElastic(5.0, 0.3)
    lam, mu = mat.lame(3)
    K = elasticity_form.assemble(basis, lam=lam, mu=mu)
    C = mat.elasticity_matrix(3)
    cells = range(0, len(patch.volume), 7)
    K_ref = sum(patch.volume[k] * _strain_displacement(patch.gradients, k, n).T @ C
                @ _strain_displacement(patch.gradients, k, n) for k in cells)
    mask = np.zeros(len(patch.volume))
    mask[list(cells)] = 1.0
    K_some = elasticity_form.assemble(basis, lam=lam * mask, mu=mu * mask)
    np.testing.assert_allclose(K_some.toarray(), K_ref, atol=1e-12 * np.abs(K_ref).max())
    assert basis.component_gradients() is not None
    general = CellBasis.from_operators(patch.model, patch.value, patch.gradients,
                                       basis.dx, basis.x.T, vector=True)
    general.__dict__["operators"] = list(general.operators)       # not the block path
    assert general.component_gradients() is None
    K_general = elasticity_form.assemble(general, lam=lam, mu=mu)
    np.testing.assert_allclose(K_general.toarray(), K.toarray(), atol=1e-12 * abs(K).max())
    groups = np.zeros(len(basis.dx), dtype=np.int64)
    K_grouped = elasticity_form.assemble(basis, groups=groups, lam=np.array([lam]),
                                         mu=np.array([mu]))
    np.testing.assert_allclose(K_grouped.toarray(), K.toarray(), atol=1e-12 * abs(K).max())


def test_3d_patch_test(patch):
    """Linear displacements on the boundary: the interior nodes take the linear field,
    every cell the exact strain and stress (Hooke), to round-off."""
    basis, nodes = patch.basis, patch.nodes
    mat = LinearElastic(5.0, 0.3)
    lam, mu = mat.lame(3)
    K = elasticity_form.assemble(basis, lam=lam, mu=mu)
    exact = nodes @ A3.T + B3
    boundary = np.flatnonzero(np.any((nodes == 0.0) | (nodes == 1.0), axis=1))
    dofs = basis.get_dofs(boundary)
    x = solve_constrained(K, np.zeros(basis.N), dofs, exact.reshape(-1)[dofs], points=nodes,
                          method="direct")
    np.testing.assert_allclose(x.reshape(-1, 3), exact, atol=1e-12)
    C = np.broadcast_to(mat.elasticity_matrix(3), (len(basis.dx), 6, 6))
    problem = SimpleNamespace(model=patch.model, basis=basis, cells=None, plane=None)
    sol = ElasticSolution.from_dofs(problem, x, C, {})
    assert sol.u.shape == (len(nodes), 3) and sol.gradient.shape == (len(basis.dx), 3, 3)
    eps = 0.5 * (A3 + A3.T)
    sigma = lam * np.trace(eps) * np.eye(3) + 2.0 * mu * eps
    np.testing.assert_allclose(sol.strain, np.broadcast_to(engineering_strain(A3), sol.strain.shape),
                               atol=1e-12)
    np.testing.assert_allclose(sol.stress, np.broadcast_to(voigt(sigma), sol.stress.shape),
                               atol=1e-11)
    assert sol.enriched.shape == (0, 3)
    np.testing.assert_allclose(sol.von_mises, von_mises(voigt(sigma)), rtol=1e-10)


# -- the block kernels ------------------------------------------------------------------
@pytest.mark.parametrize("nch", [1, 3])
def test_generic_block_kernel_is_the_2d_one_in_2d(nch):
    rng = np.random.default_rng(nch)
    m, n = 30, 20
    G = sp.random(m, n, density=0.25, format="csr", random_state=nch)
    G.sort_indices()
    gy = rng.uniform(-1, 1, G.nnz)
    coeff = rng.uniform(-1, 1, (4, 4, 4))
    group = rng.integers(0, 4, m)
    weight = rng.uniform(0.5, 2.0, m)
    two = SK.gradient_block_gram(G.indptr, G.indices, G.data, gy, coeff, group, weight, n, nch)
    generic = SK.gradient_block_gram_nd(G.indptr, G.indices, np.stack([G.data, gy]), coeff,
                                        group, weight, n, nch)
    for a, b in zip(two, generic):
        np.testing.assert_array_equal(a, b)


def test_generic_block_kernel_matches_scipy_in_3d():
    rng = np.random.default_rng(7)
    m, n, d = 25, 15, 3
    G = sp.random(m, n, density=0.3, format="csr", random_state=7)
    G.sort_indices()
    grads = np.stack([G.data] + [rng.uniform(-1, 1, G.nnz) for _ in range(d - 1)])
    coeff = rng.uniform(-1, 1, (m, d * d, d * d))
    weight = rng.uniform(0.5, 2.0, m)
    per_cell = weight[:, None, None] * coeff
    ops = [sp.csr_matrix((grads[e], G.indices * d + c, G.indptr), shape=(m, d * n))
           for c in range(d) for e in range(d)]                    # descriptor d c + e
    expected = sum((ops[b].T @ sp.diags(per_cell[:, a, b]) @ ops[a]).toarray()
                   for a in range(d * d) for b in range(d * d))
    indptr, indices, data = SK.gradient_block_gram_nd(G.indptr, G.indices, grads, coeff,
                                                      np.arange(m), weight, n, 2)
    K = sp.csr_matrix((data, indices, indptr), shape=(d * n, d * n))
    np.testing.assert_allclose(K.toarray(), expected, atol=1e-12)


# -- solutions, frames and files --------------------------------------------------------
def test_voigt_strain_and_von_mises_in_3d():
    g = np.arange(9.0).reshape(3, 3)
    np.testing.assert_array_equal(voigt(g + g.T), [0.0, 8.0, 16.0, 12.0, 8.0, 4.0])
    np.testing.assert_array_equal(engineering_strain(g), [0.0, 4.0, 8.0, 12.0, 8.0, 4.0])
    assert von_mises(np.array([2.0, 0, 0, 0, 0, 0])) == 2.0                   # uniaxial
    assert np.isclose(von_mises(np.array([0, 0, 0, 0, 0, 1.5])), np.sqrt(3) * 1.5)  # shear
    assert np.isclose(von_mises(np.array([4.0, 4.0, 4.0, 0, 0, 0])), 0.0)      # hydrostatic


def test_local_frame_and_bounding_box_in_3d():
    from cnem._predicates import bounding_box, local_frame
    pts = np.array([[1e6, 2.0, -3.0], [1e6 + 3.0, 5.0, -1.0]])
    lo, hi = bounding_box(pts)
    np.testing.assert_array_equal(lo, pts.min(axis=0))
    np.testing.assert_array_equal(hi, pts.max(axis=0))
    frame = local_frame(np.concatenate([lo, hi]))
    assert frame.origin.shape == (3,)
    np.testing.assert_array_equal(frame.to_global(frame.to_local(pts)), pts)
    flat = local_frame([0.0, 0.0, 3.0, 1.0])
    assert flat.origin.shape == (2,) and flat.scale == 4.0


class _Cells(SimpleNamespace):
    """Integration cells given by their arrays."""

    def __len__(self):
        return len(self.area)


def test_io_read_keeps_z(tmp_path, small_model):
    """A model whose nodes and cells lie off the plane z = 0 reads back with its z."""
    import cnem.io
    cells = small_model.cells

    def lifted(points):
        return np.column_stack([points, np.full(len(points), 0.5)])

    lift = SimpleNamespace(nodes=lifted(small_model.nodes), node_of_point=small_model.node_of_point,
                           cells=_Cells(vertices=lifted(cells.vertices), offsets=cells.offsets,
                                        node=cells.node, region=cells.region, area=cells.area))
    back = cnem.io.read(cnem.io.write(lift, tmp_path / "lifted.vtu"))
    np.testing.assert_array_equal(back.nodes, lift.nodes)
    np.testing.assert_array_equal(back.vertices, lift.cells.vertices)
    flat = cnem.io.read(cnem.io.write(small_model, tmp_path / "flat.vtu"))
    assert flat.nodes.shape == small_model.nodes.shape
