"""Goals in a fixed cyclic order: a deterministic curriculum (and the seam's second implementation)."""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.learn.goals.base import CYCLIC, GoalArrays, GoalGenerator


class CyclicGoals(GoalGenerator):
    """The targets of X* in their given order, round and round; draws no random numbers.

    Args:
        start: index of the first goal.
    """

    name: ClassVar[str] = "cyclic"
    kind: ClassVar[int] = CYCLIC

    def __init__(self, start: int = 0) -> None:
        self.start_index = check.positive_int("start", start, minimum=0)

    def get_params(self) -> dict[str, Any]:
        """``{"start": ...}``."""
        return {"start": self.start_index}

    def start(self, targets: NDArray[np.float64]) -> GoalArrays:
        """The first goal is target ``start`` (modulo the number of targets)."""
        istate = np.array([self.start_index % targets.shape[0]], dtype=np.int64)
        return GoalArrays(self.kind, targets, istate, np.zeros(1))
