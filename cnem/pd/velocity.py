"""Prescribed velocities of explicit peridynamic dynamics (an impactor, a moving grip).

A velocity condition holds some displacement components at ``u = value t`` and
their velocities at ``value`` through a run of `cnem.pd.Problem.run_dynamic` (and
of its distributed counterpart), from ``t = 0``: in every velocity Verlet step the
prescribed components are overwritten after the position and the velocity
updates, as Dirichlet components are held at their values. Where a velocity and a
Dirichlet condition prescribe one component, the velocity wins. The static solvers
have no time and refuse velocity conditions (`VelocityConditions.static_only`).

>>> import numpy as np, cnem.pd as pd
>>> pts = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
>>> prob = pd.Problem(pd.Body(pts, 1.0, 1.5), pd.BondBased(1.0, density=1.0))
>>> prob.add_velocity(lambda p: p[:, 0] < 0.5, 0, 2.0)
>>> prob.prescribed_velocity()
(array([0]), array([2.]))
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..solvers.conditions import dirichlet_dofs, merged_conditions
from ..errors import ConditionError

if TYPE_CHECKING:
    from typing import Any, Callable

    from numpy.typing import ArrayLike

__all__ = ["VelocityConditions"]


class VelocityConditions:
    """``add_velocity`` for a problem with ``condition_points`` (a mixin of the PD problems)."""

    #: ``(dofs, values)`` of each velocity condition, in the order given.
    velocities: tuple = ()

    def add_velocity(self, where: Any, component: int | None,
                     value: ArrayLike | Callable[..., np.ndarray] = 0.0) -> None:
        """Prescribe velocities at points for the dynamic runs: ``u = value t``.

        Parameters
        ----------
        where : str, callable ``(n, d) -> (n,) bool``, or a boolean mask / index array
            over the points (``condition_points``); a str names a boundary of the body's
            domain (`cnem.solvers.Conditions.named_nodes`)
        component : {0, ..., d - 1, None}
            ``None`` prescribes every component.
        value : float, or callable ``(p, d) -> (p,)`` (``(p, d)`` for every component)
            Velocity (length / time), constant in time.
        """
        self.velocities = self.velocities + (
            dirichlet_dofs(self.condition_points, where, component, value,
                           where_to_look=self.points_name, what="add_velocity",
                           named=getattr(self, "named_nodes", None)),)

    def prescribed_velocity(self) -> tuple[np.ndarray, np.ndarray]:
        """The dofs (``d * point + component``, sorted) with a prescribed velocity and
        its values (conditions on one dof must agree: `merged_conditions`)."""
        return merged_conditions(self.velocities, self.condition_points.shape[1], "add_velocity")

    def static_only(self, what: str) -> None:
        """Refuse a static solve (``what``) of a problem with velocity conditions.

        Raises
        ------
        ConditionError
        """
        if self.velocities:
            raise ConditionError(f"{what}: expected no velocity condition (a static solve has "
                                 f"no time), received {len(self.velocities)} (add_velocity); "
                                 f"run them with run_dynamic, or prescribe displacements with "
                                 f"add_dirichlet")
