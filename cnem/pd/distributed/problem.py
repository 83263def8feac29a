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
from .._pmb_kernels import pmb_forces_rows
from ...material import PLANES
from ..guards import checked_run, diverged, first_non_finite
from ..solution import DynamicRun
from ..velocity import VelocityConditions
from . import _kernels as K
from . import checkpoint as ckpt
from .operators import LocalOperators
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


#: Points per block of the energy sums (their bonds' temporaries stay small).
ENERGY_BLOCK = 65536


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
        kind = getattr(material, "kind", None)
        if kind not in ("bond", "state"):
            raise MaterialError(f"material: expected cnem.pd.BondBased or StateBased (CPD runs "
                             f"serially only), received {type(material).__name__}")
        super().__init__()
        self.body, self.material, self.plane, self.dim = body, material, plane, body.dim
        self.comm = body.comm
        self.surface_correction = True if surface_correction is None else \
            bool(surface_correction)
        self.ops = LocalOperators(body, material, plane, self.surface_correction)
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

        Bond-based: the exchange runs while the bonds of the interior points
        (`Body.interior`, no ghost in their families) are computed, and the boundary
        points follow it. State-based: the exchange first, then the dilatations, one
        more exchange (of them and the pressures) and the forces.
        """
        b, ops = self.body, self.ops
        o = b.n_owned
        pending = b.halo.start(u)
        if self.material.kind == "bond":
            out = np.empty((o, self.dim))
            args = (u, b.points, b.image, b.length, b.offsets, b.bond_j, ops.stiffness,
                    b.volumes, self.alive, limit, out)
            broken = pmb_forces_rows(b.interior, *args)
            b.halo.finish(pending)
            broken += pmb_forces_rows(b.boundary, *args)
            return out, int(broken)
        b.halo.finish(pending)
        broken = K.break_bonds(u, b.xi, b.length, b.offsets[:o + 1], b.bond_j, limit,
                               self.alive, self.alive_reverse)
        if self.comm.allreduce(int(broken)):
            ops.follow_breaking(self.alive)
        fields = np.zeros((len(b.points), 2))          # theta and P, copied to the ghosts
        fields[:o, 0] = ops.dilatation(u, self.alive)
        theta = np.ascontiguousarray(fields[:o, 0])
        P = np.empty(o)
        K.pressure(u, b.xi, b.length, b.offsets[:o + 1], b.bond_j, theta, ops.bulk_volume,
                   ops.c, self.alive, P)
        fields[:o, 1] = P
        b.halo.exchange(fields)
        out = np.empty((o, self.dim))
        K.lps_forces(u, b.xi, b.length, b.offsets[:o + 1], b.bond_j, b.volumes, ops.g,
                     ops.g_reverse, np.ascontiguousarray(fields[:, 0]),
                     np.ascontiguousarray(fields[:, 1]), ops.c, ops.c_reverse, self.alive,
                     self.alive_reverse, out)
        return out, int(broken)

    def energy(self, u: np.ndarray, v: np.ndarray) -> float:
        """Kinetic plus elastic energy of the whole body (all ranks)."""
        b, ops, o = self.body, self.ops, self.body.n_owned
        kinetic = 0.5 * self.material.density * float(b.volumes[:o] @ (v * v).sum(axis=1))
        if self.material.kind == "bond":
            elastic = 0.0
            for start in range(0, o, ENERGY_BLOCK):      # blocks of points: small temporaries
                stop = min(start + ENERGY_BLOCK, o)
                sl = slice(b.offsets[start], b.offsets[stop])
                i, j = b.bond_i[sl], b.bond_j[sl]
                y = b.xi[sl] + u[j] - u[i]
                s = np.sqrt((y * y).sum(axis=1)) / b.length[sl] - 1
                per = 0.25 * ops.bond_stiffness * ops.factor[sl] * b.beta[sl] * s * s * \
                    b.length[sl] * b.volumes[j] * self.alive[sl]
                elastic += float(b.volumes[start:stop] @ np.bincount(
                    i - start, weights=per, minlength=stop - start))
        else:
            theta = ops.dilatation(u, self.alive)
            ed = ops.deviatoric(u, theta)
            elastic = 0.5 * float(ops.bulk_volume @ (theta * theta)) + \
                0.5 * float((ops.c * self.alive) @ (ed * ed))
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
        b, ops, o = self.body, self.ops, self.body.n_owned
        if self.material.kind == "bond":
            per = ops.bond_stiffness * ops.factor * b.beta * b.volumes[b.bond_j] / b.length
            diag = np.bincount(b.bond_i, weights=per, minlength=o)
        else:
            diag = (ops.row_bound() / b.volumes[:o, None]).reshape(-1)
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
            v[:] = per_point(velocity, b.points[:o], d, "velocity")
        prescribed.start(owned_u, v)
        first, earlier, broken_here = 0, 0, 0      # earlier: broken before a restart
        if restart is not None:
            state = ckpt.load(restart, self.comm, b.owned)
            first, earlier = int(state["step"]), int(state["broken"])
            owned_u[:], v[:] = state["u"], state["velocity"]
            self.alive[:], self.alive_reverse[:] = state["alive"], state["alive_reverse"]
            if self.material.kind == "state":
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

