"""Error-based goal selection: practise where the inverse estimate is worst."""

from __future__ import annotations

from typing import ClassVar

from gb_pin.learn.goals.base import ERROR
from gb_pin.learn.goals.selection import GoalSetSelector


class ErrorGoals(GoalSetSelector):
    """Targets of X* chosen with probability proportional to their recent error.

    Rules: with probability ``uniform_share`` a uniform choice; else a target never tried yet
    (uniformly among them) while there are any; else target k with probability proportional
    to e_k, the running average (weight ``rate``) of ||x*_k - x|| at the end of its movements.
    As in the lab code of the paper's authors (python-goal-babbling's error-based selector).
    It chases unreachable goals when X* has any (docs/GOALS.md).

    Args: see :class:`~gb_pin.learn.goals.selection.GoalSetSelector`.
    """

    name: ClassVar[str] = "error"
    kind: ClassVar[int] = ERROR
