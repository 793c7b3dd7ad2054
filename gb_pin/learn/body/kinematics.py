"""What the learner needs from a robot: forward kinematics, a home posture and joint limits."""

from __future__ import annotations

from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from gb_pin.learn.body.chain import KinematicChain


class Kinematics(Protocol):
    """A robot as the learner sees it (a :class:`~gb_pin.robot.target.KinematicTarget` is one)."""

    @property
    def chain(self) -> KinematicChain:
        """Compiled forward kinematics of the task map."""

    @property
    def home(self) -> NDArray[np.float64]:
        """Home posture q_home (m,), within the limits."""

    @property
    def lower(self) -> NDArray[np.float64]:
        """Lower joint limits (m,), -inf where unbounded."""

    @property
    def upper(self) -> NDArray[np.float64]:
        """Upper joint limits (m,), +inf where unbounded."""
