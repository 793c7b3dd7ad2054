"""The arms gb_pin drives over a Feetech bus: their motors (LeRobot's names and ids) and units.

LeRobot's follower arms (SO-100 and SO-101) have six STS3215 servos with ids 1-6. A calibration
puts the middle of each servo's calibrated range at a known posture of the preset's URDF:

- SO-101: the URDF's zero (example-robot-data's so101.urdf is LeRobot's so101_new_calib, whose
  zero is the middle of the calibrated range), so radians of the URDF = radians(LeRobot degrees);
- SO-100: the middle of the URDF's joint limits (its URDF predates the mid-range convention).

Radians of the URDF <-> ticks: ``q = centre + sign * (raw - mid) * 2 pi / 4095`` with ``mid`` the
middle of the calibrated range, ``sign`` -1 for a motor of drive mode 1 (as LeRobot's degrees).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

MOTORS = ("shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll", "gripper")
TICKS_PER_RAD = 4095 / (2 * math.pi)


@dataclass(frozen=True, eq=False)
class ArmKind:
    """A robot preset's motors: names, bus ids, the URDF posture at each range's middle, URDF limits."""

    robot: str
    motors: tuple[str, ...]
    ids: tuple[int, ...]
    centre: NDArray[np.float64]  # (6,) URDF radians at the middle of each calibrated range
    lower: NDArray[np.float64]  # (6,) URDF limits
    upper: NDArray[np.float64]
    learned: tuple[str, ...]  # the preset's joints (the rest held at the preset's locked value 0)


def arm_kind(robot: str) -> ArmKind:
    """The motors of ``robot`` ("so101" or "so100"), with the URDF's limits (loads the preset).

    Raises:
        InvalidArgumentError: another robot.
    """
    from gb_pin.exceptions import InvalidArgumentError
    from gb_pin.robot.presets import load_robot

    if robot not in ("so101", "so100"):
        raise InvalidArgumentError(f"robot must be 'so101' or 'so100' for a Feetech arm, got {robot!r}")
    target = load_robot(robot)
    model = target.full_model
    names = list(model.names)[1:]
    index = [names.index(m) for m in MOTORS]
    lower = np.asarray(model.lowerPositionLimit, dtype=float)[index]
    upper = np.asarray(model.upperPositionLimit, dtype=float)[index]
    centre = np.zeros(6) if robot == "so101" else 0.5 * (lower + upper)
    return ArmKind(robot, MOTORS, (1, 2, 3, 4, 5, 6), centre, lower, upper, tuple(target.joints))
