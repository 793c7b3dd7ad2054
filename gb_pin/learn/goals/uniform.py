"""The paper's goal choice: uniformly at random from the target set X* (Sec. II-A)."""

from __future__ import annotations

from typing import ClassVar

from gb_pin.learn.goals.base import UNIFORM, GoalGenerator


class UniformGoals(GoalGenerator):
    """Each goal-directed movement goes to a target drawn uniformly from X* (paper Sec. II-A).

    One draw ``rng.integers(0, N)`` per goal-directed movement, from the run's Generator.
    """

    name: ClassVar[str] = "uniform"
    kind: ClassVar[int] = UNIFORM
