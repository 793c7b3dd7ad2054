"""Goals in a fixed cyclic order: a deterministic curriculum (and the seam's second implementation)."""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.goals.base import CYCLIC, GoalArrays, GoalGenerator, snap_threshold


class CyclicGoals(GoalGenerator):
    """The targets of X* in their given order, round and round; draws no random numbers.

    Args:
        start: index of the first goal.
        snap: snap-back lag threshold [m] (None: off), as for :class:`UniformGoals`.
    """

    name: ClassVar[str] = "cyclic"
    kind: ClassVar[int] = CYCLIC

    def __init__(self, start: int = 0, snap: float | None = None) -> None:
        self.start_index = check.positive_int("start", start, minimum=0)
        self.snap = snap_threshold(snap)

    def get_params(self) -> dict[str, Any]:
        """``{"start": ..., "snap": ...}``."""
        return {"start": self.start_index, **super().get_params()}

    def check_state(self, state: GoalArrays) -> None:
        """The next index must be a target's."""
        if not 0 <= int(state.istate[0]) < state.targets.shape[0]:
            raise InvalidArgumentError(f"cyclic goals: next index {int(state.istate[0])} out of range")

    def start(self, targets: NDArray[np.float64]) -> GoalArrays:
        """The first goal is target ``start`` (modulo the number of targets)."""
        istate = np.array([self.start_index % targets.shape[0]], dtype=np.int64)
        return GoalArrays(self.kind, targets, self.param_array(), istate, np.zeros(1))
