"""ExternalRobot: a robot gb_pin cannot compute, only ask: a real arm driven through a session.

On hardware nobody may have written the kinematics down, and nothing but the robot itself may
say where its hand is. An :class:`ExternalRobot` describes such a robot by what goal babbling
needs besides Eq. 1: a home posture, joint limits, a goal set and the task dimension. Only
``babble_session`` drives it: every posture the robot executes is one that ``ask()`` returned,
the first being home (its reading is f(q_home), where the learner starts). E^X then comes from
evaluation movements (``babble_session(..., evaluate="movements")``) or not at all; the free
measure of progress (``History.reach``) needs none. This module does not import pinocchio.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.robot.function import BlackBox, home_and_limits


class ExternalRobot(BlackBox):
    """A robot known only by its home, limits, goal set and task dimension (no forward model).

    Args:
        home: home posture q_home (m,) [rad] or [m], within the limits.
        n_task: the task dimension n (3 for a hand position).
        targets: goal set X* (N, n) [m] (also the test set of evaluation movements by default).
        lower: lower joint limits (m,); default -inf (unbounded).
        upper: upper joint limits (m,); default +inf.
        name: a label for messages and saved files.

    Raises:
        InvalidArgumentError: a bad home, limits, task dimension or targets.
    """

    chain = None  # nothing gb_pin can compute: only ask/tell sessions drive it
    preset: str | None = None  # a preset it was taken from: runs use that preset's learner defaults

    def __init__(
        self,
        home: ArrayLike,
        n_task: int,
        targets: ArrayLike,
        *,
        lower: ArrayLike | None = None,
        upper: ArrayLike | None = None,
        name: str = "external",
    ) -> None:
        self.home, self.lower, self.upper = home_and_limits(home, lower, upper)
        self._n = check.positive_int("n_task", n_task, 1, 10**4)
        self.targets: NDArray[np.float64] = check.points("targets", targets, self._n)
        self.name = str(name)

    @classmethod
    def from_preset(cls, name: str, targets: ArrayLike | None = None) -> ExternalRobot:
        """The real robot a preset describes: its home, limits and goal set, none of its kinematics.

        Runs on it take the preset's learner defaults (e.g. the SO-101's radius).

        Args:
            name: the preset.
            targets: a goal set of its own (N, n), e.g. taught in a camera's frame (docs/CAMERA.md);
                default the preset's (in the URDF's base frame).

        Raises:
            UnknownRobotError: unknown preset name.
            InvalidArgumentError: targets of another task dimension or not finite.
        """
        from gb_pin.robot.presets import load_robot

        model = load_robot(name)
        if targets is None:
            targets = model.targets if model.targets is not None else model.auto_targets()
        robot = cls(model.home, model.n_task, targets, lower=model.lower, upper=model.upper,
                    name=f"{name} (hardware)")  # fmt: skip
        robot.preset = name
        return robot

    def auto_targets(self) -> NDArray[np.float64]:
        """The goal set given at construction."""
        return self.targets

    def forward(self, q: ArrayLike) -> NDArray[np.float64]:
        """There is no forward model: only the robot knows where its hand is.

        Raises:
            InvalidArgumentError: always; drive the robot with ``gb_pin.babble_session``.
        """
        raise InvalidArgumentError(
            f"ExternalRobot {self.name!r} has no forward model: drive it with gb_pin.babble_session "
            "(ask() a posture, execute it, tell() the reading)"
        )

    def __repr__(self) -> str:
        return f"ExternalRobot({self.name!r}, {self.n_joints} joints, {self.n_task} task axes)"
