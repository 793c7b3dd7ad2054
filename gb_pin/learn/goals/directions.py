"""Direction sampling: goals without a goal set, for workspaces nobody gave us.

After Rolf, "Goal babbling with unknown ranges: a direction-sampling approach" (ICDL 2013), as
gb_pin implements it (the rules are documented in docs/GOALS.md):

1. Each goal-directed movement moves the target from where the last one ended (the end of
   its path) along a random unit direction u (isotropic in the task space) by ``distance``:
   x*_end = x*_start + distance * u, reached over L steps as in Eq. 3.
2. Snap-back: if the arm ended farther than ``snap`` from its goal, the next movement starts
   where the arm got to, not at the unreached goal. This keeps the goals at the border of
   what the arm can do instead of wandering off into space.
3. Home returns (Eq. 7, probability p_home) reset the start to f(q_home), as in the paper.

Without the snap-back (``snap=None``) the goals drift out of reach and learning diverges
(measured in docs/GOALS.md).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.learn.goals.base import DIRECTIONS, DirectionArrays, GoalGenerator, snap_threshold

DISTANCE = 1  # params[DISTANCE]: the length of each goal path [m]


class DirectionGoals(GoalGenerator):
    """Goals a fixed distance away in random directions (no goal set needed).

    Args:
        distance: D, how far each goal lies from the start of its path [m] (0.2 m for an
            arm of 1 m: a fifth of its reach).
        snap: the lag threshold [m] of the snap-back (rule 2); None: off (diverges).

    The run's target set is then used only to measure E^X (give ``eval_targets`` or a robot
    with a target set).
    """

    name: ClassVar[str] = "directions"
    kind: ClassVar[int] = DIRECTIONS
    needs_targets: ClassVar[bool] = False
    arrays_class: ClassVar[type] = DirectionArrays

    def __init__(self, distance: float = 0.2, snap: float | None = 0.05) -> None:
        self.distance = check.positive_float("distance", distance)
        self.snap = snap_threshold(snap)

    def get_params(self) -> dict[str, Any]:
        """``{"distance": ..., "snap": ...}``."""
        return {"distance": self.distance, **super().get_params()}

    def param_array(self) -> NDArray[np.float64]:
        """``[snap, distance]``."""
        return np.array([self.snap, self.distance], dtype=np.float64)
