"""Which joints the learner moves, and locking the others: the reduced Pinocchio model.

A :class:`~gb_pin.robot.target.KinematicTarget` moves only the joints it names; every
other joint (a floating base included) is locked at the reference posture with
``pinocchio.buildReducedModel``. :func:`select_joints` checks the names,
:func:`lock_joints` builds the reduced model and :func:`find_frame` looks the
operational frame up in it. Every error names the bad value and the closest valid names.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from gb_pin._names import suggest
from gb_pin.exceptions import InvalidArgumentError, UnknownRobotError
from gb_pin.robot.chain_reader import joint_kind

if TYPE_CHECKING:
    import pinocchio as pin


def joint_names(model: pin.Model) -> list[str]:
    """The names of the model's joints, the universe left out."""
    return list(model.names)[1:]


def select_joints(
    model: pin.Model, joints: Sequence[str] | None, name: str, frame: str | None = None
) -> list[str]:
    """The joints the learner moves: ``joints`` checked, or every joint of the model for None.

    Args:
        model: the full model.
        joints: joint names in the order of q, or None for all (then the model must
            have no free floating base, which would stay unlocked).
        name: the robot's label, for messages.
        frame: the operational frame, whose joints an error suggests.

    Raises:
        UnknownRobotError: an unknown joint name (the closest names listed).
        InvalidArgumentError: not a sequence of distinct names, none, a joint the
            learner cannot move, or None with a floating base.
    """
    full_names = joint_names(model)
    if joints is None:
        floating = [
            n for n in full_names if model.joints[model.getJointId(n)].shortname() == "JointModelFreeFlyer"
        ]
        if floating:
            raise InvalidArgumentError(
                f"model {name!r} has a free floating base {floating[0]!r}, which moving every joint "
                "would leave unlocked: name the joints the learner moves (the base is then locked at "
                f"the reference posture){_frame_joints(model, frame, name)}, or let gb_pin choose them "
                "(onboard=True; the default of from_urdf, from_example_robot_data and the command line)"
            )
        joints = full_names
    if isinstance(joints, str) or not all(isinstance(j, str) for j in joints):
        raise InvalidArgumentError(f"joints must be a sequence of joint names, got {joints!r}")
    joints = list(joints)
    if not joints:
        raise InvalidArgumentError("joints must name at least one joint, got []")
    if len(set(joints)) != len(joints):
        raise InvalidArgumentError(f"joints must not repeat a name, got {joints!r}")
    for j in joints:
        if j not in full_names:
            raise UnknownRobotError(f"unknown joint {j!r} in model {name!r}; {suggest(j, full_names)}")
    for j in joints:  # a clear error before buildReducedModel sees an odd joint
        joint_kind(model.joints[model.getJointId(j)], j)
    return joints


def _frame_joints(model: pin.Model, frame: str | None, name: str) -> str:
    """``, e.g. the 7 that move 'hand': a, b, ...`` (the joints on the frame's path), or ``""``."""
    from gb_pin.robot.onboarding import path_joints

    if frame is None or not isinstance(frame, str) or not model.existFrame(frame):
        return ""
    try:
        path = path_joints(model, int(model.getFrameId(frame)), name)
    except InvalidArgumentError:
        return ""
    return f", e.g. the {len(path)} that move {frame!r}: {', '.join(path)}"


def lock_joints(
    model: pin.Model, joints: Sequence[str], reference: NDArray[np.float64], name: str
) -> pin.Model:
    """A copy of ``model`` with every joint but ``joints`` locked at ``reference``.

    Args:
        model: the full model (not modified).
        joints: the joints kept (see :func:`select_joints`).
        reference: the full model's configuration the locked joints keep.
        name: the robot's label, for messages.

    Raises:
        InvalidArgumentError: ``pinocchio.buildReducedModel`` failed.
    """
    import pinocchio as pin

    kept = set(joints)
    locked_names = [n for n in joint_names(model) if n not in kept]
    if not locked_names:
        return pin.Model(model)
    # buildReducedModel needs a JOINT frame on every joint; hand-built models may lack them.
    source = pin.Model(model)
    framed = {f.parentJoint for f in source.frames if f.type == pin.FrameType.JOINT}
    for jid in range(1, source.njoints):
        if jid not in framed:
            source.addJointFrame(jid)
    # buildReducedModel looks a locked joint's frame up by name alone: a link named like a joint
    # (SO-100's "gripper") makes that ambiguous. Such frames are renamed for the call, then back.
    renamed = _rename_clashing_frames(source)
    try:
        reduced = pin.buildReducedModel(source, [model.getJointId(n) for n in locked_names], reference)
    except (ValueError, RuntimeError) as exc:
        raise InvalidArgumentError(
            f"cannot lock joints {locked_names} of {name!r}: "
            f"pinocchio.buildReducedModel failed ({exc}); give every joint its frame "
            "(Model.addJointFrame) before adding other frames"
        ) from exc
    for i, frame in enumerate(reduced.frames):
        if frame.name in renamed:
            frame.name = renamed[frame.name]
            reduced.frames[i] = frame
    return reduced


def _rename_clashing_frames(model: pin.Model) -> dict[str, str]:
    """Give every non-joint frame named like a joint a unique name (in place); {new name: old name}."""
    import pinocchio as pin

    joint_frame = pin.FrameType.JOINT
    names = set(joint_names(model))
    taken = {f.name for f in model.frames}
    renamed: dict[str, str] = {}
    for i, frame in enumerate(model.frames):
        if frame.name in names and frame.type != joint_frame:
            new = f"{frame.name}#gb_pin{i}"
            while new in taken:
                new += "_"
            renamed[new] = frame.name
            frame.name = new
            model.frames[i] = frame
    return renamed


def find_frame(model: pin.Model, frame: str, name: str) -> int:
    """The id of the operational frame ``frame`` in ``model``.

    Where several frames have that name (a URDF may name a link and a joint alike), the link's
    frame is taken: a BODY frame first, then an operational frame, then a joint's.

    Raises:
        UnknownRobotError: no such frame (the closest names listed).
    """
    if not isinstance(frame, str) or not model.existFrame(frame):
        frame_names = [f.name for f in model.frames]
        raise UnknownRobotError(
            f"unknown frame {frame!r} in model {name!r}; {suggest(str(frame), frame_names)}"
        )
    import pinocchio as pin

    order = [pin.FrameType.BODY, pin.FrameType.OP_FRAME, pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT]
    matches = [i for i, f in enumerate(model.frames) if f.name == frame]
    matches.sort(key=lambda i: order.index(model.frames[i].type) if model.frames[i].type in order else 9)
    return int(matches[0])
