"""Competence-progress goal selection (SAGG-RIAC-like): practise where the arm is improving."""

from __future__ import annotations

from typing import ClassVar

from gb_pin.learn.goals.base import PROGRESS
from gb_pin.learn.goals.selection import GoalSetSelector


class ProgressGoals(GoalSetSelector):
    """Targets of X* chosen by their learning progress, measured on log errors.

    After Baranes and Oudeyer's SAGG-RIAC (2013), with one region per target. For target k,
    ``p_k`` is the running average (weight ``rate``) of log e_prev - log e_now over its visits,
    e being ||x*_k - x|| at the end of the movement: the relative improvement, so that
    unreachable goals, whose absolute errors fluctuate without improving, do not look
    interesting. Rules: with probability ``uniform_share`` a uniform choice; else a target
    visited fewer than twice (uniformly among them) while there are any; else target k with
    probability proportional to max(p_k, 0) (uniform if no target improves).
    With the snap-back on by default (docs/GOALS.md: the best goal-set rule measured).

    Args: see :class:`~gb_pin.learn.goals.selection.GoalSetSelector`.
    """

    name: ClassVar[str] = "progress"
    kind: ClassVar[int] = PROGRESS
