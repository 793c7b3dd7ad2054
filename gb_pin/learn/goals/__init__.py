"""Goal generators (who chooses each movement's goal) and their registry by name."""

from __future__ import annotations

from typing import Any

from gb_pin._names import suggest
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.goals.base import GoalArrays, GoalGenerator, PythonGoals
from gb_pin.learn.goals.cyclic import CyclicGoals
from gb_pin.learn.goals.uniform import UniformGoals

# name -> class, for goals="uniform" and for rebuilding a generator from a checkpoint.
GOAL_GENERATORS: dict[str, type[GoalGenerator]] = {"uniform": UniformGoals, "cyclic": CyclicGoals}


def make_goals(goals: str | GoalGenerator | None, params: dict[str, Any] | None = None) -> GoalGenerator:
    """A goal generator from a name (its defaults, or ``params``), a generator, or None (the paper's).

    Raises:
        InvalidArgumentError: unknown name, bad parameters or a wrong type.
    """
    if goals is None:
        return UniformGoals()
    if isinstance(goals, GoalGenerator):
        return goals
    if isinstance(goals, str):
        cls = GOAL_GENERATORS.get(goals)
        if cls is None:
            raise InvalidArgumentError(
                f"goals={goals!r} is not a goal generator; {suggest(goals, GOAL_GENERATORS)}"
            )
        try:
            return cls(**(params or {}))
        except TypeError as exc:
            raise InvalidArgumentError(f"goals={goals!r}: bad parameters {params!r} ({exc})") from exc
    raise InvalidArgumentError(
        f"goals must be a name ({', '.join(GOAL_GENERATORS)}) or a GoalGenerator, got {goals!r}"
    )


__all__ = [
    "GOAL_GENERATORS",
    "CyclicGoals",
    "GoalArrays",
    "GoalGenerator",
    "PythonGoals",
    "UniformGoals",
    "make_goals",
]
