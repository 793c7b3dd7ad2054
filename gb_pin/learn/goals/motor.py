"""Random motor babbling: the baseline goal babbling is measured against."""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.learn.goals.base import MOTOR, GoalGenerator, MotorArrays

SPREAD = 1  # params[SPREAD]: standard deviation of the random postures around home [rad]


class MotorGoals(GoalGenerator):
    """Motor babbling: movements to random postures around home, learnt by the same learner.

    Every movement goes in joint space, linearly over L steps as a home return (Eq. 7), from
    the current posture to q_home + spread * z (z standard normal per joint, clipped to the
    joint limits). The map learns from every step with the efficiency weight of Eq. 5 only
    (no goal, so no direction weight); no home returns. No goal set is needed.

    Args:
        spread: standard deviation of the random postures around home [rad or m].
    """

    name: ClassVar[str] = "motor"
    kind: ClassVar[int] = MOTOR
    needs_targets: ClassVar[bool] = False
    arrays_class: ClassVar[type] = MotorArrays

    def __init__(self, spread: float = 0.25) -> None:
        self.spread = check.positive_float("spread", spread)

    def get_params(self) -> dict[str, Any]:
        """``{"spread": ...}``."""
        return {"spread": self.spread}

    def param_array(self) -> NDArray[np.float64]:
        """``[inf (no snap-back), spread]``."""
        return np.array([np.inf, self.spread], dtype=np.float64)
