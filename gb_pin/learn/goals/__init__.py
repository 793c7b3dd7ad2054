"""Goal generators (who chooses each movement's goal) and their registry by name."""

from __future__ import annotations

import inspect
from typing import Any

from gb_pin._names import closest, suggest
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.goals.base import GoalArrays, GoalGenerator, PythonGoals
from gb_pin.learn.goals.curriculum import CurriculumGoals
from gb_pin.learn.goals.cyclic import CyclicGoals
from gb_pin.learn.goals.directions import DirectionGoals
from gb_pin.learn.goals.error import ErrorGoals
from gb_pin.learn.goals.motor import MotorGoals
from gb_pin.learn.goals.progress import ProgressGoals
from gb_pin.learn.goals.uniform import UniformGoals

# name -> class, for goals="uniform" and for rebuilding a generator from a checkpoint.
GOAL_GENERATORS: dict[str, type[GoalGenerator]] = {
    cls.name: cls
    for cls in (
        UniformGoals,
        CyclicGoals,
        DirectionGoals,
        ErrorGoals,
        ProgressGoals,
        MotorGoals,
        CurriculumGoals,
    )
}


def make_goals(goals: str | GoalGenerator | None, params: dict[str, Any] | None = None) -> GoalGenerator:
    """A goal generator from a name (its defaults, or ``params``), a generator, or None (the paper's).

    A name may carry parameters: ``"progress:snap=0.1,uniform_share=0.3"``, ``"uniform:snap=0.05"``
    (``none`` for None).

    Raises:
        InvalidArgumentError: unknown name, bad parameters or a wrong type.
    """
    if goals is None:
        return UniformGoals()
    if isinstance(goals, GoalGenerator):
        return goals
    if isinstance(goals, str):
        if ":" in goals:
            goals, text = goals.split(":", 1)
            params = {**(params or {}), **_parse_params(goals, text)}
        cls = GOAL_GENERATORS.get(goals)
        if cls is None:
            raise InvalidArgumentError(
                f"goals={goals!r} is not a goal generator; {suggest(goals, GOAL_GENERATORS)}"
            )
        accepted = [p for p in inspect.signature(cls.__init__).parameters if p != "self"]
        for key in params or {}:
            if key not in accepted:
                close = closest(key, accepted)
                hint = f"did you mean {close[0]!r}? " if close else ""
                raise InvalidArgumentError(
                    f"goals={goals!r}: unknown parameter {key!r}; {hint}{goals} takes "
                    f"{', '.join(accepted) or 'no parameters'}"
                )
        try:
            return cls(**(params or {}))
        except TypeError as exc:
            raise InvalidArgumentError(f"goals={goals!r}: bad parameters {params!r} ({exc})") from exc
    raise InvalidArgumentError(
        f"goals must be a name ({', '.join(GOAL_GENERATORS)}) or a GoalGenerator, got {goals!r}"
    )


def _parse_params(name: str, text: str) -> dict[str, Any]:
    """``"snap=0.1,uniform_share=0.3"`` as ``{"snap": 0.1, "uniform_share": 0.3}`` (numbers or none)."""
    out: dict[str, Any] = {}
    for item in filter(None, (part.strip() for part in text.split(","))):
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise InvalidArgumentError(f"goals={name}:{text!r}: expected key=value pairs, got {item!r}")
        value = value.strip()
        try:
            out[key.strip()] = None if value.lower() == "none" else (int(value) if value.lstrip("-").isdigit()
                                                                     else float(value))  # fmt: skip
        except ValueError as exc:
            raise InvalidArgumentError(
                f"goals={name}:{text!r}: {key.strip()}={value!r} is not a number"
            ) from exc
    return out


__all__ = [
    "GOAL_GENERATORS",
    "CurriculumGoals",
    "CyclicGoals",
    "DirectionGoals",
    "ErrorGoals",
    "GoalArrays",
    "GoalGenerator",
    "MotorGoals",
    "ProgressGoals",
    "PythonGoals",
    "UniformGoals",
    "make_goals",
]
