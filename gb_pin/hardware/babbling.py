"""Goal babbling on a real arm: the ask/tell loop between a session, a :class:`FeetechArm` and a tracker.

Each ask goes to the arm (:meth:`FeetechArm.move`: sent, settled, read back), the tracker reads the
hand once the arm is at rest, and the session learns from the posture the encoders read
(``tell(x, executed=q)``). The arm's limits and step limit are the session's. A checkpoint is
written as the session says and on Ctrl-C (an unanswered ask is asked again after a resume).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

import numpy as np

from gb_pin.hardware.arm import FeetechArm

Tracker = Callable[[], Any]


def arm_robot(arm: FeetechArm) -> Any:
    """The :class:`~gb_pin.robot.external.ExternalRobot` of the arm's preset, within the arm's limits."""
    from gb_pin.robot.external import ExternalRobot

    preset = ExternalRobot.from_preset(arm.kind.robot)
    robot = ExternalRobot(
        arm.home, preset.n_task, preset.targets, lower=arm.lower, upper=arm.upper, name=preset.name
    )
    robot.preset = arm.kind.robot
    return robot


def babble_on_arm(
    arm: FeetechArm,
    tracker: Tracker,
    *,
    movements: int = 3000,
    seed: int = 0,
    checkpoint: str | os.PathLike[str] | None = None,
    resume: bool = False,
    checkpoint_every: int | None = None,
    callback: Callable[[int], None] | None = None,
    evaluate: str = "none",
) -> Any:
    """Learn the arm's inverse kinematics by goal babbling; returns the session's :class:`BabbleResult`.

    Args:
        arm: the arm (its ``max_joint_step`` limits the session's asks).
        tracker: ``tracker()`` -> the hand's position (3,) [m] now, or None when it lost the hand.
        movements: movements to learn (a resumed run keeps its own).
        seed: the run's seed.
        checkpoint: the file to checkpoint to (and, with ``resume``, to continue from).
        resume: continue the run of ``checkpoint``.
        checkpoint_every: movements between checkpoints (default a tenth of the run).
        callback: called with the movement count after each completed movement.
        evaluate: ``"none"`` or ``"movements"`` (E^X from evaluation movements on the arm).

    Raises:
        KeyboardInterrupt: after the checkpoint was written (the arm stops as its ``on_stop`` says).
    """
    from gb_pin.runs.session import babble_session, resume_session

    robot = arm_robot(arm)
    if resume:
        if checkpoint is None:
            raise ValueError("resume needs the checkpoint file")
        session = resume_session(checkpoint, robot=robot, checkpoint_every=checkpoint_every)
    else:
        session = babble_session(
            robot, movements=movements, seed=seed, evaluate=evaluate, max_joint_step=arm.max_joint_step,
            checkpoint=checkpoint, checkpoint_every=checkpoint_every,
        )  # fmt: skip
    start = arm.home if session.state is None else session.state.vectors["q_exec"]
    arm.move_to(np.asarray(start, dtype=float))  # from wherever the arm rests, in steps
    try:
        while not session.done:
            q = session.ask()
            executed = arm.move(q)
            x = tracker()
            if session.tell(x, executed=executed) and callback is not None:
                callback(session.movements)
    except BaseException:
        if checkpoint is not None and session.state is not None:
            session.save_checkpoint()  # an unanswered ask is asked again after a resume
        session.close()
        raise
    result = session.result()
    session.close()
    return result
