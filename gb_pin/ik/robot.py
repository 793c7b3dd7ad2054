"""The robot as the IK sees it: a preset name or any Kinematics, its chain, its task as components.

The solver handles every task map the learner learns through one compiled form: the task's
components (:class:`~gb_pin.learn.body.components.TaskComponents`); the paper's position task
is one position component. A preset name is resolved by the robot layer (imported only then:
planar presets need no Pinocchio).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.ik.solver import IKRobot
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.learn.body.components import POSITION, TaskComponents
from gb_pin.learn.body.joints import REVOLUTE
from gb_pin.learn.body.kinematics import Kinematics
from gb_pin.learn.body.task import STACKED, StackedTaskArrays

__all__ = ["as_components", "chain_of", "ik_robot", "resolve"]


def resolve(robot: Kinematics | str) -> Kinematics:
    """The robot itself, or the preset of that name (``"talos_left_arm"``, ``"planar5"``...).

    Raises:
        UnknownRobotError: an unknown preset name (the closest names suggested).
    """
    if isinstance(robot, str):
        from gb_pin.robot.presets import load_robot

        return load_robot(robot)
    return robot


def chain_of(robot: Any) -> KinematicChain:
    """The robot's compiled chain.

    Raises:
        InvalidArgumentError: a robot without one (a function, a simulator, hardware).
    """
    chain = getattr(robot, "chain", None)
    if not isinstance(chain, KinematicChain):
        raise InvalidArgumentError(
            f"IK needs the robot's compiled kinematic chain (a preset name, KinematicTarget, URDF or changed "
            f"body); this {type(robot).__name__} has none (a robot given as a Python function or driven "
            "from outside): seed its own solver with result.inverse(X)"
        )
    return chain


def as_components(chain: KinematicChain) -> TaskComponents:
    """The chain's task as components: its own, or one position component for the paper's task."""
    if chain.components is not None:
        return chain.components
    axes = np.zeros((1, 3), dtype=np.int64)
    axes[0, : chain.n_task] = chain.task_axes
    return TaskComponents(
        kinds=np.array([POSITION], dtype=np.int64),
        parents=np.array([chain.frame_parent], dtype=np.int64),
        translations=chain.frame_translation.reshape(1, 3).astype(np.float64),
        rotations=np.eye(3).reshape(1, 3, 3),
        references=np.eye(3).reshape(1, 3, 3),
        directions=np.zeros((1, 3)),
        axes=axes,
        sizes=np.array([chain.n_task], dtype=np.int64),
        scales=np.ones(1),
    )


def ik_robot(robot: Kinematics, chain: KinematicChain) -> IKRobot:
    """The compiled solver's view of ``robot``: joints, components, weights, limits, restart ranges.

    The rotational rows are weighted by their component's scale s [m/rad], as the learner
    weighs them; restarts draw within the limits (home +/- pi for an unbounded joint).
    """
    comps = as_components(chain)
    arrays = StackedTaskArrays(STACKED, *(getattr(comps, k) for k in TaskComponents.FIELDS))
    weights = np.where(comps.kinds == POSITION, 1.0, comps.scales).astype(np.float64)
    lower = np.ascontiguousarray(robot.lower, dtype=np.float64)
    upper = np.ascontiguousarray(robot.upper, dtype=np.float64)
    home = np.asarray(robot.home, dtype=np.float64)
    sample_lower = np.where(np.isfinite(lower), lower, home - np.pi)
    sample_upper = np.where(np.isfinite(upper), upper, home + np.pi)
    m = chain.n_joints
    revolute = np.zeros(m, dtype=bool)
    revolute[chain.q_index[chain.kinds == REVOLUTE]] = True
    prismatic = np.zeros(m, dtype=bool)
    prismatic[chain.q_index[chain.kinds != REVOLUTE]] = True  # an entry driving both is not periodic
    periodic = (revolute & ~prismatic & ~(upper - lower <= 2 * np.pi)).astype(np.float64)
    return IKRobot(
        chain.joints, arrays, weights, np.empty((m, 3, 3)), np.empty((m, 3)), lower, upper,
        np.ascontiguousarray(sample_lower), np.ascontiguousarray(sample_upper), periodic,
    )  # fmt: skip
