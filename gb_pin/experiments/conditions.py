"""Experimental conditions (a robot and babble parameters), grids of them, and a sweep's results.

The babble parameters a condition may set are the learner's hyperparameters, named once
in :data:`gb_pin.learn.config.NAMES` (:data:`BABBLE_ARGS` is that tuple), and the goals
(:data:`GOAL_ARGS`: a goal generator by name, e.g. ``"progress"`` or ``"uniform:snap=0.05"``,
a goal set and a separate test set as nested lists), all plain JSON values.
"""

from __future__ import annotations

import itertools
import json
import math
import os
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gb_pin._files import write_json
from gb_pin.exceptions import InvalidArgumentError, ResultFileError
from gb_pin.experiments._json import plain, read_json
from gb_pin.experiments.trialset import TrialSet
from gb_pin.learn.config import NAMES, check_values

BABBLE_ARGS: tuple[str, ...] = NAMES  # the babble arguments of a trial: the hyperparameter table's names
GOAL_ARGS: tuple[str, ...] = ("goals", "targets", "eval_targets")  # where goals and E^X come from
SAFETY_ARGS: tuple[str, ...] = ("obstacles", "self_collision", "collision_geometry", "clearance")
TRIAL_ARGS: tuple[str, ...] = (*BABBLE_ARGS, *GOAL_ARGS, *SAFETY_ARGS)
SWEEP_FORMAT = "gb_pin.sweep"
MAX_CONDITIONS = 10**4
"""The most conditions of one sweep (each is validated by a one-movement run before any trial)."""


def check_parameters(parameters: Mapping[str, Any], what: str = "babble arguments") -> None:
    """Validate babble arguments against the hyperparameter table (names and values; None = default).

    The values are only checked: a trial receives them as given, so that its journal key
    and its :class:`TrialSet`'s ``parameters`` are what the caller wrote.

    Raises:
        InvalidArgumentError: an unknown name or a bad value (the message names it).
    """
    unknown = sorted(set(parameters) - set(TRIAL_ARGS))
    if unknown:
        raise InvalidArgumentError(f"unknown {what} {unknown}; valid: {', '.join(TRIAL_ARGS)}")
    check_values({k: v for k, v in parameters.items() if k in BABBLE_ARGS}, what=what)
    obstacles = parameters.get("obstacles")
    if obstacles is not None:
        from gb_pin.safety.obstacles import check_obstacles

        if not isinstance(obstacles, list) or not all(isinstance(o, dict) for o in obstacles):
            raise InvalidArgumentError(
                "obstacles of a trial are a list of plain tables (gb_pin.safety.obstacles.plain: "
                f'{{"kind": "box", "center": [...], "half_extents": [...]}}), got {obstacles!r:.100}'
            )
        check_obstacles(obstacles)
    goals = parameters.get("goals")
    if goals is not None:
        if not isinstance(goals, str):
            raise InvalidArgumentError(
                f"goals of a trial must be a goal generator's name (with parameters, e.g. "
                f"'uniform:snap=0.05'), got {goals!r}"
            )
        from gb_pin.learn.goals import make_goals

        make_goals(goals)
    for key in ("targets", "eval_targets"):
        value = parameters.get(key)
        if key == "targets" and isinstance(value, str):
            from gb_pin.robot.workspace import WorkspaceRegion

            WorkspaceRegion.parse(value)  # a workspace region travels as its spec
        elif value is not None:
            arr = np.asarray(value, dtype=object)
            try:
                ok = (
                    arr.ndim == 2
                    and 0 < arr.shape[0] <= 10**6
                    and bool(np.all(np.isfinite(arr.astype(float))))
                )
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise InvalidArgumentError(
                    f"{key} of a trial must be a finite (N, n) list of points, got {value!r:.80}"
                )


@dataclass(frozen=True)
class Condition:
    """One experimental condition of a sweep: a robot and babble parameters.

    Attributes:
        robot: preset name, e.g. ``"planar5"``, MODULE:NAME, or a KinematicTarget loaded from a URDF
            or example-robot-data (trial workers rebuild it from its robot source).
        parameters: babble arguments (``learning_rate``, ``sigma``, ``sigma_delta``,
            ``radius``, ``path_length``, ``p_home``); the rest take the preset's defaults.
        movements: movements per trial; None takes the sweep's.
        schedule: movement counts to record (0 is always added); None: the default
            :func:`~gb_pin.learn.metrics.evaluation_schedule` of the run length.
    """

    robot: Any = "planar5"
    parameters: Mapping[str, Any] = field(default_factory=dict)
    movements: int | None = None
    schedule: tuple[int, ...] | None = None

    def __hash__(self) -> int:
        items = tuple(sorted((k, json.dumps(plain(v))) for k, v in self.parameters.items()))
        return hash((self.robot, items, self.movements, self.schedule))

    @property
    def label(self) -> str:
        """A short readable name, e.g. ``planar5 learning_rate=0.1`` or ``planar5 goals=progress``."""
        parts = [robot_label(self.robot), *(_label(k, v) for k, v in sorted(self.parameters.items()))]
        return " ".join(parts)

    def to_json(self) -> dict[str, Any]:
        """A JSON-serialisable dict (a model robot as its label and robot source)."""
        source = None
        if not isinstance(self.robot, str):
            from gb_pin.runs.robot_source import describe

            source = describe(self.robot, None)
        return {
            "robot": robot_label(self.robot),
            **({} if source is None else {"robot_source": source}),
            "parameters": dict(self.parameters),
            "movements": self.movements,
            "schedule": None if self.schedule is None else list(self.schedule),
        }

    @classmethod
    def from_json(cls, raw: Mapping[str, Any]) -> Condition:
        """Rebuild a condition from :meth:`to_json`'s dict."""
        sched = raw.get("schedule")
        mv = raw.get("movements")
        return cls(
            robot=str(raw["robot"]),
            parameters=dict(raw.get("parameters", {})),
            movements=None if mv is None else int(mv),
            schedule=None if sched is None else tuple(int(s) for s in sched),
        )


