"""`Problem` on MPI ranks: explicit dynamics and dynamic relaxation with ghost exchanges.

Each rank computes the bonds of its own points from its and its ghosts'
displacements (no reverse force exchange): one halo exchange of the
displacements per force evaluation, and for the state-based solid one more of
the dilatations and "pressures" ``dW/dtheta`` of the points. The bond-based
exchange is non-blocking: the bonds of the points with no ghost in their families
are computed while it runs (`Problem.internal_force`). Bond breaking is
decided by the stretch as in serial, and the reverse of a bond is judged by the
same formula on both of its ranks, so the broken bonds are those of the serial
run.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...solvers.conditions import Conditions, per_point
from ...solvers.stepping import Prescribed, velocity_verlet
from ...errors import MaterialError, OptionError
from ...material import PLANES
from ..guards import checked_run, diverged, first_non_finite
from ..solution import DynamicRun
from ..velocity import VelocityConditions
from . import checkpoint as ckpt
from .output import PieceWriter
from .relaxation import relax

if TYPE_CHECKING:
    import os
    from numpy.typing import ArrayLike
    from ..materials import BondBased, StateBased
    from ..solution import Relaxation
    from .body import Body

__all__ = ["Problem", "DistributedRun"]


@dataclass(eq=False, repr=False)
class DistributedRun(DynamicRun):
    """Result of `Problem.run_dynamic` on the ranks.

    On rank 0 (with ``gather=True``): ``u``, ``velocity``, ``damage`` of all points
    (global numbering), ``frames`` (list of ``(u, damage)``) and ``broken_bonds``
    (``(k, 2)`` global point pairs, both directions); None / empty on the other ranks.
    Every rank: ``times``, ``energy`` (kinetic + elastic, summed over the ranks),
    ``broken`` (bonds broken during the run, all ranks), ``files`` (the ``.pvtu`` of
    each frame), ``local`` (dict: ``owned`` global ids, ``u``, ``velocity``,
    ``damage`` of the owned points) and ``step`` (the last step).
    """

    broken_bonds: np.ndarray = None
    local: dict = None
    step: int = 0

    def __repr__(self):
        where = "gathered" if self.u is not None else "local"
        return (f"<DistributedRun ({where}) t = {self.times[-1]:.3e}, {self.broken} bonds "
                f"broken>")


class Problem(Conditions, VelocityConditions):
    """`cnem.pd.Problem` for a `cnem.pd.distributed.Body`: the same conditions and the
    same dynamic solvers (`run_dynamic`, `relax`, `stable_time_step`, `damage`), every
    rank computing its own points.

    Parameters
    ----------
    body : cnem.pd.distributed.Body
    material : cnem.pd.BondBased or cnem.pd.StateBased
    plane : {"stress", "strain"}
    surface_correction : bool, optional
        Default on (as in serial).

    Conditions (`cnem.solvers.conditions.Conditions`): Dirichlet predicates see all the
    points (``body.global_points``) on every rank; body forces are evaluated at the
    owned points. Tractions are not supported.
    """

    points_name = "body.points"

    def __init__(self, body: Body, material: BondBased | StateBased, *, plane: str = "stress",
                 surface_correction: bool | None = None):
        if plane not in PLANES:
            raise OptionError(f"plane: expected 'stress' or 'strain', received {plane!r}")
        if not callable(getattr(material, "local_operators", None)):
            raise MaterialError(f"material: expected cnem.pd.BondBased or StateBased (CPD runs "
                             f"serially only), received {type(material).__name__}")
        super().__init__()
        self.body, self.material, self.plane, self.dim = body, material, plane, body.dim
        self.comm = body.comm
        self.surface_correction = True if surface_correction is None else \
            bool(surface_correction)
        #: the material's bonds on this rank (`cnem.pd.distributed.operators`)
        self.ops = material.local_operators(body, plane, self.surface_correction)
        self.alive = np.ones(len(body.bond_j), dtype=np.uint8)
        self.alive_reverse = np.ones(len(body.bond_j), dtype=np.uint8)

    def __repr__(self):
        return f"<distributed Problem {self.body!r}, {self.material!r}>"

    @property
    def root(self) -> bool:
        """Whether this is rank 0."""
        return self.comm.rank == 0

    # -- conditions (global predicates, kept at the owned points) -----------------------
    @property
    def condition_points(self) -> np.ndarray:
        """All points of the body (every rank): what Dirichlet predicates see."""
        return self.body.global_points

    def owned_prescribed(self, velocity: bool = False) -> tuple:
        """Owned local dofs ``d * row + component`` and their values: of the Dirichlet
        conditions, or of the velocity conditions."""
        dofs, values = self.prescribed_velocity() if velocity else self.prescribed()
        d, body = self.dim, self.body
        node = dofs // d
        mine = body.part[node] == self.comm.rank
        local = d * np.searchsorted(body.owned, node[mine]) + dofs[mine] % d
        return local.astype(np.int64), values[mine]

    def load(self) -> np.ndarray:
        """External forces of the owned points ``(o, d)``."""
        b, o = self.body, self.body.n_owned
        f = np.zeros((o, self.dim))
        for force in self.body_forces_at(b.points[:o]):
            f += b.volumes[:o, None] * force
        return f

    # -- global reductions ---------------------------------------------------------------
    def allsum(self, x: np.ndarray) -> float:
        """Sum of a float over the ranks."""
        return self.comm.allreduce(float(x))

    def norm(self, x: np.ndarray) -> float:
        """Euclidean norm of a vector split over the ranks."""
        return float(np.sqrt(self.allsum(np.dot(x, x))))

    def gather(self, values: np.ndarray) -> np.ndarray | None:
        """Owned rows of every rank, in global numbering, on rank 0 (None elsewhere)."""
        parts = self.comm.gather((self.body.owned, np.asarray(values)), root=0)
        if not self.root:
            return None
        out = np.empty((len(self.body),) + np.shape(values)[1:], dtype=np.asarray(values).dtype)
        for ids, v in parts:
            out[ids] = v
        return out

    # -- forces --------------------------------------------------------------------------
    def internal_force(self, u: np.ndarray, limit: float) -> tuple[np.ndarray, int]:
        """Force per unit volume of the owned points ``(o, d)`` from local displacements
        ``(o + g, d)`` whose owned rows are current (the ghost rows are exchanged here);
        bonds beyond ``limit`` break. Returns the force and the number of owned bonds
        broken.

        The material's operators compute them (`BondOperators.forces`: the exchange runs
        while the bonds of the interior points are computed; `StateOperators.forces`: the
        exchange first, then the dilatations, one more exchange and the forces).
        """
        return self.ops.forces(u, limit, self.alive, self.alive_reverse)

    def energy(self, u: np.ndarray, v: np.ndarray) -> float:
        """Kinetic plus elastic energy of the whole body (all ranks)."""
        b, ops, o = self.body, self.ops, self.body.n_owned
        kinetic = 0.5 * self.material.density * float(b.volumes[:o] @ (v * v).sum(axis=1))
        elastic = ops.elastic_energy(u, self.alive)
        return self.allsum(kinetic + elastic)

    # -- per-point results ---------------------------------------------------------------
    def damage(self) -> np.ndarray:
        """Damage of the owned points ``(o,)`` (as `cnem.pd.Problem.damage`)."""
        b, o, w = self.body, self.body.n_owned, self.ops.weight
        total = np.bincount(b.bond_i, weights=w, minlength=o)
        live = np.bincount(b.bond_i, weights=w * self.alive, minlength=o)
        return 1.0 - live / np.maximum(total, 1e-300)

    def broken_bonds(self) -> np.ndarray | None:
        """Broken bonds as ``(k, 2)`` global point pairs, on rank 0 (None elsewhere)."""
        b = self.body
        dead = self.alive == 0
        local = np.concatenate([b.owned, b.ghosts])
        pairs = np.column_stack([b.owned[b.bond_i[dead]], local[b.bond_j[dead]]])
        parts = self.comm.gather(pairs, root=0)
        return np.concatenate(parts) if self.root else None

    def stable_time_step(self, safety: float = 0.8) -> float:
        """`cnem.pd.Problem.stable_time_step` over all ranks. State-based: from an upper
        bound of the stiffness rows (`LocalOperators.row_bound`), so at most the serial
        step."""
        diag = self.ops.stable_diagonal()
        top = self.comm.allreduce(float(diag.max()) if len(diag) else 0.0, op=_max())
        return safety * float(np.sqrt(2.0 * self.material.density / top))

    # -- dynamics ------------------------------------------------------------------------
    def run_dynamic(self, dt: float, steps: int, *, velocity: ArrayLike | None = None,
                    every: int | None = None, output: str | os.PathLike | None = None,
                    progress: bool | None = None, gather: bool = True,
                    checkpoint: str | os.PathLike | None = None,
                    checkpoint_every: int | None = None,
                    restart: str | os.PathLike | None = None) -> DistributedRun:
        """Explicit velocity Verlet with bond breaking, as `cnem.pd.Problem.run_dynamic`.

        Parameters
        ----------
        dt, steps, velocity, every, progress
            As in serial (``steps``: the last step of the run, also when resuming).
            Progress is shown by rank 0 only.
        output : str or os.PathLike, optional
            Frames as VTU pieces (one per rank) indexed by one ``.pvtu`` per frame
            (`cnem.pd.distributed.output.PieceWriter`).
        gather : bool
            Gather ``u``, ``velocity``, ``damage``, the frames and the broken bonds on
            rank 0.
        checkpoint : str or os.PathLike, optional
            Stem of the checkpoint files (one per rank), written at the steps that are
            multiples of ``checkpoint_every`` (default: at the last step only).
        restart : str or os.PathLike, optional
            Stem of a checkpoint to resume from (same body, conditions and rank count):
            the run continues from its step to ``steps``.

        Returns
        -------
        DistributedRun
        """
        b, d, o = self.body, self.dim, self.body.n_owned
        stable = self.stable_time_step(1.0)
        dt, steps = checked_run(dt, steps, stable)
        save_every = steps if checkpoint_every is None else int(checkpoint_every)
        limit = self.material.stretch_limit(d, self.plane, b.horizon)
        prescribed = Prescribed(*self.owned_prescribed(), *self.owned_prescribed(velocity=True))
        u = np.zeros((len(b.points), d))
        owned_u = u[:o]
        v = np.zeros((o, d))
        if velocity is not None:
            if not callable(velocity) and np.shape(velocity) == (len(b), d):
                velocity = np.asarray(velocity)[b.owned]      # the whole body's, as serial
            v[:] = per_point(velocity, b.points[:o], d, "velocity")
        prescribed.start(owned_u, v)
        first, earlier, broken_here = 0, 0, 0      # earlier: broken before a restart
        if restart is not None:
            state = ckpt.load(restart, self.comm, b.owned)
            first, earlier = int(state["step"]), int(state["broken"])
            owned_u[:], v[:] = state["u"], state["velocity"]
            self.alive[:], self.alive_reverse[:] = state["alive"], state["alive_reverse"]
            self.ops.follow_breaking(self.alive)
        fext = self.load() / b.volumes[:o, None]

        def forces(owned):                         # a view of u, whose ghost rows it fills
            nonlocal broken_here
            force, broken = self.internal_force(u, limit)
            broken_here += broken
            return force + fext

        writer = None if output is None else PieceWriter(output, self.comm, b.points[:o], steps)
        times, frames, energy, files = [], [], [], []

        def store(step, owned, v):
            damage = self.damage()
            times.append(step * dt)
            if gather:
                gu, gd = self.gather(owned), self.gather(damage)
                if self.root:
                    frames.append((gu, gd))
            energy.append(self.energy(u, v))
            if writer is not None:
                files.append(writer.write(step, u=owned, damage=damage, velocity=v))

        def check_and_save(step, owned, v):
            self._check_finite(step, dt, owned, v, stable)
            if checkpoint is not None and step % save_every == 0:
                total = earlier + self.comm.allreduce(broken_here)
                ckpt.save(checkpoint, self.comm, step=step, broken=total, owned=b.owned,
                          u=owned, velocity=v, alive=self.alive,
                          alive_reverse=self.alive_reverse)

        velocity_verlet(owned_u, v, dt, steps, forces=forces, mass=self.material.density,
                        prescribed=prescribed, after_step=check_and_save, frame=store,
                        every=every, start=first, progress=progress if self.root else False,
                        desc="PD steps")
        damage = self.damage()
        local = dict(owned=b.owned, u=owned_u.copy(), velocity=v.copy(), damage=damage)
        return DistributedRun(
            problem=self, u=self.gather(owned_u) if gather else None,
            velocity=self.gather(v) if gather else None,
            damage=self.gather(damage) if gather else None,
            broken_bonds=self.broken_bonds() if gather else None,
            times=np.array(times), frames=frames, energy=np.array(energy), files=files,
            broken=earlier + self.comm.allreduce(broken_here), local=local, step=steps)

    def _check_finite(self, step, dt, u, v, stable):
        """`cnem.pd.guards.diverged` on every rank once any rank's owned ``u`` or ``v``
        is not finite (the lowest global point number that is)."""
        bad = first_non_finite(u, v)
        point = self.comm.allreduce(int(self.body.owned[bad]) if bad >= 0 else len(self.body),
                                    op=_min())
        if point < len(self.body):
            raise diverged(step, dt, point, self.body.global_points[point], stable)

    def relax(self, *, tol: float = 1e-8, max_steps: int = 100_000, steps: int = 1,
              every: int | None = None, progress: bool | None = None) -> Relaxation:
        """Adaptive dynamic relaxation over the ranks (`cnem.pd.distributed.relaxation.relax`);
        ``u``, ``damage`` gathered on rank 0."""
        self.static_only("relax")
        return relax(self, tol=tol, max_steps=max_steps, steps=steps, every=every,
                     progress=progress)


def _max():
    from .comm import mpi
    return mpi().MAX


def _min():
    from .comm import mpi
    return mpi().MIN

