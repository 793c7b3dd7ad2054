"""The paper's goal choice: uniformly at random from the target set X* (Sec. II-A)."""

from __future__ import annotations

from typing import ClassVar

from gb_pin.learn.goals.base import UNIFORM, GoalGenerator, snap_threshold


class UniformGoals(GoalGenerator):
    """Each goal-directed movement goes to a target drawn uniformly from X* (paper Sec. II-A).

    One draw ``rng.integers(0, N)`` per goal-directed movement, from the run's Generator.

    Args:
        snap: snap-back lag threshold [m]: after a goal-directed movement that ended farther
            than this from its goal, the next path starts where the arm got to. None (the
            paper, default): the next path starts at the last goal. 0.05 m rescues goal sets
            with unreachable goals (docs/GOALS.md).
    """

    name: ClassVar[str] = "uniform"
    kind: ClassVar[int] = UNIFORM

    def __init__(self, snap: float | None = None) -> None:
        self.snap = snap_threshold(snap)
