"""`cnem.pd.behaviour`: the materials' behaviour objects, checked against the problem's
own operators and against properties they must have (no numbers the code printed)."""

from __future__ import annotations

import numpy as np
import pytest

import cnem.pd as pd
from cnem.errors import MaterialError, UnsupportedError
from cnem.pd.behaviour import BondBehaviour, CPDBehaviour, StateBehaviour
from cnem.pd.correction import classical_density, unit_strain_targets
from cnem.pd.materials import isotropic_moduli


def _grid(n=7, h=1.0):
    g = np.arange(n) * h
    return np.array([(x, y) for x in g for y in g])


def _problem(material, **options):
    return pd.Problem(pd.Body(_grid(), 1.0, 3.015), material, **options)


MATERIALS = {"bond": (pd.BondBased(1.0), BondBehaviour),
             "state": (pd.StateBased(1.0, 0.3), StateBehaviour),
             "cpd": (pd.CPD(1.0, 0.5), CPDBehaviour)}


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_every_material_builds_its_behaviour(name):
    material, kind = MATERIALS[name]
    prob = _problem(material)
    assert isinstance(prob.behaviour, kind) and prob.behaviour.problem is prob
    assert prob.behaviour.linear == (name != "cpd")
    assert prob.behaviour.has_stress == (name != "cpd")
    assert prob.surface_correction == material.correctable == (name != "cpd")


@pytest.mark.parametrize("name", ["bond", "state"])
def test_linear_forces_are_the_stiffness_times_u(name):
    prob = _problem(MATERIALS[name][0])
    u = np.random.default_rng(1).normal(size=2 * len(prob.body))
    force, K = prob.behaviour.evaluate(u, tangent=True)
    np.testing.assert_array_equal(force, prob.stiffness() @ u)
    assert abs(K - prob.stiffness()).max() == 0
    # the energy is half of u . K u
    energy = float(prob.body.volumes @ prob.energy_density(u))
    np.testing.assert_allclose(energy, 0.5 * u @ force, rtol=1e-12)


def test_cpd_forces_are_the_interactions_gradient_and_linear_methods_refuse():
    prob = _problem(pd.CPD(1.0, 0.5))
    u = 0.01 * np.random.default_rng(2).normal(size=2 * len(prob.body))
    _, force, K = prob.interactions.evaluate(u)
    mine, tangent = prob.behaviour.evaluate(u, tangent=True)
    np.testing.assert_array_equal(mine, force)
    assert abs(tangent - K).max() == 0
    assert prob.behaviour.evaluate(u, tangent=False)[1] is None
    for method in (prob.stiffness, prob.stable_time_step):
        with pytest.raises(UnsupportedError, match="not for CPD"):
            method()
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    assert sorted(prob.solve().fields()[0]) == ["strain", "u"]


def test_pmb_stiffness_without_broken_bonds_is_the_reassembled_one():
    prob = _problem(pd.BondBased(1.0))
    K = prob.stiffness()
    over = np.zeros(len(prob.alive), dtype=bool)
    over[::7] = True
    prob.alive[over] = 0
    np.testing.assert_allclose(prob.behaviour.stiffness_without(K, over).toarray(),
                               prob.stiffness().toarray(), atol=1e-13)


@pytest.mark.parametrize("dim,plane", [(2, "stress"), (2, "strain"), (3, "stress")])
def test_pmb_moduli_are_those_of_its_poisson_ratio(dim, plane):
    material = pd.BondBased(3.0)
    nu = material.poisson(dim, plane)
    k, mu = material.moduli(dim, plane)
    assert (k, mu) == isotropic_moduli(3.0, nu, dim, plane)
    np.testing.assert_allclose(mu, 3.0 / (2 * (1 + nu)))


def test_classical_density_of_uniaxial_strain():
    """Plane strain, ``eps_xx = e``: ``W = (lam + 2 mu) e^2 / 2``."""
    E, nu, e = 2.0, 0.3, 1e-3
    k, mu = isotropic_moduli(E, nu, 2, "strain")
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    np.testing.assert_allclose(classical_density(np.diag([e, 0.0]), k, mu),
                               0.5 * (lam + 2 * mu) * e * e, rtol=1e-12)
    pairs, target = unit_strain_targets(2, k, mu)
    assert pairs.tolist() == [[0, 0], [0, 1], [1, 1]]
    np.testing.assert_allclose(target, [0.5 * (lam + 2 * mu), 2 * mu, 0.5 * (lam + 2 * mu)],
                               rtol=1e-12)


def test_only_materials_with_a_behaviour_are_taken():
    with pytest.raises(MaterialError, match="BondBased"):
        pd.Problem(pd.Body(_grid(), 1.0, 3.015), object())
