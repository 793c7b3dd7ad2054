"""Procedural planar chains of the paper (Sec. III): ``planar_chain(m)``, its home posture, its target.

:func:`planar_chain` builds the chain as a ``pin.Model``; :func:`planar_target` builds the
:class:`~gb_pin.robot.target.KinematicTarget` of a preset from the same geometry written
directly as the learner's arrays (:func:`planar_kinematics`), and builds the ``pin.Model``
only when something asks for it (a viewer, a check against Pinocchio). A planar run then never
imports pinocchio; tests hold the arrays equal, bit for bit, to the ones read from the model.
"""

from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.learn.body.chain import REVOLUTE, KinematicChain
from gb_pin.robot.chain_reader import AXIS_INDEX, JointTable, parse_axes
from gb_pin.robot.target import KinematicTarget
from gb_pin.robot.targets_auto import TargetSpec

MAX_CHAIN_JOINTS = 10**4
"""The most joints of a planar chain built in Python (the presets ``planarN`` stop at 500)."""

if TYPE_CHECKING:
    import pinocchio as pin


def planar_chain(m: int, total_length: float = 1.0) -> pin.Model:
    """A planar chain of ``m`` revolute z-joints and ``m`` equal segments (paper, Sec. III).

    Joint 1 sits at the world origin; joint i+1 sits at the end of segment i; the
    operational frame ``"tip"`` sits at the end of the last segment. Each segment
    carries a thin-rod inertia (mass 1 kg) so that the model is a valid dynamic
    model too.

    Args:
        m: number of joints (>= 1).
        total_length: length of the whole arm [m].

    Returns:
        The Pinocchio model, joints named ``joint1`` .. ``joint{m}``.
    """
    import pinocchio as pin

    m = check.positive_int("m", m, maximum=MAX_CHAIN_JOINTS)
    total_length = check.positive_float("total_length", total_length)
    segment = total_length / m
    model = pin.Model()
    model.name = f"planar{m}"
    parent = 0
    offset = pin.SE3.Identity()
    rod = pin.Inertia.FromCylinder(1.0, 0.01 * segment, segment)
    # FromCylinder is about the z-axis; the rod lies along x from the joint.
    rod_inertia = pin.Inertia(
        1.0,
        np.array([segment / 2.0, 0.0, 0.0]),
        np.diag([rod.inertia[2, 2], rod.inertia[0, 0], rod.inertia[0, 0]]),
    )
    for i in range(m):
        parent = model.addJoint(parent, pin.JointModelRZ(), offset, f"joint{i + 1}")
        model.appendBodyToJoint(parent, rod_inertia, pin.SE3.Identity())
        model.addFrame(pin.Frame(f"joint{i + 1}", parent, 0, pin.SE3.Identity(), pin.FrameType.JOINT))
        offset = pin.SE3(np.eye(3), np.array([segment, 0.0, 0.0]))
    model.addFrame(pin.Frame("tip", parent, 0, offset, pin.FrameType.OP_FRAME))
    return model


def planar_kinematics(m: int, total_length: float = 1.0, axes: str = "xy") -> KinematicChain:
    """The learner's chain of :func:`planar_chain` ``(m, total_length)``, written as arrays.

    Joint i+1 is placed at (total_length / m, 0, 0) in joint i's frame, without rotation (joint 1
    at the origin); every axis is z; the tip is one segment beyond the last joint. These are
    the arrays :func:`~gb_pin.robot.chain_reader.read_chain` reads from the model.
    """
    m = check.positive_int("m", m, maximum=MAX_CHAIN_JOINTS)
    total_length = check.positive_float("total_length", total_length)
    segment = total_length / m
    translations = np.zeros((m, 3))
    translations[1:, 0] = segment
    axes = parse_axes(axes)
    return KinematicChain(
        parents=np.arange(-1, m - 1, dtype=np.int64),
        rotations=np.tile(np.eye(3), (m, 1, 1)),
        translations=translations,
        axes=np.tile(np.array([0.0, 0.0, 1.0]), (m, 1)),
        kinds=np.full(m, REVOLUTE, dtype=np.int64),
        q_index=np.arange(m, dtype=np.int64),
        frame_parent=m - 1,
        frame_translation=np.array([segment, 0.0, 0.0]),
        task_axes=np.array([AXIS_INDEX[c] for c in axes], dtype=np.int64),
    )


def planar_home(m: int) -> NDArray[np.float64]:
    """The paper's home posture: q_1 = -pi/3, q_i = 2 pi / (3 (m - 1)) for i > 1 [rad]."""
    m = check.positive_int("m", m, maximum=MAX_CHAIN_JOINTS)
    home = np.full(m, 2.0 * math.pi / (3.0 * (m - 1)) if m > 1 else 0.0)
    home[0] = -math.pi / 3.0
    return home


def planar_target(
    m: int,
    total_length: float = 1.0,
    *,
    axes: str = "xy",
    targets: TargetSpec = None,
    name: str | None = None,
) -> KinematicTarget:
    """The :class:`KinematicTarget` of :func:`planar_chain` ``(m, total_length)``, frame ``"tip"``.

    The same target as ``KinematicTarget(planar_chain(m, total_length), "tip", home=planar_home(m),
    axes=axes, targets=targets)``, without importing pinocchio until its model is asked for.

    Args:
        m: number of joints (>= 1).
        total_length: length of the whole arm [m].
        axes: the task axes (``"xy"``, the paper's plane).
        targets: the default target set (see :class:`KinematicTarget`).
        name: a label; default ``planar{m}``.
    """
    chain = planar_kinematics(m, total_length, axes)  # checks m, total_length and axes
    m = chain.axes.shape[0]
    # Joint i + 1 of the model is entry i of q, every joint revolute (and bounded) about z.
    table = JointTable(
        order=tuple(range(1, m + 1)), kinds=(REVOLUTE,) * m, continuous=(False,) * m, axes=chain.axes.copy()
    )
    return KinematicTarget._from_arrays(
        name=name if name is not None else f"planar{m}",
        frame="tip",
        joints=[f"joint{i + 1}" for i in range(m)],
        chain=chain,
        table=table,
        limits=(np.full(m, -np.inf), np.full(m, np.inf)),
        home=planar_home(m),
        axes=axes,
        model_source=functools.partial(planar_chain, m, total_length),
        targets=targets,
    )
