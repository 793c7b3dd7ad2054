"""Closed-form forward kinematics of chains whose joints all turn about one direction (planar chains).

When every joint between the world and the frame is revolute and their axes are parallel in
the world (the paper's planar arms, and any URDF chain built that way), the joint rotations
commute: joint i's world rotation is a rotation by theta_i = s_1 q_1 + ... + s_i q_i (s = +-1,
the sense of each axis) about the common axis a, applied to its rotation at q = 0. Writing
c_i for the vector from joint i to the next joint (or to the frame) at q = 0, split into its
part along a and the rest, the frame's position is

    x = x_0 + sum_i (cos theta_i u_i + sin theta_i v_i),    u_i = c_i - (a . c_i) a,  v_i = a x c_i,

with x_0 the root joint's position plus every part along a (constant). :func:`parallel_axes`
detects such a chain from its arrays (never from a robot's name) and precomputes x_0, u_i and
v_i on the task axes; :func:`planar_forward` evaluates the sum with one sine and cosine per
joint, keeping (cos theta_i, sin theta_i) by the angle-addition formulas. On the planar presets
(identity placements, z axes) these are the very operations the general kernel
(:func:`~gb_pin.learn.body.joints.joints_forward`) performs once its products with 0 and 1 are
dropped, so both give the same numbers bit for bit (tests/test_chain.py).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin._jit import njit
from gb_pin.learn.body.joints import REVOLUTE
from gb_pin.learn.body.task import TaskArrays

if TYPE_CHECKING:
    from gb_pin.learn.body.chain import KinematicChain

#: Axes count as parallel when |a_i x a| <= this (their closed form then agrees with the general
#: kernel to about this relative size, far below what a posture's rounding moves the frame).
PARALLEL_TOLERANCE = 1e-12


class PlanarBody(NamedTuple):
    """A chain about parallel axes in closed form, as :func:`~gb_pin.learn.body.chain.body_forward` takes it.

    Attributes:
        task: the frame-position task map (what the chain's general form carries).
        joints: (p,) int64, the entry of q driving each joint from the world to the frame.
        signs: (p,) +1.0 or -1.0: joint i turns by ``signs[i] * q[joints[i]]`` about the common axis.
        base: (n,) the frame's position on the task axes that no joint changes [m].
        radial: (p, n) u_i on the task axes [m].
        tangential: (p, n) v_i on the task axes [m].
    """

    task: TaskArrays
    joints: NDArray[np.int64]
    signs: NDArray[np.float64]
    base: NDArray[np.float64]
    radial: NDArray[np.float64]
    tangential: NDArray[np.float64]


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def planar_forward(q, body, out):  # type: ignore[no-untyped-def]
    """x = f(q) into ``out`` (n,) for a :class:`PlanarBody` (Eq. 1, in closed form)."""
    joints, signs, base, radial, tangential = body.joints, body.signs, body.base, body.radial, body.tangential
    n = out.shape[0]
    for a in range(n):
        out[a] = base[a]
    C = 1.0
    S = 0.0
    for i in range(joints.shape[0]):
        t = signs[i] * q[joints[i]]
        c = math.cos(t)
        s = math.sin(t)
        C, S = C * c - S * s, S * c + C * s
        for a in range(n):
            out[a] += C * radial[i, a] + S * tangential[i, a]


def parallel_axes(chain: KinematicChain) -> PlanarBody | None:
    """The closed form of ``chain``'s frame position, or None if its joints are not all parallel revolute.

    The chain qualifies when its task is a frame's position and every joint on the path from the
    world to the frame is revolute with its axis parallel (either sense) to the first one's at
    q = 0 (then at every q: rotations about one axis leave it fixed). Joints off that path do not
    move the frame and are ignored.
    """
    if chain.components is not None or chain.frame_parent < 0:
        return None
    path = []
    i = chain.frame_parent
    while i >= 0:
        path.append(i)
        i = int(chain.parents[i])
    path.reverse()
    if any(chain.kinds[i] != REVOLUTE for i in path):
        return None
    # World rotations at q = 0 (each joint's own motion is then the identity).
    rot = {-1: np.eye(3)}
    for i in path:
        rot[i] = rot[int(chain.parents[i])] @ chain.rotations[i]
    axes = [rot[i] @ chain.axes[i] for i in path]
    a = axes[0] / np.linalg.norm(axes[0])
    if any(np.linalg.norm(np.cross(w, a)) > PARALLEL_TOLERANCE for w in axes):
        return None
    signs = np.array([1.0 if float(w @ a) > 0.0 else -1.0 for w in axes])
    links = [rot[path[k]] @ chain.translations[path[k + 1]] for k in range(len(path) - 1)]
    links.append(rot[path[-1]] @ chain.frame_translation)
    along = [float(a @ c) * a for c in links]
    base = chain.translations[path[0]] + np.sum(along, axis=0)
    radial = np.array([c - p for c, p in zip(links, along, strict=True)])
    tangential = np.array([np.cross(a, c) for c in links])
    ax = chain.task_axes
    return PlanarBody(
        task=chain.task.arrays(),  # type: ignore[arg-type]
        joints=np.ascontiguousarray(chain.q_index[path], dtype=np.int64),
        signs=signs,
        base=np.ascontiguousarray(base[ax]),
        radial=np.ascontiguousarray(radial[:, ax]),
        tangential=np.ascontiguousarray(tangential[:, ax]),
    )
