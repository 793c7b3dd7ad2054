"""Competence-progress goal selection (SAGG-RIAC-like): practise where the arm is improving."""

from __future__ import annotations

from typing import ClassVar

from gb_pin.learn.goals.base import PROGRESS
from gb_pin.learn.goals.selection import GoalSetSelector


class ProgressGoals(GoalSetSelector):
    """Targets of X* chosen by their learning progress, measured on log errors.

    After Baranes and Oudeyer's SAGG-RIAC (2013), with one region per target. For target k,
    two running averages of log e, e being ||x*_k - x|| at the end of each movement to it: a
    fast one (weight ``rate``) and a slow one (weight ``rate / 4``); the progress is
    p_k = slow - fast, positive while the errors fall. Log errors measure the relative
    improvement, so that unreachable goals, whose absolute errors fluctuate without
    improving, do not look interesting. Rules: with probability ``uniform_share`` a uniform
    choice; else a target visited fewer than twice (uniformly among them) while there are
    any; else target k with probability proportional to max(p_k, 0) (uniform if no target
    improves). With the snap-back on by default.

    Args:
        uniform_share: probability of a uniform choice.
        rate: weight of the newest log error in the fast average (the slow one: rate / 4).
        snap: the snap-back lag threshold [m] (None: off).

    The defaults (rate 0.1, snap 0.02 m) were chosen on planar5 with an oversized goal set,
    20 seeds, E^X at 3000 movements on a test grid (docs/GOALS.md).
    """

    name: ClassVar[str] = "progress"
    kind: ClassVar[int] = PROGRESS

    def __init__(self, uniform_share: float = 0.2, rate: float = 0.1, snap: float | None = 0.02) -> None:
        super().__init__(uniform_share=uniform_share, rate=rate, snap=snap)
