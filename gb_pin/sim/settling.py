"""Settling: how long a simulated arm holds each asked posture before its hand is read.

A real arm does not jump to a commanded posture: its servos take time, and a reading taken too
early sees the arm on its way, lagging the command. A learner fed such readings learns the lag
(along its own paths) as if it were kinematics. Two rules:

- **settle until at rest** (the default): hold the command until every joint's speed is below
  ``tolerance`` [rad/s] and its acceleration below ``tolerance / REST_TIME`` (an arm swinging
  through a turning point has no speed but an acceleration), checked every ``CHECK_PERIOD``
  seconds, and at most ``settle`` seconds. What a careful experimenter does on hardware: wait
  until the servos report that they stopped moving.
- **a fixed control period** (``period``): hold each command exactly that long, at rest or not
  (a controller streaming postures at 1 / period Hz).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.sim.health import MIN_TOLERANCE, bounded_time

DEFAULT_SETTLE = 0.5
"""Longest hold of the default rule [s]."""
DEFAULT_TOLERANCE = 0.01
"""Joint speed below which the default rule calls the arm at rest [rad/s]."""
REST_TIME = 0.05
"""At rest also means |acceleration| < tolerance / REST_TIME [rad/s^2] (REST_TIME in [s])."""
CHECK_PERIOD = 0.01
"""Seconds between the checks of the rule (the servos run at every step in between)."""


def count_contacts(data: Any, contacts: list[Any]) -> None:
    """Add this step's contacts to ``contacts`` = ``[total, pairs]`` (the plant's counts).

    ``pairs[(geom1, geom2)]`` = (steps in contact, deepest penetration [m]).
    """
    touching = int(data.ncon)
    if not touching:
        return
    contacts[0] += touching
    for i in range(touching):
        c = data.contact[i]
        key = (int(c.geom1), int(c.geom2))
        steps, deepest = contacts[1].get(key, (0, 0.0))
        contacts[1][key] = (steps + 1, max(deepest, -float(c.dist)))


def ramp(mujoco: Any, model: Any, data: Any, q: Any, speed: float, contacts: Any = None) -> int:
    """Move the servo targets from the last command to ``q`` on a straight line at ``speed``; the steps.

    The joint that moves most at ``speed`` [rad/s], a target per MuJoCo step; the last target, ``q``
    itself, is left to the settling rule. ``contacts``: counted as :meth:`Settling.hold` counts them.
    """
    start = data.ctrl.copy()
    count = math.ceil(float(np.abs(q - start).max()) / (speed * float(model.opt.timestep)))
    for i in range(1, count):
        data.ctrl[:] = start + (q - start) * (i / count)
        mujoco.mj_step(model, data)
        if contacts is not None:
            count_contacts(data, contacts)
    return max(count - 1, 0)


@dataclass(frozen=True)
class Settling:
    """When a held posture is read.

    Attributes:
        time: the longest hold (``tolerance`` given) or the exact hold (``tolerance`` None) [s].
        tolerance: joint speed of "at rest" [rad/s] (prismatic joints: [m/s]); None: a fixed period.
    """

    time: float = DEFAULT_SETTLE
    tolerance: float | None = DEFAULT_TOLERANCE

    @classmethod
    def of(
        cls, settle: float | None = None, tolerance: float | None = None, period: float | None = None
    ) -> Settling:
        """The rule from the plant's arguments: ``period``, or ``settle`` and ``tolerance``.

        Raises:
            InvalidArgumentError: ``period`` together with ``settle`` or ``tolerance``, a value
                that is not a positive finite number, a hold beyond
                :data:`~gb_pin.sim.health.MAX_HOLD` or a tolerance below
                :data:`~gb_pin.sim.health.MIN_TOLERANCE`.
        """
        if period is not None:
            if settle is not None or tolerance is not None:
                raise InvalidArgumentError(
                    "give period= (a fixed hold per ask) or settle= / tolerance= (hold until at rest), "
                    f"not both: got period={period!r}, settle={settle!r}, tolerance={tolerance!r}"
                )
            return cls(bounded_time("period", check.positive_float("period", period)), None)
        if tolerance is not None:
            tolerance = check.positive_float("tolerance", tolerance)
            if tolerance < MIN_TOLERANCE:
                raise InvalidArgumentError(
                    f"tolerance must be at least {MIN_TOLERANCE:g} rad/s (a speed MuJoCo can resolve), "
                    f"got {tolerance!r}"
                )
        longest = DEFAULT_SETTLE if settle is None else check.positive_float("settle", settle)
        return cls(bounded_time("settle", longest), DEFAULT_TOLERANCE if tolerance is None else tolerance)

    def steps(self, timestep: float) -> tuple[int, int]:
        """(most steps of one hold, steps between checks) at ``timestep`` [s]."""
        most = max(1, round(self.time / timestep))
        every = max(1, round(CHECK_PERIOD / timestep))
        return most, (most if self.tolerance is None else min(every, most))

    def hold(self, mujoco: Any, model: Any, data: Any, contacts: Any = None, limit: int | None = None) -> int:
        """Advance the simulation under the current command by this rule; returns the steps taken.

        ``contacts``: ``[total, pairs]`` to which each step's contacts are added
        (:func:`count_contacts`; the steps then run one at a time); None: not counted. ``limit``:
        take at most that many steps (a budget), whatever the rule says.
        """
        most, every = self.steps(float(model.opt.timestep))
        if limit is not None:
            most = max(1, min(most, limit))
            every = min(every, most)
        if contacts is not None:
            return self._hold_counting(mujoco, model, data, contacts, most, every)
        if self.tolerance is None:
            mujoco.mj_step(model, data, most)
            return most
        speed, accel = self.tolerance, self.tolerance / REST_TIME
        done = 0
        while done < most:
            n = min(every, most - done)
            mujoco.mj_step(model, data, n)
            done += n
            if np.abs(data.qvel).max() < speed and np.abs(data.qacc).max() < accel:
                break
        return done

    def _hold_counting(self, mujoco: Any, model: Any, data: Any, contacts: Any, most: int, every: int) -> int:
        """:meth:`hold` one step at a time, counting each step's contacts (:func:`count_contacts`)."""
        speed = math.inf if self.tolerance is None else self.tolerance
        accel = math.inf if self.tolerance is None else self.tolerance / REST_TIME
        for done in range(1, most + 1):
            mujoco.mj_step(model, data)
            count_contacts(data, contacts)
            if done % every == 0 and np.abs(data.qvel).max() < speed and np.abs(data.qacc).max() < accel:
                return done
        return most

    def describe(self) -> str:
        """``settle until at rest (0.01 rad/s), at most 0.5 s`` or ``a fixed period of 0.05 s``."""
        if self.tolerance is None:
            return f"a fixed period of {self.time:g} s"
        return f"settle until at rest ({self.tolerance:g} rad/s), at most {self.time:g} s"

    def options(self) -> dict[str, float]:
        """The rule as the plant's keyword arguments (``settle``, ``tolerance``, or ``period``)."""
        if self.tolerance is None:
            return {"period": self.time}
        return {"settle": self.time, "tolerance": self.tolerance}
