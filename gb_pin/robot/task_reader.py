"""Reading task components (positions, orientations, pointing axes of frames) from a ``pin.Model``.

:func:`stack_task` turns the specs of :mod:`gb_pin.robot.task_spec` into the arrays of
:class:`~gb_pin.learn.body.components.TaskComponents` on a chain read by
:func:`~gb_pin.robot.chain_reader.read_chain`: each frame's parent joint and placement,
and the default references (the frame's rotation, or its pointing axis, at home), computed
by the chain's own compiled kinematics so that x = 0 on the rotational rows at home.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.learn.body.components import ORIENTATION, POINTING, POSITION, TaskComponents
from gb_pin.learn.body.joints import joints_forward
from gb_pin.robot.chain_reader import AXIS_INDEX
from gb_pin.robot.reduction import find_frame
from gb_pin.robot.task_spec import Orientation, Pointing, Position, TaskComponentSpec


def tangent_basis(d0: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """An orthonormal basis (u, v) of the plane normal to the unit vector d0, with u x v = d0.

    u is the world axis least aligned with d0, made orthogonal to it (a fixed rule, so the
    same reference always gives the same chart).
    """
    e = np.zeros(3)
    e[int(np.argmin(np.abs(d0)))] = 1.0
    u = e - float(e @ d0) * d0
    u /= np.linalg.norm(u)
    return u, np.cross(d0, u)


def _frames_at(
    chain: KinematicChain, q: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    m = chain.n_joints
    rot, pos = np.empty((m, 3, 3)), np.empty((m, 3))
    joints_forward(np.ascontiguousarray(q, dtype=float), chain.joints, rot, pos)
    return rot, pos


def stack_task(
    chain: KinematicChain,
    model: pin.Model,
    specs: Sequence[TaskComponentSpec],
    home: NDArray[np.float64],
    name: str,
) -> KinematicChain:
    """``chain`` with the stacked task map of ``specs`` (references at the ``home`` posture).

    Args:
        chain: the chain of ``model`` (read by :func:`~gb_pin.robot.chain_reader.read_chain`).
        model: the reduced model.
        specs: the task components, frames resolved.
        home: the home posture (m,).
        name: the robot's label, for messages.

    Raises:
        UnknownRobotError: an unknown frame (the closest names listed).
        InvalidArgumentError: a frame that the moved joints do not move.
    """
    order = list(range(1, model.njoints))  # the reduced model holds only the moved joints
    index = {jid: i for i, jid in enumerate(order)}
    rot_home, _ = _frames_at(chain, home)
    c = len(specs)
    arrays = dataclasses.asdict(TaskComponents.empty())
    fields = {k: np.zeros((c, *np.shape(v)[1:]), dtype=np.asarray(v).dtype) for k, v in arrays.items()}
    for k, spec in enumerate(specs):
        assert spec.frame is not None
        frame = model.frames[find_frame(model, spec.frame, name)]
        parent = index.get(int(frame.parentJoint), -1)
        if parent < 0:
            moved = [model.names[j] for j in order]
            raise InvalidArgumentError(
                f"task frame {spec.frame!r} of {name!r} is not moved by the joints the learner moves "
                f"({', '.join(moved)}): choose a frame on the moved chain"
            )
        placement = frame.placement
        fields["parents"][k] = parent
        fields["translations"][k] = placement.translation
        fields["rotations"][k] = placement.rotation
        fields["scales"][k] = 1.0
        world_home = rot_home[parent] @ placement.rotation
        if isinstance(spec, Position):
            fields["kinds"][k] = POSITION
            fields["sizes"][k] = len(spec.axes)
            fields["axes"][k, : len(spec.axes)] = [AXIS_INDEX[a] for a in spec.axes]
        elif isinstance(spec, Orientation):
            fields["kinds"][k] = ORIENTATION
            fields["sizes"][k] = 3
            fields["scales"][k] = spec.scale
            fields["references"][k] = world_home if spec.reference is None else spec.reference
        elif isinstance(spec, Pointing):
            fields["kinds"][k] = POINTING
            fields["sizes"][k] = 2
            fields["scales"][k] = spec.scale
            fields["directions"][k] = placement.rotation @ spec.axis
            d0 = world_home @ spec.axis if spec.reference is None else spec.reference
            d0 = d0 / np.linalg.norm(d0)
            fields["references"][k] = np.vstack([d0, *tangent_basis(d0)])
    components = TaskComponents(**{k: np.ascontiguousarray(v) for k, v in fields.items()})
    stacked = dataclasses.replace(chain, components=components)
    stacked.validate()
    return stacked


def pinocchio_task_vector(
    model: pin.Model, data: pin.Data, chain: KinematicChain, specs: Sequence[TaskComponentSpec]
) -> NDArray[np.float64]:
    """The stacked task vector from Pinocchio's frames (``data`` after ``framesForwardKinematics``).

    The references are the chain's (``chain.components``); this is the independent check of
    the compiled :func:`~gb_pin.learn.body.components.components_forward`.
    """
    comps = chain.components
    assert comps is not None
    out = []
    for k, spec in enumerate(specs):
        oMf = data.oMf[find_frame(model, str(spec.frame), "the model")]  # the specs are resolved
        if isinstance(spec, Position):
            out.extend(oMf.translation[[AXIS_INDEX[a] for a in spec.axes]])
        elif isinstance(spec, Orientation):
            out.extend(spec.scale * pin.log3(comps.references[k].T @ oMf.rotation))
        else:
            d0, u, v = comps.references[k]
            d = oMf.rotation @ spec.axis
            rotvec = pin.log3(_rotation_between(d0, d))
            out.extend(spec.scale * np.array([rotvec @ u, rotvec @ v]))
    return np.array(out)


def _rotation_between(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """The smallest rotation taking unit vector a to unit vector b (for checks; not antipodal)."""
    axis = np.cross(a, b)
    s, c = float(np.linalg.norm(axis)), float(a @ b)
    if s < 1e-15:
        return np.eye(3)
    return np.asarray(pin.exp3(axis / s * np.arctan2(s, c)))
