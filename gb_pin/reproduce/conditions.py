"""The experiments of the paper's Figs. 3-8: which robots, learning rates and run lengths each figure needs.

Fig. 4 runs planar5 at eta 0.1 and 0.01, Fig. 5 planar5 over nine learning rates, Fig. 7
planar20 and planar50, Fig. 8 planar2 ... planar50 (eta 0.1, sigma by Eq. 12); Figs. 3 and
6 show one trial of planar5 and planar20 after 10, 100, 1000 and 10000 movements.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.experiments.trials import Condition
from gb_pin.learn.metrics import evaluation_schedule

FIGURES = ("fig3", "fig4", "fig5", "fig6", "fig7", "fig8", "throughput")
QUANTILES = (0.1, 0.25, 0.5, 0.75, 0.9)  # the paper's bands: median bold, 10/90 % thin, 25-75 % filled
LEARNING_RATES = (0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5)  # Fig. 5
JOINTS = (2, 3, 5, 7, 10, 15, 20, 30, 50)  # Fig. 8
SNAPSHOTS = (10, 100, 1000, 10000)  # Figs. 3 and 6
FIG4_RATES = (0.1, 0.01)
FIG7_ROBOTS = ("planar20", "planar50")
PER_DECADE = 100  # recorded movement counts per decade beyond 1000 (every movement before)


@dataclass(frozen=True)
class Settings:
    """What every statistic of a reproduction used.

    Attributes:
        trials: trials per condition (the paper: 100).
        movements: run length N of Figs. 4, 7, 8 and the length at which final errors
            are read (Fig. 5 runs low learning rates longer, see :func:`fig5_length`).
        seed: seed of trial 0 (trial i uses seed + i); also the seed of the snapshot trial.
        out: output folder.
    """

    trials: int = 100
    movements: int = 10_000
    seed: int = 0
    out: str = "reproduction"

    def as_dict(self) -> dict[str, Any]:
        """The settings as a plain dict."""
        return {"trials": self.trials, "movements": self.movements, "seed": self.seed}


def schedule(length: int, also: int) -> tuple[int, ...]:
    """Recorded movement counts of a run of ``length``: every one up to 1000, then 100 per decade.

    Args:
        length: the run length.
        also: a count recorded as well where it is shorter than ``length`` (the length
            ``movements`` at which final errors are read).

    Returns:
        The sorted movement counts, 0 and ``length`` included.
    """
    at = evaluation_schedule(length, per_decade=PER_DECADE)
    if also < length:
        at = np.union1d(at, [also])
    return tuple(int(a) for a in at)


def fig5_length(learning_rate: float, movements: int) -> int:
    """Run length of Fig. 5 for a learning rate: N, and N * 0.01 / eta for eta < 0.01.

    Rates below 0.01 thus get the learning "budget" eta * r of eta = 0.01; at N = 10^4
    that is 100 / eta movements, which lets the slowest rates reach 10 % of E_0.
    """
    return max(movements, math.ceil(movements * 0.01 / learning_rate - 1e-9))


def conditions_for(figure: str, movements: int) -> list[Condition]:
    """The conditions a figure needs, with their run lengths and recorded movement counts.

    Args:
        figure: ``"fig4"``, ``"fig5"``, ``"fig7"`` or ``"fig8"``; any other name needs none
            (Figs. 3 and 6 are one babble run each, the throughput benchmark its own trials).
        movements: the run length N.

    Returns:
        The conditions, in the figure's order.
    """

    def planar(robot: str, eta: float, length: int) -> Condition:
        return Condition(
            robot=robot,
            parameters={"learning_rate": eta},
            movements=length,
            schedule=schedule(length, movements),
        )

    if figure == "fig4":
        return [planar("planar5", eta, movements) for eta in FIG4_RATES]
    if figure == "fig5":
        return [planar("planar5", eta, fig5_length(eta, movements)) for eta in LEARNING_RATES]
    if figure == "fig7":
        return [planar(r, 0.1, movements) for r in FIG7_ROBOTS]
    if figure == "fig8":
        return [planar(f"planar{m}", 0.1, movements) for m in JOINTS]
    return []


def expand(figures: Sequence[str]) -> list[str]:
    """Figure names in drawing order; ``"all"`` stands for every figure and the throughput benchmark.

    Raises:
        InvalidArgumentError: a name is unknown, or there is none.
    """
    names: list[str] = []
    for f in figures:
        if f == "all":
            names += list(FIGURES)
        elif f in FIGURES:
            names.append(f)
        else:
            raise InvalidArgumentError(f"unknown figure {f!r}; valid: {', '.join(FIGURES)}, all")
    if not names:
        raise InvalidArgumentError(f"name at least one figure: {', '.join(FIGURES)} or all")
    return list(dict.fromkeys(names))
