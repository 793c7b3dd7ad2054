"""A hand pose (position + quaternion) as the task vector of a robot's stacked task: a target for IK.

A pose task's x is not a position and a quaternion: it is the position on the task axes [m] and
``s log(R_ref^T R)`` (docs/TASKS.md), with R_ref the frame's orientation at home (or the one given)
and s the orientation scale; a pointing task's is the position and two scaled tangent coordinates
of the axis's direction. :func:`pose_target` computes that vector from what a user has (a position
and a unit quaternion, as ROS, MuJoCo or a camera give it), with the robot's own references, so that
``solve(robot, pose_target(robot, p, quat))`` and ``gb-pin ik run.npz --pose X Y Z QX QY QZ QW``
reach that pose. numpy only: the references are read from the robot's task arrays.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.body.components import ORIENTATION, POINTING, POSITION

ORDERS = ("xyzw", "wxyz")


def quaternion_matrix(quaternion: ArrayLike, order: str = "xyzw") -> NDArray[np.float64]:
    """The rotation matrix (3, 3) of a quaternion, normalised; ``order`` "xyzw" (ROS, scipy) or "wxyz".

    Raises:
        InvalidArgumentError: not 4 finite numbers of nonzero norm, or an unknown order.
    """
    if order not in ORDERS:
        raise InvalidArgumentError(f"order must be one of {ORDERS}, got {order!r}")
    q = np.asarray(quaternion, dtype=float)
    if q.shape != (4,) or not np.all(np.isfinite(q)) or not np.linalg.norm(q) > 1e-9:
        raise InvalidArgumentError(
            f"a quaternion is 4 finite numbers ({', '.join(order)}) of nonzero norm, got {quaternion!r}"
        )
    x, y, z, w = (q if order == "xyzw" else q[[1, 2, 3, 0]]) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def log3(R: NDArray[np.float64]) -> NDArray[np.float64]:
    """The rotation vector (3,) of a rotation matrix: axis times angle in [0, pi] (SO(3)'s log)."""
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    cos = min(max((float(np.trace(R)) - 1.0) / 2.0, -1.0), 1.0)
    theta = math.acos(cos)
    if theta < 1e-5:  # theta / (2 sin theta) = 1/2 + theta^2 / 12 + ...
        return (0.5 + theta * theta / 12.0) * w
    if math.pi - theta < 1e-5:  # the axis from (R + I) / 2 = a a^T, its sign from w
        B = 0.5 * (R + np.eye(3))
        i = int(np.argmax(np.diag(B)))
        a = B[:, i] / math.sqrt(max(B[i, i], 1e-300))
        if a @ w < 0:
            a = -a
        return theta * a / np.linalg.norm(a)
    return theta / (2.0 * math.sin(theta)) * w


def pose_target(
    robot: Any, position: ArrayLike, quaternion: ArrayLike | None = None, order: str = "xyzw"
) -> NDArray[np.float64]:
    """The task vector (n,) of ``robot`` for its frame at ``position`` [m] with orientation ``quaternion``.

    Args:
        robot: a :class:`~gb_pin.robot.target.KinematicTarget` (or a result: its ``target``) whose task
            components all concern one frame: a position (the paper's task), a pose, or a pointing task.
        position: (3,) the frame's world position [m] (only the task's axes are used).
        quaternion: (4,) its world orientation; needed unless the task is a position only.
        order: ``"xyzw"`` (ROS, scipy; default) or ``"wxyz"`` (MuJoCo, Eigen's constructor).

    Raises:
        InvalidArgumentError: bad numbers, no quaternion for an orientation, or a task of several frames.
    """
    target = getattr(robot, "target", robot)
    chain = getattr(target, "chain", None)
    if chain is None:
        raise InvalidArgumentError(f"pose_target needs a KinematicTarget (or a result), got {robot!r}")
    p = np.asarray(position, dtype=float)
    if p.shape != (3,) or not np.all(np.isfinite(p)):
        raise InvalidArgumentError(f"position must be 3 finite numbers [m] (x, y, z), got {position!r}")
    comps = chain.components
    if comps is None:  # the paper's task: the position on the task axes
        return np.ascontiguousarray(p[np.asarray(chain.task_axes)])
    specs = getattr(target, "task", None) or ()
    if len({getattr(s, "frame", None) for s in specs}) > 1:
        raise InvalidArgumentError(
            "pose_target gives one frame's pose; this task has several frames "
            f"({', '.join(target.component_labels)}): build the task vector from each component"
        )
    R = None if quaternion is None else quaternion_matrix(quaternion, order)
    out: list[float] = []
    for k in range(comps.kinds.shape[0]):
        kind = int(comps.kinds[k])
        if kind == POSITION:
            out.extend(p[comps.axes[k, : comps.sizes[k]]])
            continue
        if R is None:
            raise InvalidArgumentError(
                f"the task has an orientation ({target.component_labels[k]}): give a quaternion too"
            )
        if kind == ORIENTATION:
            out.extend(comps.scales[k] * log3(comps.references[k].T @ R))
        elif kind == POINTING:
            d0, u, v = comps.references[k]
            rotvec = _turn(d0, R @ np.asarray(specs[k].axis, dtype=float))
            out.extend(comps.scales[k] * np.array([rotvec @ u, rotvec @ v]))
    return np.array(out)


def _turn(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """The rotation vector of the smallest rotation taking direction ``a`` to ``b`` (as the task map does)."""
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    axis = np.cross(a, b)
    s, c = float(np.linalg.norm(axis)), float(a @ b)
    if s < 1e-15:
        return np.zeros(3)
    return axis / s * math.atan2(s, c)
