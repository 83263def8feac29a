"""Peridynamics on MPI ranks (``pip install "cnem[mpi]"``): the drop-in `Body` and `Problem`.

A serial script becomes a distributed one by its import alone::

    import cnem.pd.distributed as pd        # instead of: import cnem.pd as pd

    body = pd.Body(points, volumes, horizon, cracks=cracks)
    prob = pd.Problem(body, pd.BondBased(E, fracture_energy=G0))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    run = prob.run_dynamic(prob.stable_time_step(), 500, output="out/run")
    if run.u is not None:                   # rank 0 holds the gathered results
        print(run.damage.max())

and runs with ``python script.py`` (one rank) or ``mpiexec -n 4 python script.py``.
Every rank is given the whole point cloud; it keeps the bonds of the points it owns
(recursive coordinate bisection weighted by family size) and one horizon of ghost
points (`Body`). Dynamics and dynamic relaxation give the serial answers (`Problem`).
Without mpi4py, `Body` raises `cnem.errors.MissingExtraError` naming the extra.
"""

from ..materials import BondBased, StateBased
from .body import Body
from .problem import DistributedRun, Problem

__all__ = ["Body", "Problem", "DistributedRun", "BondBased", "StateBased"]
