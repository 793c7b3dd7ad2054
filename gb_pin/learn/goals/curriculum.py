"""A curriculum from home outwards: goals from one block of the goal set after the other.

Learning a large region (half of every joint's range) from home at once spreads the first
movements over goals the map cannot reach yet; growing the region from home outwards lets the
map grow with it. The goal set is read as ``stages`` equal blocks, ordered from home outwards
(a workspace region writes them so: :mod:`gb_pin.robot.workspace`, block s holding the region
of ``f / 2^(stages - 1 - s)``). Stage s (from 0) draws uniformly from block s; it begins after
``first * growth^(s - 1)`` goal-directed movements (stage 1 after ``first``, stage 2 after
``first * growth``, ...). Stage boundaries count goals, not movements: with p_home = 0.1 about
nine movements in ten are goal-directed, so the defaults 900 and 2700 fall near movements 1000
and 3000 (the reference's curriculum, docs/WORKSPACE.md).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.goals.base import CURRICULUM, GoalArrays, GoalGenerator, snap_threshold

STAGES = 1  # params[STAGES]: the number of blocks
FIRST = 2  # params[FIRST]: goals drawn before stage 1
GROWTH = 3  # params[GROWTH]: each later stage lasts this factor longer


class CurriculumGoals(GoalGenerator):
    """Goals uniform within one block of X* at a time, the blocks from home outwards.

    One draw ``rng.integers(0, N / stages)`` per goal-directed movement (as :class:`UniformGoals`
    within the block); ``istate[0]`` counts the goals drawn.

    Args:
        stages: blocks of the goal set (its size must be a multiple); 1 is uniform goals.
        first: goal-directed movements drawn from block 0 (then block 1).
        growth: stage s >= 1 begins after ``first * growth^(s - 1)`` goals.
        snap: snap-back lag threshold [m] (None: off), as for :class:`UniformGoals`.
    """

    name: ClassVar[str] = "curriculum"
    kind: ClassVar[int] = CURRICULUM

    def __init__(
        self, stages: int = 3, first: int = 900, growth: float = 3.0, snap: float | None = None
    ) -> None:
        self.stages = check.positive_int("stages", stages, 1, 64)
        self.first = check.positive_int("first", first, 1)
        self.growth = check.positive_float("growth", growth)
        if self.growth < 1.0:
            raise InvalidArgumentError(f"curriculum growth must be >= 1, got {growth!r}")
        self.snap = snap_threshold(snap)

    def get_params(self) -> dict[str, Any]:
        """``{"stages": ..., "first": ..., "growth": ..., "snap": ...}``."""
        return {"stages": self.stages, "first": self.first, "growth": self.growth, **super().get_params()}

    def param_array(self) -> NDArray[np.float64]:
        """``[snap, stages, first, growth]``."""
        return np.array([self.snap, self.stages, self.first, self.growth], dtype=np.float64)

    def start(self, targets: NDArray[np.float64]) -> GoalArrays:
        """The state at movement 0 (no goal drawn yet).

        Raises:
            InvalidArgumentError: a goal set whose size is not a multiple of ``stages``.
        """
        if targets.shape[0] % self.stages != 0:
            raise InvalidArgumentError(
                f"curriculum goals with {self.stages} stages need a goal set of a multiple of {self.stages} "
                f"points (the blocks from home outwards, e.g. targets='workspace:fraction=0.5'), "
                f"got {targets.shape[0]}"
            )
        return GoalArrays(self.kind, targets, self.param_array(), np.zeros(1, dtype=np.int64), np.zeros(1))

    def check_state(self, state: GoalArrays) -> None:
        """The count of goals drawn must be >= 0."""
        super().check_state(state)
        if state.istate.shape[0] < 1 or int(state.istate[0]) < 0:
            raise InvalidArgumentError("curriculum goals: corrupted state (negative goal count)")


def stage_of(count: int, stages: int, first: float, growth: float) -> int:
    """The stage (block) of the ``count``-th goal (from 0): the Python twin of the compiled rule."""
    s, end = 0, float(first)
    while s < stages - 1 and count >= end:
        s += 1
        end *= growth
    return s
