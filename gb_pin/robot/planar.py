"""Procedural planar chains of the paper (Sec. III): ``planar_chain(m)`` and its home posture."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from gb_pin import _validation as check


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
    m = check.positive_int("m", m)
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


def planar_home(m: int) -> NDArray[np.float64]:
    """The paper's home posture: q_1 = -pi/3, q_i = 2 pi / (3 (m - 1)) for i > 1 [rad]."""
    home = np.full(m, 2.0 * math.pi / (3.0 * (m - 1)) if m > 1 else 0.0)
    home[0] = -math.pi / 3.0
    return home
