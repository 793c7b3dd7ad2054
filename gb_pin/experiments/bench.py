"""Benchmark: microseconds per babbling step, everything included, on one core.

A step is one example: target path point, inverse estimate, noise, forward
kinematics, weights, prototype check, gradient update and noise walk.
"""

from __future__ import annotations

import platform
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from gb_pin import _validation as check
from gb_pin.runs.api import babble, warmup


@dataclass(frozen=True)
class BenchRow:
    """One benchmark measurement.

    Attributes:
        robot: preset name (or the robot's name).
        movements: movements per run.
        steps: steps per run.
        us_per_step: best-of-``repeat`` wall time per step, evaluation only at the end [us].
        us_per_step_eval: the same with E^X/D^home recorded on the default schedule [us].
        prototypes: prototypes at the end of the run.
        error: final E^X [m].
    """

    robot: str
    movements: int
    steps: int
    us_per_step: float
    us_per_step_eval: float
    prototypes: int
    error: float


def run_benchmark(robots: list[Any], movements: int = 2000, repeat: int = 3, seed: int = 0) -> list[BenchRow]:
    """Time ``babble`` for each robot (after one warm-up run that compiles the kernels).

    A robot is anything ``babble`` takes: a preset name, a KinematicTarget (its onboarded defaults
    apply), MODULE:NAME.

    Raises:
        InvalidArgumentError: ``repeat`` < 1 or a bad number of movements.
    """
    repeat = check.positive_int("repeat", repeat)
    movements = check.movements("movements", movements, minimum=1)
    warmup()  # JIT compilation, not timed
    rows = []
    for robot in robots:
        best = np.inf
        best_eval = np.inf
        for r in range(repeat):
            start = time.perf_counter()
            res = babble(robot, movements=movements, seed=seed + r, schedule=[0, movements])
            best = min(best, time.perf_counter() - start)
            start = time.perf_counter()
            babble(robot, movements=movements, seed=seed + r)
            best_eval = min(best_eval, time.perf_counter() - start)
        rows.append(
            BenchRow(
                robot=robot if isinstance(robot, str) else str(getattr(robot, "name", robot)),
                movements=movements,
                steps=res.steps,
                us_per_step=1e6 * best / res.steps,
                us_per_step_eval=1e6 * best_eval / res.steps,
                prototypes=res.n_prototypes,
                error=res.error,
            )
        )
    return rows


def format_table(rows: list[BenchRow]) -> str:
    """A markdown table of benchmark rows, with the machine it ran on."""
    lines = [
        f"machine: {platform.processor() or platform.machine()}, Python {platform.python_version()}",
        "",
        "| robot | movements | steps | us/step | us/step (with eval) | prototypes | final E^X [m] |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r.robot} | {r.movements} | {r.steps} | {r.us_per_step:.2f} | {r.us_per_step_eval:.2f} "
            f"| {r.prototypes} | {r.error:.4f} |"
        )
    return "\n".join(lines)
