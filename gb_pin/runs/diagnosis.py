"""Why a run stayed degenerate, and what to try: the warning that ends such a run.

A run *stays degenerate* when, after enough movements to judge (:data:`JUDGE_AFTER`), its E^X is
above :data:`ERROR_SHARE` of E_0 (the learned model barely beats the constant home posture) or it
made at most :data:`FEW_PROTOTYPES` local models (it barely explored). The usual causes are measured
on the robot: a home at a joint limit (the exploration is clipped away), a singular home (some task
directions do not move), targets beyond the arm's reach, or simply too few movements.
"""

from __future__ import annotations

from typing import Any

import numpy as np

JUDGE_AFTER = 100  # movements: the paper's planar5 is at about 10 % of E_0 by then
ERROR_SHARE = 0.5
FEW_PROTOTYPES = 5
AT_LIMIT = 0.01  # a joint within this fraction of its range from a limit sits at it
SINGULAR = 1e-3  # smallest singular value of the task Jacobian at home [m] (joint reach scaled)


def diagnose(result: Any) -> str | None:
    """A one-line warning for a run that stayed degenerate (see the module), or None.

    Args:
        result: a :class:`~gb_pin.runs.result.BabbleResult`.
    """
    e0 = float(result.initial_error)  # the home estimate's, also after init= (a continued run)
    if result.movements < JUDGE_AFTER or not e0 > 0:
        return None
    share = result.error / e0
    few = result.n_prototypes <= FEW_PROTOTYPES
    if share <= ERROR_SHARE and not few:
        return None
    what = f"E^X is {share:.0%} of E_0" if share > ERROR_SHARE else f"E^X is {share:.0%} of E_0, but"
    reasons = _causes(result)
    if result.movements < 1000:
        reasons.append(f"only {result.movements} movements (most robots need 1000-3000)")
    why = "; ".join(reasons) if reasons else "no cause measured on the robot"
    return (
        f"the run stayed degenerate: {what} with {result.n_prototypes} local models after "
        f"{result.movements} movements. Likely: {why}. Try: more --movements; a --home inside the limits "
        "(or none, for a URDF or erd:NAME robot: gb-pin chooses one); fewer --joints; --radius about the "
        "target grid's spacing (docs/ROBOTS.md)"
    )


def _causes(result: Any) -> list[str]:
    """The causes measured on the robot: joints at their limits at home, a singular home, far targets."""
    target = result.target
    causes = []
    lower, upper = np.asarray(target.lower, dtype=float), np.asarray(target.upper, dtype=float)
    bounded = np.isfinite(lower) & np.isfinite(upper) & (upper > lower)
    span = np.where(bounded, upper - lower, 1.0)
    home = np.asarray(target.home, dtype=float)
    near = bounded & (np.minimum(home - lower, upper - home) <= AT_LIMIT * span)
    names = getattr(target, "joints", None) or [f"joint {i}" for i in range(home.shape[0])]
    if near.any():
        causes.append(
            f"the home has {', '.join(str(names[i]) for i in np.flatnonzero(near))} at a joint limit"
        )
    chain = getattr(target, "chain", None)
    if chain is not None:
        from gb_pin.robot.onboarding import smallest_singular_value
        from gb_pin.robot.reachability import beyond_reach

        if smallest_singular_value(target, home[None, :])[0] < SINGULAR:
            causes.append("the home is singular (some task directions do not move: a stretched arm?)")
        far = int(beyond_reach(chain, lower, upper, result.targets).sum())
        if far:
            causes.append(f"{far} of {len(result.targets)} targets lie beyond the arm's reach")
    return causes
