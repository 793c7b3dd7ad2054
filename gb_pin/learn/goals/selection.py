"""What the goal-set selectors share: a uniform share, a rate, per-target state (error, progress)."""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.goals.base import GoalArrays, GoalGenerator, SelectorArrays, snap_threshold

# params of the selectors: [snap, uniform_share, rate]
SHARE = 1
RATE = 2
# istate: [index of the last goal (-1: none), visits of target 0, ..., visits of target N-1]
LAST = 0


class GoalSetSelector(GoalGenerator):
    """A goal generator that picks targets of X* by a score kept per target.

    Args:
        uniform_share: probability of a uniform choice instead of one by score (keeps every
            target visited).
        rate: weight of the newest measurement in the per-target running averages (0, 1].
        snap: the snap-back lag threshold [m] (None: off).
    """

    arrays_class: ClassVar[type] = SelectorArrays

    def __init__(self, uniform_share: float = 0.2, rate: float = 0.3, snap: float | None = 0.05) -> None:
        self.uniform_share = check.probability("uniform_share", uniform_share)
        rate = check.positive_float("rate", rate)
        if rate > 1.0:
            raise InvalidArgumentError(f"rate must lie in (0, 1], got {rate!r}")
        self.rate = rate
        self.snap = snap_threshold(snap)

    def get_params(self) -> dict[str, Any]:
        """``{"uniform_share": ..., "rate": ..., "snap": ...}``."""
        return {"uniform_share": self.uniform_share, "rate": self.rate, **super().get_params()}

    def param_array(self) -> NDArray[np.float64]:
        """``[snap, uniform_share, rate]``."""
        return np.array([self.snap, self.uniform_share, self.rate], dtype=np.float64)

    def check_state(self, state: GoalArrays) -> None:
        """The last index must be -1 or a target's, the visit counts >= 0."""
        N = state.targets.shape[0]
        if not -1 <= int(state.istate[LAST]) < N or np.any(state.istate[1:] < 0):
            raise InvalidArgumentError(f"{self.name} goals: corrupted state (index or visit counts)")

    def start(self, targets: NDArray[np.float64]) -> GoalArrays:
        """No goal chosen yet, no target visited; two floats per target (score state)."""
        N = targets.shape[0]
        istate = np.zeros(N + 1, dtype=np.int64)
        istate[LAST] = -1
        return SelectorArrays(self.kind, targets, self.param_array(), istate, np.zeros(2 * N))
