"""Compiled forward kinematics of the joints: every joint frame in the world for a posture q.

A kinematic tree is held as plain arrays (:class:`Joints`), read from a ``pin.Model`` on
the robot side (:mod:`gb_pin.robot.chain_reader`), so that the learner can evaluate it
in compiled code without Pinocchio. Joint i's frame is
``oMi = oMparent * placement_i * motion_i(q_i)``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin._jit import njit

REVOLUTE = 0
PRISMATIC = 1


class Joints(NamedTuple):
    """The joints of a kinematic tree as arrays (what :func:`joints_forward` takes).

    Attributes:
        parents: (m,) int64, index of the parent joint, -1 for the world.
        rotations: (m, 3, 3) rotation of each joint placement in its parent.
        translations: (m, 3) translation of each joint placement in its parent [m].
        axes: (m, 3) unit joint axis in the joint frame.
        kinds: (m,) int64, ``REVOLUTE`` (q in [rad]) or ``PRISMATIC`` (q in [m]).
        q_index: (m,) int64, which entry of the posture vector q drives each joint.
    """

    parents: NDArray[np.int64]
    rotations: NDArray[np.float64]
    translations: NDArray[np.float64]
    axes: NDArray[np.float64]
    kinds: NDArray[np.int64]
    q_index: NDArray[np.int64]


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def joints_forward(q, joints, rot_ws, pos_ws):  # type: ignore[no-untyped-def]
    """Each joint's world rotation into ``rot_ws`` (m, 3, 3) and position into ``pos_ws`` (m, 3).

    Joints are numbered so that every joint's parent comes before it.
    """
    parents, rotations, translations, axes, kinds, q_index = joints
    m = q.shape[0]
    for i in range(m):
        p = parents[i]
        # Rp, tp: parent frame in the world (identity for the world itself).
        # B = Rp @ R0_i is the joint frame's rotation before the joint motion.
        b00 = rotations[i, 0, 0]
        b01 = rotations[i, 0, 1]
        b02 = rotations[i, 0, 2]
        b10 = rotations[i, 1, 0]
        b11 = rotations[i, 1, 1]
        b12 = rotations[i, 1, 2]
        b20 = rotations[i, 2, 0]
        b21 = rotations[i, 2, 1]
        b22 = rotations[i, 2, 2]
        t0 = translations[i, 0]
        t1 = translations[i, 1]
        t2 = translations[i, 2]
        if p >= 0:
            r = rot_ws[p]
            c00 = r[0, 0] * b00 + r[0, 1] * b10 + r[0, 2] * b20
            c01 = r[0, 0] * b01 + r[0, 1] * b11 + r[0, 2] * b21
            c02 = r[0, 0] * b02 + r[0, 1] * b12 + r[0, 2] * b22
            c10 = r[1, 0] * b00 + r[1, 1] * b10 + r[1, 2] * b20
            c11 = r[1, 0] * b01 + r[1, 1] * b11 + r[1, 2] * b21
            c12 = r[1, 0] * b02 + r[1, 1] * b12 + r[1, 2] * b22
            c20 = r[2, 0] * b00 + r[2, 1] * b10 + r[2, 2] * b20
            c21 = r[2, 0] * b01 + r[2, 1] * b11 + r[2, 2] * b21
            c22 = r[2, 0] * b02 + r[2, 1] * b12 + r[2, 2] * b22
            px = pos_ws[p, 0] + r[0, 0] * t0 + r[0, 1] * t1 + r[0, 2] * t2
            py = pos_ws[p, 1] + r[1, 0] * t0 + r[1, 1] * t1 + r[1, 2] * t2
            pz = pos_ws[p, 2] + r[2, 0] * t0 + r[2, 1] * t1 + r[2, 2] * t2
            b00, b01, b02 = c00, c01, c02
            b10, b11, b12 = c10, c11, c12
            b20, b21, b22 = c20, c21, c22
        else:
            px, py, pz = t0, t1, t2
        ax = axes[i, 0]
        ay = axes[i, 1]
        az = axes[i, 2]
        if kinds[i] == REVOLUTE:
            # Rodrigues' formula for the joint rotation about the unit axis a.
            s = math.sin(q[q_index[i]])
            c = math.cos(q[q_index[i]])
            v = 1.0 - c
            j00 = c + ax * ax * v
            j01 = ax * ay * v - az * s
            j02 = ax * az * v + ay * s
            j10 = ay * ax * v + az * s
            j11 = c + ay * ay * v
            j12 = ay * az * v - ax * s
            j20 = az * ax * v - ay * s
            j21 = az * ay * v + ax * s
            j22 = c + az * az * v
            rot_ws[i, 0, 0] = b00 * j00 + b01 * j10 + b02 * j20
            rot_ws[i, 0, 1] = b00 * j01 + b01 * j11 + b02 * j21
            rot_ws[i, 0, 2] = b00 * j02 + b01 * j12 + b02 * j22
            rot_ws[i, 1, 0] = b10 * j00 + b11 * j10 + b12 * j20
            rot_ws[i, 1, 1] = b10 * j01 + b11 * j11 + b12 * j21
            rot_ws[i, 1, 2] = b10 * j02 + b11 * j12 + b12 * j22
            rot_ws[i, 2, 0] = b20 * j00 + b21 * j10 + b22 * j20
            rot_ws[i, 2, 1] = b20 * j01 + b21 * j11 + b22 * j21
            rot_ws[i, 2, 2] = b20 * j02 + b21 * j12 + b22 * j22
        else:
            d = q[q_index[i]]
            px += (b00 * ax + b01 * ay + b02 * az) * d
            py += (b10 * ax + b11 * ay + b12 * az) * d
            pz += (b20 * ax + b21 * ay + b22 * az) * d
            rot_ws[i, 0, 0] = b00
            rot_ws[i, 0, 1] = b01
            rot_ws[i, 0, 2] = b02
            rot_ws[i, 1, 0] = b10
            rot_ws[i, 1, 1] = b11
            rot_ws[i, 1, 2] = b12
            rot_ws[i, 2, 0] = b20
            rot_ws[i, 2, 1] = b21
            rot_ws[i, 2, 2] = b22
        pos_ws[i, 0] = px
        pos_ws[i, 1] = py
        pos_ws[i, 2] = pz
