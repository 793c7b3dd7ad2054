"""Compiled forward kinematics of a kinematic tree, read from a Pinocchio model.

The babbling loop runs hundreds of millions of steps and cannot call Pinocchio per
step. :class:`KinematicChain` holds what forward kinematics of one frame needs as
plain arrays (joint parents, joint placements, joint axes and kinds, the frame's
placement), filled from a ``pin.Model`` by :mod:`gb_pin.target`, so that Pinocchio
stays the single source of the robot. :func:`chain_position` evaluates it in
compiled code; it is tested against ``pin.framesForwardKinematics``.

This module imports neither pinocchio nor meshcat: the learner uses it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

from gb_pin.exceptions import InvalidArgumentError

REVOLUTE = 0
PRISMATIC = 1


@dataclass(frozen=True, eq=False)
class KinematicChain:
    """Arrays describing the forward kinematics of one frame.

    Joints are numbered 0..m-1 so that every joint's parent comes before it;
    ``q_index`` maps them to entries of the learner's posture vector q. Joint i's frame is
    ``oMi = oMparent * placement_i * motion_i(q_i)``.

    Attributes:
        parents: (m,) int64, index of the parent joint, -1 for the world.
        rotations: (m, 3, 3) rotation of each joint placement in its parent.
        translations: (m, 3) translation of each joint placement in its parent [m].
        axes: (m, 3) unit joint axis in the joint frame.
        kinds: (m,) int64, ``REVOLUTE`` (q in [rad]) or ``PRISMATIC`` (q in [m]).
        q_index: (m,) int64, which entry of the posture vector q drives each joint.
        frame_parent: index of the joint carrying the operational frame, -1 for the world.
        frame_translation: (3,) position of the frame in its parent joint [m].
        task_axes: (n,) int64, which world coordinates (0=x, 1=y, 2=z) the learner sees.
    """

    parents: NDArray[np.int64]
    rotations: NDArray[np.float64]
    translations: NDArray[np.float64]
    axes: NDArray[np.float64]
    kinds: NDArray[np.int64]
    q_index: NDArray[np.int64]
    frame_parent: int
    frame_translation: NDArray[np.float64]
    task_axes: NDArray[np.int64]

    @property
    def n_joints(self) -> int:
        """Number of joints m (the posture dimension)."""
        return int(self.parents.shape[0])

    @property
    def n_task(self) -> int:
        """Task dimension n."""
        return int(self.task_axes.shape[0])

    def as_tuple(self) -> tuple[object, ...]:
        """The arrays in the order the compiled kernels take them."""
        return (
            self.parents,
            self.rotations,
            self.translations,
            self.axes,
            self.kinds,
            self.q_index,
            np.int64(self.frame_parent),
            self.frame_translation,
            self.task_axes,
        )

    def workspace(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Scratch buffers (joint rotations, joint positions) for :func:`chain_position`."""
        m = self.n_joints
        return np.empty((m, 3, 3)), np.empty((m, 3))

    def forward(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """Task-space position of the frame for one posture ``q`` of shape (m,)."""
        q = np.ascontiguousarray(q, dtype=np.float64)
        if q.shape != (self.n_joints,):
            raise InvalidArgumentError(f"q must have shape ({self.n_joints},), got shape {q.shape}")
        out = np.empty(self.n_task)
        rot_ws, pos_ws = self.workspace()
        chain_position(q, self.as_tuple(), rot_ws, pos_ws, out)
        return out


@njit(cache=True, nogil=True, error_model="numpy")
def chain_position(q, chain, rot_ws, pos_ws, out):  # type: ignore[no-untyped-def]
    """Write the frame's task-space position for posture ``q`` into ``out``.

    Args:
        q: (m,) posture.
        chain: :meth:`KinematicChain.as_tuple`.
        rot_ws: (m, 3, 3) scratch, receives each joint's world rotation.
        pos_ws: (m, 3) scratch, receives each joint's world position.
        out: (n,) output.
    """
    (
        parents,
        rotations,
        translations,
        axes,
        kinds,
        q_index,
        frame_parent,
        frame_translation,
        task_axes,
    ) = chain
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
    f = frame_parent
    if f >= 0:
        r = rot_ws[f]
        for a in range(task_axes.shape[0]):
            k = task_axes[a]
            out[a] = (
                pos_ws[f, k]
                + r[k, 0] * frame_translation[0]
                + r[k, 1] * frame_translation[1]
                + r[k, 2] * frame_translation[2]
            )
    else:
        for a in range(task_axes.shape[0]):
            out[a] = frame_translation[task_axes[a]]
