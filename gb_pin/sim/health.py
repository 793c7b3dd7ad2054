"""A simulated arm that never lies: its state checked after every hold, its time settings bounded.

When MuJoCo's integration blows up (a servo gain far too stiff for the time step, huge link
masses, commands far beyond the limits) it resets the simulation, prints a warning on stderr and
goes on: a plant that only read the joints would hand the learner readings of the reset arm as
if nothing had happened. After every hold the plant calls :func:`check_state`: MuJoCo's
instability counters (``data.warning``: bad accelerations, speeds or positions, after which it
resets), non-finite positions or speeds, and joint speeds beyond :data:`SPEED_LIMIT` (no servo
arm moves that fast: the integration is running away) end the ask with a
:class:`~gb_pin.exceptions.SimulationError` naming the plant's settings to change.

Time settings are bounded (:func:`hold_steps`): a hold is at most :data:`MAX_HOLD` seconds and
:data:`MAX_HOLD_STEPS` MuJoCo steps, the time step at least :data:`MIN_TIMESTEP`, the rest
tolerance at least :data:`MIN_TOLERANCE` (``period=1e6`` or ``timestep=1e-9`` used to hang inside
MuJoCo; ``period=1e9`` raised a raw TypeError from ``mj_step``). One evaluation of the true body
(E^X over a goal set) simulates at most :data:`EVALUATION_STEPS` steps in all.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gb_pin.exceptions import InvalidArgumentError, SimulationError

MAX_HOLD = 10.0
"""Longest hold of one ask (``settle``, ``period``) [s]."""
MIN_TIMESTEP = 1e-5
"""Shortest MuJoCo time step [s]."""
MAX_HOLD_STEPS = 2 * 10**5
"""Most MuJoCo steps of one hold (``settle`` or ``period`` over ``timestep``)."""
MIN_TOLERANCE = 1e-9
"""Smallest joint speed that counts as at rest [rad/s]."""
SPEED_LIMIT = 1e3
"""Joint speed beyond which the integration is running away [rad/s] (prismatic: [m/s])."""
EVALUATION_STEPS = 5 * 10**5
"""Most MuJoCo steps simulated by one evaluation of the true body (all its postures together)."""
_UNSTABLE = ("mjWARN_BADQACC", "mjWARN_BADQVEL", "mjWARN_BADQPOS")


def bounded_time(name: str, value: float, most: float = MAX_HOLD) -> float:
    """``value`` [s] if at most ``most``, else an error naming the setting."""
    if value > most:
        raise InvalidArgumentError(f"{name} must be at most {most:g} s (one hold of one ask), got {value!r}")
    return value


def hold_steps(name: str, seconds: float, timestep: float) -> int:
    """The MuJoCo steps of a hold of ``seconds`` at ``timestep``, refused beyond :data:`MAX_HOLD_STEPS`."""
    steps = max(1, round(seconds / timestep))
    if steps > MAX_HOLD_STEPS:
        raise InvalidArgumentError(
            f"{name}={seconds:g} s at timestep={timestep:g} s is {steps} MuJoCo steps per ask, more than "
            f"{MAX_HOLD_STEPS}: shorten {name} or lengthen timestep"
        )
    return steps


def warnings_seen(mujoco: Any, data: Any) -> int:
    """MuJoCo's count of instability warnings in ``data`` so far (bad accelerations, speeds, positions)."""
    return sum(int(data.warning[int(getattr(mujoco.mjtWarning, w))].number) for w in _UNSTABLE)


def check_state(mujoco: Any, data: Any, before: int, settings: str, what: str = "the ask") -> None:
    """Raise if the simulation went unstable since MuJoCo's warning count was ``before``.

    Args:
        mujoco: the mujoco module.
        data: the arm's ``MjData`` after the hold.
        before: MuJoCo's warning count (:func:`warnings_seen`) before the hold.
        settings: the plant's settings as text, named in the message (``kp=..., timestep=...``).
        what: what was simulated (``ask 12``).

    Raises:
        SimulationError: MuJoCo warned of (and reset after) an instability, or the positions or
            speeds are not finite or beyond :data:`SPEED_LIMIT`.
    """
    problem = ""
    if warnings_seen(mujoco, data) > before:
        problem = "MuJoCo found NaN/Inf or huge accelerations and reset the simulation"
    elif not (np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.qvel))):
        problem = "joint positions or speeds became NaN/Inf"
    else:
        speed = float(np.abs(data.qvel).max(initial=0.0))
        if speed > SPEED_LIMIT:
            problem = f"a joint moves at {speed:.3g} rad/s, beyond {SPEED_LIMIT:g} (a runaway integration)"
    if problem:
        raise SimulationError(
            f"the simulated arm went unstable during {what}: {problem}; its readings would be wrong. "
            f"Settings: {settings}: lower kp, shorten timestep, raise armature or damping, "
            "or keep commands within the joint limits"
        )


class StepBudget:
    """MuJoCo steps left to one evaluation of the true body (:data:`EVALUATION_STEPS`)."""

    def __init__(self, settings: str, steps: int | None = None) -> None:
        self.settings = settings
        self.steps: int = EVALUATION_STEPS if steps is None else steps
        self.left = self.steps

    def spend(self, steps: int, at_rest: bool) -> None:
        """Count ``steps``; raise once they are all spent and the arm is still not at rest.

        Raises:
            SimulationError: the evaluation would simulate beyond its budget.
        """
        self.left -= steps
        if self.left <= 0 and not at_rest:
            raise SimulationError(
                f"evaluating the simulated arm's resting postures took more than {self.steps} MuJoCo "
                f"steps (its servos are too soft to bring it to rest quickly). Settings: "
                f"{self.settings}: raise kp or damping, or evaluate fewer postures at once"
            )


RESTORE_MARGIN = 1.0
"""How far beyond its limits a restored joint (or its command) may be [rad] (prismatic: [m])."""


def check_restored(data: Any, dofs: Any, steps: int, timestep: float, lower: Any, upper: Any) -> None:
    """Refuse a plant state (from a checkpoint) that no run of this plant could have left.

    The simulated time must be the steps taken times the time step, the speeds within
    :data:`SPEED_LIMIT`, the joints and their commands within the limits widened by
    :data:`RESTORE_MARGIN` (sessions clip commands to the limits; the servos sag a little beyond).

    Raises:
        InvalidArgumentError: the state is inconsistent, naming what.
    """
    expected = steps * timestep
    if abs(float(data.time) - expected) > 1e-9 * max(1.0, expected) + 0.5 * timestep:
        raise InvalidArgumentError(
            f"the checkpoint's plant state is inconsistent: simulated time {float(data.time):.6g} s after "
            f"{steps} steps of {timestep:g} s (expected {expected:.6g} s); the file was altered"
        )
    speed = float(np.abs(data.qvel).max(initial=0.0))
    if speed > SPEED_LIMIT:
        raise InvalidArgumentError(
            f"the checkpoint's plant state has a joint moving at {speed:.3g} rad/s (beyond {SPEED_LIMIT:g})"
        )
    lo, hi = np.asarray(lower) - RESTORE_MARGIN, np.asarray(upper) + RESTORE_MARGIN
    checked = (("joint positions", np.asarray(data.qpos)[dofs]), ("commands", np.asarray(data.ctrl)))
    for what, values in checked:
        if np.any(values < lo) or np.any(values > hi):
            raise InvalidArgumentError(
                f"the checkpoint's plant state has {what} beyond the joint limits by more than "
                f"{RESTORE_MARGIN:g}: {np.array2string(values, precision=3, max_line_width=200)}"
            )
