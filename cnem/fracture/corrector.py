"""The predictor-corrector increment of `grow` (``scheme="corrector"``).

The explicit increment appends at each tip a straight segment in the direction
the criterion gives at the tip: the tangent of the path where the segment
starts. A smooth path bends over the increment, and its chord of length ``da``
points along the mean of the tangents at its two ends, to ``O(da^2)``:
``phi(da/2) = (phi(0) + phi(da)) / 2 + O(da^2)``. Taking the start tangent
instead turns every segment by ``O(da)``, so the path converges only to first
order in the increment. The corrector (Heun's, or the trapezoidal rule, on the
path):

1. *predictor*: at every growing tip a trial segment of the tip's increment in
   the criterion's direction ``theta0`` (the explicit segment), all tips at once;
2. the trial model is solved, and at every trial tip the criterion gives the
   kink ``theta1`` relative to the trial segment: the path's tangent at the end
   of the increment;
3. *corrector*: the accepted segment turns by ``theta1 / 2`` from the trial one
   (``theta0 + theta1 / 2`` from the tip's direction): a second-order step on a
   smooth path. A genuine kink, the first one of a straight crack under mixed
   mode, stays whole in ``theta0``; only the bending of the path is averaged.

The trial configuration is thrown away: its model is a local update of the
accepted one and the accepted segments are grown from the accepted model again,
so the models of the run are those of the explicit scheme's construction
(`discretize` of the same cloud and cracks); the `cnem.SIFWarning` of a trial
tip's discs is not passed on (the accepted tip's own K warns at the next
increment). The increments (a Paris-type ``exponent`` included), load factors
and cycles are those of the accepted tips.
A tip whose trial segment meets the boundary, a hole or a crack, or whose trial
tip is closed or finds no direction, takes the predictor's direction in that
step, reported as event ``"predictor"``; a trial that cannot be built or solved
(the trial cut the body apart, say) leaves every tip to its predictor.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np

from ..errors import CNEMError, SIFWarning

if TYPE_CHECKING:
    from typing import Any

__all__ = ["SCHEMES", "corrections"]

#: The increments of `grow` (``scheme=``).
SCHEMES = {
    "explicit": "a straight segment in the criterion's direction at the tip (first order)",
    "corrector": "that segment turned by half the kink found at its end (predictor-corrector, "
                 "second order on a smooth path; two solves per increment)",
}


def corrections(run: Any, state: dict, increments: np.ndarray, step: int,
                clearance: float) -> np.ndarray:
    """Turn of every tip's accepted segment from its predictor, by a trial step.

    Parameters
    ----------
    run : cnem.fracture.growth._Run
        The run in the accepted configuration (its ``snapshot``, ``restore``,
        ``advance``, ``solve`` and ``tip_kink``); it is left there.
    state : dict
        `_Run.state` of the accepted configuration (``"angle"`` the predictor kinks).
    increments : (t,) ndarray
        Segment length per tip (0: does not grow).
    step : int
    clearance : float
        As in `grow`.

    Returns
    -------
    (t,) ndarray
        ``theta1 / 2`` (radians) per tip; 0 where the tip does not grow or takes
        the predictor (event ``"predictor"``).
    """
    out = np.zeros(len(run.rows))
    growing = np.flatnonzero(increments > 0)
    saved = run.snapshot()
    run.trial_events = trial = []
    fallback = {}                                  # tip -> why it takes the predictor
    try:
        if not run.advance(state, increments, step, clearance):
            return out
        for e in trial:
            for i in (growing if e.tip < 0 else [e.tip]):
                fallback.setdefault(int(i), f"its trial segment: {e.kind}: {e.message}")
        sol = run.solve()
        for i in growing:
            c, end, active = run.rows[i]
            if i in fallback or not active:
                fallback.setdefault(int(i), "its trial tip stopped growing")
                continue
            with warnings.catch_warnings():    # a trial tip's discs: not the user's tip
                warnings.simplefilter("ignore", SIFWarning)
                res, theta, _, at_bound = run.tip_kink(sol, run.cracks[c][end])
            if res[0] <= 0 or at_bound:
                fallback[int(i)] = (f"the criterion finds no direction at its trial tip "
                                    f"(K = {res[0]:.4g}, {res[1]:.4g})")
                continue
            out[i] = 0.5 * theta
    except CNEMError as err:
        out[:] = 0.0
        fallback = {int(i): f"the trial step fails: {err}" for i in growing}
    finally:
        run.trial_events = None
        run.restore(saved)
    for i, why in sorted(fallback.items()):
        run.event("predictor", step, i, state["tips"][i],
                  f"the corrector takes the predictor's direction in this step: {why}")
    return out
