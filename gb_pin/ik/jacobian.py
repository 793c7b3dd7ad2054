"""Compiled Jacobian of the task vector: dx/dq of every task map, from the joint frames, no Pinocchio call.

With a_i the unit axis of joint i in the world and p_i its origin, the column of joint i is,
per component (:mod:`gb_pin.learn.body.components`), for revolute joints:

    position p (on its axes):            a_i x (p - p_i)                          [m/rad]
    orientation x = s phi, phi = log(R_ref^T R):
                                         s Jr^-1(phi) R^T a_i                     [m/rad]
        Jr^-1(phi) = I + [phi]/2 + (1/theta^2 - (1 + cos theta) / (2 theta sin theta)) [phi]^2
        (the inverse right Jacobian of SO(3): log(E exp(delta)) = phi + Jr^-1(phi) delta)
    pointing x = s g (u . c, v . c), c = d0 x d, g = theta / |c|, d = R a:
                                         s (g' (u . c, v . c) + g (u . c', v . c')),
        d' = a_i x d, c' = d0 x d', theta' = cos(theta) |c|' - sin(theta) (d0 . d'), |c|' = c . c' / |c|

and for prismatic joints a_i (positions) and 0 (rotations). Columns are summed into
``q_index[i]`` (joints driven by one posture entry add up), for the joints between each
component's frame and the world. Tested against central differences on every kind of
component and against ``pinocchio.computeFrameJacobian`` for positions (tests/test_ik_jacobian.py).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin._jit import njit
from gb_pin.ik.geometry import component_frame, log3, pointing_direction
from gb_pin.ik.robot import as_components
from gb_pin.learn.body.chain import Body, KinematicChain
from gb_pin.learn.body.components import ORIENTATION, POINTING, POSITION, TaskComponents, components_forward
from gb_pin.learn.body.joints import REVOLUTE, joints_forward
from gb_pin.learn.body.task import STACKED, StackedTaskArrays

__all__ = ["frame_jacobian", "task_jacobian"]


@njit(cache=True, nogil=True, error_model="numpy")
def _inverse_right_jacobian_coefficient(theta):  # type: ignore[no-untyped-def]
    """beta of Jr^-1(phi) = I + [phi]/2 + beta [phi]^2 (its series below 1e-4 rad)."""
    if theta < 1e-4:
        return 1.0 / 12.0 + theta * theta / 720.0
    return 1.0 / (theta * theta) - (1.0 + math.cos(theta)) / (2.0 * theta * math.sin(theta))


@njit(cache=True, nogil=True, error_model="numpy")
def task_jacobian(q, body, x, J):  # type: ignore[no-untyped-def]
    """x = f(q) into ``x`` (n,) and dx/dq into ``J`` (n, m) for one posture ``q`` (m,).

    ``body.task`` is the task as components (:class:`StackedTaskArrays`).
    """
    joints, comps, rot_ws, pos_ws = body
    joints_forward(q, joints, rot_ws, pos_ws)
    components_forward(comps, rot_ws, pos_ws, x)
    W, p, M = np.empty((3, 3)), np.empty(3), np.empty((3, 3))
    for a in range(J.shape[0]):
        for b in range(J.shape[1]):
            J[a, b] = 0.0
    row = 0
    for c in range(comps.component_kinds.shape[0]):
        kind = comps.component_kinds[c]
        s = comps.component_scales[c]
        ref = comps.component_references[c]
        size = comps.component_sizes[c]
        phi0, phi1, phi2, beta = 0.0, 0.0, 0.0, 0.0
        c0, c1, c2, sn, cs, theta, g = 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0
        if kind == POINTING:
            pointing_direction(comps, c, rot_ws, p)  # p holds d
            c0 = ref[0, 1] * p[2] - ref[0, 2] * p[1]
            c1 = ref[0, 2] * p[0] - ref[0, 0] * p[2]
            c2 = ref[0, 0] * p[1] - ref[0, 1] * p[0]
            sn = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
            cs = ref[0, 0] * p[0] + ref[0, 1] * p[1] + ref[0, 2] * p[2]
            theta = math.atan2(sn, cs)
            g = theta / sn if sn > 1e-12 else 1.0
        else:
            component_frame(comps, c, rot_ws, pos_ws, W, p)
        if kind == ORIENTATION:
            for a in range(3):
                for b in range(3):
                    M[a, b] = ref[0, a] * W[0, b] + ref[1, a] * W[1, b] + ref[2, a] * W[2, b]
            phi0, phi1, phi2, theta = log3(M)
            beta = _inverse_right_jacobian_coefficient(theta)
        i = comps.component_parents[c]
        while i >= 0:
            r = rot_ws[i]
            ax = joints.axes[i]
            w0 = r[0, 0] * ax[0] + r[0, 1] * ax[1] + r[0, 2] * ax[2]
            w1 = r[1, 0] * ax[0] + r[1, 1] * ax[1] + r[1, 2] * ax[2]
            w2 = r[2, 0] * ax[0] + r[2, 1] * ax[1] + r[2, 2] * ax[2]
            col = joints.q_index[i]
            revolute = joints.kinds[i] == REVOLUTE
            if kind == POSITION:
                if revolute:
                    d0, d1, d2 = p[0] - pos_ws[i, 0], p[1] - pos_ws[i, 1], p[2] - pos_ws[i, 2]
                    l0, l1, l2 = w1 * d2 - w2 * d1, w2 * d0 - w0 * d2, w0 * d1 - w1 * d0
                else:
                    l0, l1, l2 = w0, w1, w2
                for a in range(size):
                    k = comps.component_axes[c, a]
                    J[row + a, col] += l0 if k == 0 else (l1 if k == 1 else l2)
            elif revolute and kind == ORIENTATION:
                v0 = W[0, 0] * w0 + W[1, 0] * w1 + W[2, 0] * w2  # R^T a_i: the turn in the frame
                v1 = W[0, 1] * w0 + W[1, 1] * w1 + W[2, 1] * w2
                v2 = W[0, 2] * w0 + W[1, 2] * w1 + W[2, 2] * w2
                a0 = phi1 * v2 - phi2 * v1  # phi x v
                a1 = phi2 * v0 - phi0 * v2
                a2 = phi0 * v1 - phi1 * v0
                b0 = phi1 * a2 - phi2 * a1  # phi x (phi x v)
                b1 = phi2 * a0 - phi0 * a2
                b2 = phi0 * a1 - phi1 * a0
                J[row, col] += s * (v0 + 0.5 * a0 + beta * b0)
                J[row + 1, col] += s * (v1 + 0.5 * a1 + beta * b1)
                J[row + 2, col] += s * (v2 + 0.5 * a2 + beta * b2)
            elif revolute:
                e0 = w1 * p[2] - w2 * p[1]  # d' = a_i x d
                e1 = w2 * p[0] - w0 * p[2]
                e2 = w0 * p[1] - w1 * p[0]
                f0 = ref[0, 1] * e2 - ref[0, 2] * e1  # c' = d0 x d'
                f1 = ref[0, 2] * e0 - ref[0, 0] * e2
                f2 = ref[0, 0] * e1 - ref[0, 1] * e0
                dg = 0.0
                if sn > 1e-6:
                    dsn = (c0 * f0 + c1 * f1 + c2 * f2) / sn
                    dtheta = cs * dsn - sn * (ref[0, 0] * e0 + ref[0, 1] * e1 + ref[0, 2] * e2)
                    dg = (dtheta * sn - theta * dsn) / (sn * sn)
                for a in range(2):
                    u = ref[a + 1]
                    J[row + a, col] += s * (
                        dg * (u[0] * c0 + u[1] * c1 + u[2] * c2) + g * (u[0] * f0 + u[1] * f1 + u[2] * f2)
                    )
            i = joints.parents[i]
        row += size


def frame_jacobian(chain: KinematicChain, q: ArrayLike) -> NDArray[np.float64]:
    """The task Jacobian dx/dq at one posture, for any task map (positions, orientations, pointing).

    Args:
        chain: the learner's kinematic chain (``KinematicTarget.chain``).
        q: posture (m,) [rad] or [m] for prismatic joints.

    Returns:
        (n, m) Jacobian: [m/rad] for revolute columns, [m/m] for prismatic ones (rotational rows
        are in the task's units, s [m/rad] x [rad]).

    Raises:
        InvalidArgumentError: ``q`` of the wrong shape or not finite.
    """
    qv = check.vector("q", q, chain.n_joints)
    comps: TaskComponents = as_components(chain)
    arrays = StackedTaskArrays(STACKED, *(getattr(comps, k) for k in TaskComponents.FIELDS))
    m = chain.n_joints
    body = Body(chain.joints, arrays, np.empty((m, 3, 3)), np.empty((m, 3)))
    J = np.empty((chain.n_task, m))
    task_jacobian(qv, body, np.empty(chain.n_task), J)
    return J
