"""Compiled Jacobian of the task map: dx/dq from the joint frames, no Pinocchio call.

For the frame-position task map (:class:`~gb_pin.learn.body.task.FramePosition`) the
column of joint i is, with a_i its unit axis in the world and p_i its origin,

    revolute:   a_i x (p_frame - p_i)      [m/rad]
    prismatic:  a_i                         [m/m]

restricted to the task axes, for every joint on the path from the frame to the world
(the others do not move the frame). Columns are summed into ``q_index[i]``, so joints
driven by one posture entry add up. The axis a_i = R_i axes_i is the same before and after
the joint's own motion (a rotation leaves its axis fixed). Tested against finite
differences and ``pinocchio.computeFrameJacobian`` (LOCAL_WORLD_ALIGNED) in tests/test_ik.py.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin._jit import njit
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.learn.body.joints import REVOLUTE, joints_forward
from gb_pin.learn.body.task import FRAME_POSITION, task_forward

__all__ = ["body_jacobian", "frame_jacobian", "frames_jacobian"]


@njit(cache=True, nogil=True, error_model="numpy")
def frames_jacobian(body, J):  # type: ignore[no-untyped-def]
    """dx/dq (n, m) into ``J`` from the joint frames in ``body.rot_ws`` / ``body.pos_ws``.

    The frames must be those of :func:`~gb_pin.learn.body.joints.joints_forward` at the
    posture of interest. Only the frame-position task map is handled (``task.kind ==
    FRAME_POSITION``; the Python side checks it).
    """
    joints, task, rot, pos = body
    parents, axes, kinds, q_index = joints.parents, joints.axes, joints.kinds, joints.q_index
    n, m = J.shape
    for a in range(n):
        for c in range(m):
            J[a, c] = 0.0
    f = task.frame_parent
    if task.kind != FRAME_POSITION or f < 0:
        return  # a frame fixed in the world does not move
    t = task.frame_translation
    # the frame's world position
    p0 = pos[f, 0] + rot[f, 0, 0] * t[0] + rot[f, 0, 1] * t[1] + rot[f, 0, 2] * t[2]
    p1 = pos[f, 1] + rot[f, 1, 0] * t[0] + rot[f, 1, 1] * t[1] + rot[f, 1, 2] * t[2]
    p2 = pos[f, 2] + rot[f, 2, 0] * t[0] + rot[f, 2, 1] * t[1] + rot[f, 2, 2] * t[2]
    i = f
    while i >= 0:
        r = rot[i]
        w0 = r[0, 0] * axes[i, 0] + r[0, 1] * axes[i, 1] + r[0, 2] * axes[i, 2]
        w1 = r[1, 0] * axes[i, 0] + r[1, 1] * axes[i, 1] + r[1, 2] * axes[i, 2]
        w2 = r[2, 0] * axes[i, 0] + r[2, 1] * axes[i, 1] + r[2, 2] * axes[i, 2]
        if kinds[i] == REVOLUTE:
            d0 = p0 - pos[i, 0]
            d1 = p1 - pos[i, 1]
            d2 = p2 - pos[i, 2]
            c0 = w1 * d2 - w2 * d1
            c1 = w2 * d0 - w0 * d2
            c2 = w0 * d1 - w1 * d0
        else:
            c0, c1, c2 = w0, w1, w2
        col = q_index[i]
        for a in range(n):
            k = task.axes[a]
            J[a, col] += c0 if k == 0 else (c1 if k == 1 else c2)
        i = parents[i]


@njit(cache=True, nogil=True, error_model="numpy")
def body_jacobian(q, body, x, J):  # type: ignore[no-untyped-def]
    """x = f(q) into ``x`` (n,) and dx/dq into ``J`` (n, m) for one posture ``q`` (m,)."""
    joints_forward(q, body.joints, body.rot_ws, body.pos_ws)
    task_forward(body.task, body.rot_ws, body.pos_ws, x)
    frames_jacobian(body, J)


def check_task_map(chain: KinematicChain) -> None:
    """Raise unless the chain's task map is one the Jacobian handles (a frame's position).

    Raises:
        InvalidArgumentError: another kind of task map.
    """
    kind = chain.task.arrays().kind
    if kind != FRAME_POSITION:
        raise InvalidArgumentError(f"the IK solver handles the frame-position task map only, got kind {kind}")


def frame_jacobian(chain: KinematicChain, q: ArrayLike) -> NDArray[np.float64]:
    """The task Jacobian dx/dq at one posture.

    Args:
        chain: the learner's kinematic chain (``KinematicTarget.chain``).
        q: posture (m,) [rad] or [m] for prismatic joints.

    Returns:
        (n, m) Jacobian [m/rad] (revolute columns) or [m/m] (prismatic columns).

    Raises:
        InvalidArgumentError: ``q`` of the wrong shape or not finite; an unsupported task map.
    """
    check_task_map(chain)
    qv = check.vector("q", q, chain.n_joints)
    J = np.empty((chain.n_task, chain.n_joints))
    body_jacobian(qv, chain.kernel(), np.empty(chain.n_task), J)
    return J
