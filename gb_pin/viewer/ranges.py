"""Which recorded movements to show: ``"A:B"`` ranges, and the recorded steps that fall in one.

No meshcat here: the command line parses ``--record-movements`` with :func:`parse_range`
whether or not the viewer is installed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from gb_pin.exceptions import InvalidArgumentError

if TYPE_CHECKING:
    from gb_pin.learn.history import RecordedSteps
    from gb_pin.runs.result import BabbleResult

Movements = tuple[int, int | None]
"""(first, last or None): movements ``first <= r < last``."""


def parse_range(text: str, name: str = "movements") -> Movements:
    """Parse ``"A:B"`` (movements A <= r < B), ``"A:"`` or ``":B"`` into (first, last or None).

    Raises:
        InvalidArgumentError: not of that form, negative, or B <= A.
    """
    parts = text.split(":") if isinstance(text, str) else []
    try:
        if len(parts) != 2:
            raise ValueError
        first = int(parts[0]) if parts[0].strip() else 0
        last = int(parts[1]) if parts[1].strip() else None
    except ValueError:
        raise InvalidArgumentError(
            f"{name} must be a range FIRST:LAST of movement counts (e.g. 0:50, 100:), got {text!r}"
        ) from None
    if first < 0 or (last is not None and last <= first):
        raise InvalidArgumentError(f"{name} range {text!r} must satisfy 0 <= FIRST < LAST")
    return first, last


def select_movements(recording: RecordedSteps, movements: Movements | None) -> RecordedSteps:
    """The recorded steps of movements ``first <= r < last`` (all of them for None).

    Raises:
        InvalidArgumentError: no recorded step falls in the range.
    """
    from gb_pin.learn.history import RecordedSteps  # the learner's package loads its compiler

    if movements is None:
        keep = np.ones(recording.step.shape[0], dtype=bool)
    else:
        first, last = movements
        keep = recording.movement >= first
        if last is not None:
            keep &= recording.movement < last
    if not np.any(keep):
        have = (
            f"{int(recording.movement.min())}..{int(recording.movement.max())}"
            if recording.movement.size
            else "none"
        )
        raise InvalidArgumentError(f"no recorded step in movements {movements!r}; recorded movements: {have}")
    return RecordedSteps(
        step=recording.step[keep],
        movement=recording.movement[keep],
        posture=recording.posture[keep],
        target=recording.target[keep],
        position=recording.position[keep],
    )


def recorded_steps(result: BabbleResult, movements: Movements | None = None) -> RecordedSteps:
    """The recorded steps of ``result`` in ``movements``.

    Raises:
        InvalidArgumentError: the result has no recorded step, or none in the range.
    """
    if result.recording is None or result.recording.step.shape[0] == 0:
        raise InvalidArgumentError(
            "this result has no recorded steps; record them with babble(record=gb_pin.Recording(...)) "
            "or gb-pin babble --record-every 1 --record-movements 0:50"
        )
    return select_movements(result.recording, movements)