def robot_label(robot: Any) -> str:
    """A robot's name for labels and trial sets: the preset or MODULE:NAME, else the target's name."""
    return robot if isinstance(robot, str) else str(getattr(robot, "name", robot))


def _label(key: str, value: Any) -> str:
    if key in ("targets", "eval_targets") and value is not None and not isinstance(value, str):
        return f"{key}=<{len(value)} points>"
    return (
        f"{key}={value:g}"
        if isinstance(value, int | float) and not isinstance(value, bool)
        else f"{key}={value}"
    )


def conditions_grid(robot: str | Sequence[str] = "planar5", **parameters: Any) -> list[Condition]:
    """The Cartesian product of a robot (or robots) and babble arguments given as values or lists.

    >>> [c.label for c in conditions_grid("planar5", learning_rate=[0.01, 0.1])]
    ['planar5 learning_rate=0.01', 'planar5 learning_rate=0.1']
    """
    gridded = (*BABBLE_ARGS, "goals")
    unknown = sorted(set(parameters) - set(gridded))
    if unknown:
        raise InvalidArgumentError(
            f"unknown sweep arguments {unknown}; valid: robot, {', '.join(gridded)} "
            "(goal and test sets: Condition(parameters=...))"
        )

    def values(name: str, v: Any) -> list[Any]:
        out = [v] if isinstance(v, str) or not isinstance(v, Sequence | np.ndarray) else list(v)
        if not out:
            raise InvalidArgumentError(f"{name} must list at least one value, got {v!r}")
        return out

    robots = values("robot", robot)
    names = list(parameters)
    lists = [values(n, parameters[n]) for n in names]
    count = math.prod(len(v) for v in lists) * len(robots)
    if count > MAX_CONDITIONS:
        raise InvalidArgumentError(
            f"the grid has {count} conditions; a sweep has at most {MAX_CONDITIONS} "
            "(gb_pin.experiments.conditions.MAX_CONDITIONS): split it into several sweeps"
        )
    return [
        Condition(robot=r, parameters={n: plain(v) for n, v in zip(names, combo, strict=True)})
        for r in robots
        for combo in itertools.product(*lists)
    ]


@dataclass(frozen=True, eq=False)
class Sweep:
    """Trials of several conditions: ``results[i]`` holds the trials of ``conditions[i]``.

    Iterating yields ``(condition, trial_set)`` pairs.
    """

    conditions: tuple[Condition, ...]
    results: tuple[TrialSet, ...]

    def __len__(self) -> int:
        return len(self.conditions)

    def __iter__(self) -> Iterator[tuple[Condition, TrialSet]]:
        return iter(zip(self.conditions, self.results, strict=True))

    def __getitem__(self, index: int) -> TrialSet:
        return self.results[index]

    def to_json(self) -> dict[str, Any]:
        """A JSON-serialisable dict: the conditions and each one's trials."""
        return {
            "format": SWEEP_FORMAT,
            "format_version": 1,
            "conditions": [c.to_json() for c in self.conditions],
            "results": [r.to_json() for r in self.results],
        }

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the sweep to one JSON file (atomically, no pickle)."""
        write_json(path, self.to_json())

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Sweep:
        """Read a sweep written by :meth:`save`.

        Raises:
            ResultFileError: missing, malformed or foreign file.
        """
        path = os.fspath(path)
        raw = read_json(path)
        if not isinstance(raw, dict) or raw.get("format") != SWEEP_FORMAT:
            raise ResultFileError(f"{path}: not a gb_pin sweep file")
        try:
            conditions = tuple(Condition.from_json(c) for c in raw["conditions"])
            results = tuple(TrialSet.from_json(r, path) for r in raw["results"])
        except (KeyError, TypeError, ValueError) as exc:
            raise ResultFileError(f"{path}: malformed sweep file ({exc!r})") from exc
        if len(conditions) != len(results):
            raise ResultFileError(f"{path}: {len(conditions)} conditions but {len(results)} results")
        return cls(conditions=conditions, results=results)
