"""Compiled geometry of the IK: goals from task vectors, geometric errors, their Jacobian, residuals.

The learner's task vector x stacks components (:mod:`gb_pin.learn.body.components`):
positions [m], orientations ``s log(R_ref^T R)`` and pointing directions in tangent
coordinates ``s theta (u . k, v . k)``. The solver converts each target row x* once into a
geometric goal (a position p*, a rotation R* = R_ref exp(x*_rot / s), a direction d*) and
then works with geometric errors, which have no wrap-around at 180 degrees:

    position:     e = p* - p                                  J: linear velocity of the frame
    orientation:  e = w log(R* R^T)   (world rotation vector)  J: w * angular velocity
    pointing:     e = w theta k,  k = (d x d*) / |d x d*|     J: w * (I - d d^T) angular velocity

(w: the component's weight [m/rad]). Each is the exact first-order change of the error
towards zero (log(R* R^T) shrinks along the angular velocity e, ``d`` turns towards ``d*``
along ``d x d*``), so Gauss-Newton steps on them converge quadratically. The residual of a
component is ||p* - p|| [m] or the angle to its goal [rad]: what the tolerances bound.
Nothing here allocates; every function runs in compiled code on
:class:`~gb_pin.learn.body.task.StackedTaskArrays` (a position task is one position component).
"""

from __future__ import annotations

import math

from gb_pin._jit import NO_REFCOUNT, njit
from gb_pin.learn.body.components import ORIENTATION, POSITION
from gb_pin.learn.body.joints import REVOLUTE

__all__ = [
    "component_frame",
    "errors_and_jacobian",
    "exp3",
    "goal_from_task",
    "log3",
    "pointing_direction",
    "within",
]

_NEAR_PI_SIN = 1e-4  # below this sin(theta), with cos(theta) < 0, the axis comes from the symmetric part


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def log3(M):  # type: ignore[no-untyped-def]
    """The rotation vector (x, y, z) and angle theta of a rotation matrix ``M`` (3, 3); theta in [0, pi]."""
    wx = 0.5 * (M[2, 1] - M[1, 2])
    wy = 0.5 * (M[0, 2] - M[2, 0])
    wz = 0.5 * (M[1, 0] - M[0, 1])
    sn = math.sqrt(wx * wx + wy * wy + wz * wz)
    cs = max(-1.0, min(1.0, 0.5 * (M[0, 0] + M[1, 1] + M[2, 2] - 1.0)))
    theta = math.atan2(sn, cs)
    if sn >= _NEAR_PI_SIN or cs >= 0.0:
        g = theta / sn if sn > 1e-300 else 1.0
        return g * wx, g * wy, g * wz, theta
    # near pi: k k^T = (S - cos(theta) I) / (1 - cos(theta)), S the symmetric part
    v = 1.0 - cs
    d0 = (M[0, 0] - cs) / v
    d1 = (M[1, 1] - cs) / v
    d2 = (M[2, 2] - cs) / v
    if d0 >= d1 and d0 >= d2:
        ax = math.sqrt(max(d0, 0.0))
        ay = 0.5 * (M[0, 1] + M[1, 0]) / (v * ax)
        az = 0.5 * (M[0, 2] + M[2, 0]) / (v * ax)
    elif d1 >= d2:
        ay = math.sqrt(max(d1, 0.0))
        ax = 0.5 * (M[0, 1] + M[1, 0]) / (v * ay)
        az = 0.5 * (M[1, 2] + M[2, 1]) / (v * ay)
    else:
        az = math.sqrt(max(d2, 0.0))
        ax = 0.5 * (M[0, 2] + M[2, 0]) / (v * az)
        ay = 0.5 * (M[1, 2] + M[2, 1]) / (v * az)
    if ax * wx + ay * wy + az * wz < 0.0:
        ax, ay, az = -ax, -ay, -az
    return theta * ax, theta * ay, theta * az, theta


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def exp3(px, py, pz):  # type: ignore[no-untyped-def]
    """The rotation exp([p]x) of the rotation vector (px, py, pz), as 9 numbers row by row (Rodrigues)."""
    theta = math.sqrt(px * px + py * py + pz * pz)
    if theta > 1e-300:
        kx, ky, kz = px / theta, py / theta, pz / theta
    else:
        kx, ky, kz = 1.0, 0.0, 0.0
    s, c = math.sin(theta), math.cos(theta)
    v = 1.0 - c
    return (
        c + kx * kx * v, kx * ky * v - kz * s, kx * kz * v + ky * s,
        ky * kx * v + kz * s, c + ky * ky * v, ky * kz * v - kx * s,
        kz * kx * v - ky * s, kz * ky * v + kx * s, c + kz * kz * v,
    )  # fmt: skip


@njit(cache=True, nogil=True, error_model="numpy", inline="always", **NO_REFCOUNT)
def component_frame(comps, c, rot_ws, pos_ws, W, p):  # type: ignore[no-untyped-def]
    """World rotation ``W`` (3, 3) and position ``p`` (3,) of component ``c``'s frame."""
    f = comps.component_parents[c]
    B, t = comps.component_rotations, comps.component_translations
    for a in range(3):
        if f >= 0:
            r0, r1, r2 = rot_ws[f, a, 0], rot_ws[f, a, 1], rot_ws[f, a, 2]
            p[a] = pos_ws[f, a] + r0 * t[c, 0] + r1 * t[c, 1] + r2 * t[c, 2]
        else:
            r0, r1, r2 = (1.0 if a == 0 else 0.0), (1.0 if a == 1 else 0.0), (1.0 if a == 2 else 0.0)
            p[a] = t[c, a]
        for b in range(3):
            W[a, b] = r0 * B[c, 0, b] + r1 * B[c, 1, b] + r2 * B[c, 2, b]


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def goal_from_task(comps, x, goal_pos, goal_rot):  # type: ignore[no-untyped-def]
    """The geometric goal of task vector ``x`` (n,): per component c, ``goal_pos[c]`` (3,), ``goal_rot[c]``.

    Position: ``goal_pos[c][axis] = x[row]`` on the component's axes. Orientation:
    ``goal_rot[c] = R_ref exp(x_rows / s)``. Pointing: ``goal_rot[c][0] = d*``, the direction at
    angle theta = ||x_rows|| / s from d0 towards k = (x0 u + x1 v) / (s theta) (the inverse of
    the azimuthal equidistant chart of :func:`~gb_pin.learn.body.components.components_forward`).
    """
    row = 0
    for c in range(comps.component_kinds.shape[0]):
        kind = comps.component_kinds[c]
        s = comps.component_scales[c]
        ref = comps.component_references[c]
        if kind == POSITION:
            for a in range(comps.component_sizes[c]):
                goal_pos[c, comps.component_axes[c, a]] = x[row + a]
        elif kind == ORIENTATION:
            e00, e01, e02, e10, e11, e12, e20, e21, e22 = exp3(x[row] / s, x[row + 1] / s, x[row + 2] / s)
            R = goal_rot[c]
            for a in range(3):  # R* = R_ref exp(x / s)
                R[a, 0] = ref[a, 0] * e00 + ref[a, 1] * e10 + ref[a, 2] * e20
                R[a, 1] = ref[a, 0] * e01 + ref[a, 1] * e11 + ref[a, 2] * e21
                R[a, 2] = ref[a, 0] * e02 + ref[a, 1] * e12 + ref[a, 2] * e22
        else:
            t0, t1 = x[row] / s, x[row + 1] / s
            theta = math.sqrt(t0 * t0 + t1 * t1)
            d = goal_rot[c]
            if theta > 0.0:
                kx = (t0 * ref[1, 0] + t1 * ref[2, 0]) / theta
                ky = (t0 * ref[1, 1] + t1 * ref[2, 1]) / theta
                kz = (t0 * ref[1, 2] + t1 * ref[2, 2]) / theta
            else:
                kx, ky, kz = 0.0, 0.0, 0.0
            # d* = cos(theta) d0 + sin(theta) (k x d0)
            sn, cs = math.sin(theta), math.cos(theta)
            d[0, 0] = cs * ref[0, 0] + sn * (ky * ref[0, 2] - kz * ref[0, 1])
            d[0, 1] = cs * ref[0, 1] + sn * (kz * ref[0, 0] - kx * ref[0, 2])
            d[0, 2] = cs * ref[0, 2] + sn * (kx * ref[0, 1] - ky * ref[0, 0])
        row += comps.component_sizes[c]


@njit(cache=True, nogil=True, error_model="numpy", inline="always", **NO_REFCOUNT)
def pointing_direction(comps, c, rot_ws, d):  # type: ignore[no-untyped-def]
    """The world direction ``d`` (3,) of pointing component ``c``'s axis."""
    f = comps.component_parents[c]
    a = comps.component_directions
    for k in range(3):
        d[k] = (
            rot_ws[f, k, 0] * a[c, 0] + rot_ws[f, k, 1] * a[c, 1] + rot_ws[f, k, 2] * a[c, 2]
            if f >= 0
            else a[c, k]
        )


@njit(cache=True, nogil=True, error_model="numpy", inline="always", **NO_REFCOUNT)
def _position_rows(robot, w, c, row):  # type: ignore[no-untyped-def]
    """Position component ``c``: e = p* - p and the linear velocity rows (see :func:`errors_and_jacobian`)."""
    joints, comps, rot_ws, pos_ws = robot.joints, robot.comps, robot.rot_ws, robot.pos_ws
    axes, q_index, kinds, parents = joints.axes, joints.q_index, joints.kinds, joints.parents
    c_axes, size = comps.component_axes, comps.component_sizes[c]
    goal_pos, e, J = w.goal[0], w.e, w.J
    W, p = w.geo[0], w.geo[1]
    component_frame(comps, c, rot_ws, pos_ws, W, p)
    r2 = 0.0
    for a in range(size):
        k = c_axes[c, a]
        v = goal_pos[c, k] - p[k]
        e[row + a] = v
        r2 += v * v
    w.residuals[c] = math.sqrt(r2)
    i = comps.component_parents[c]
    while i >= 0:
        a0, a1, a2 = axes[i, 0], axes[i, 1], axes[i, 2]
        w0 = rot_ws[i, 0, 0] * a0 + rot_ws[i, 0, 1] * a1 + rot_ws[i, 0, 2] * a2
        w1 = rot_ws[i, 1, 0] * a0 + rot_ws[i, 1, 1] * a1 + rot_ws[i, 1, 2] * a2
        w2 = rot_ws[i, 2, 0] * a0 + rot_ws[i, 2, 1] * a1 + rot_ws[i, 2, 2] * a2
        if kinds[i] == REVOLUTE:
            d0, d1, d2 = p[0] - pos_ws[i, 0], p[1] - pos_ws[i, 1], p[2] - pos_ws[i, 2]
            w0, w1, w2 = w1 * d2 - w2 * d1, w2 * d0 - w0 * d2, w0 * d1 - w1 * d0
        col = q_index[i]
        for a in range(size):
            k = c_axes[c, a]
            J[row + a, col] += w0 if k == 0 else (w1 if k == 1 else w2)
        i = parents[i]
    return r2


@njit(cache=True, nogil=True, error_model="numpy", inline="always", **NO_REFCOUNT)
def _rotation_rows(robot, w, c, row):  # type: ignore[no-untyped-def]
    """Orientation or pointing component ``c``: its error and angular velocity rows (weighted)."""
    joints, comps, rot_ws = robot.joints, robot.comps, robot.rot_ws
    axes, q_index, kinds, parents = joints.axes, joints.q_index, joints.kinds, joints.parents
    goal_rot, e, J = w.goal[1], w.e, w.J
    W, p, M = w.geo
    wgt = robot.weights[c]
    pointing = comps.component_kinds[c] != ORIENTATION
    if not pointing:
        component_frame(comps, c, rot_ws, robot.pos_ws, W, p)
        for a in range(3):  # M = R* W^T: the world rotation still to do
            for b in range(3):
                M[a, b] = (
                    goal_rot[c, a, 0] * W[b, 0] + goal_rot[c, a, 1] * W[b, 1] + goal_rot[c, a, 2] * W[b, 2]
                )
        ex, ey, ez, theta = log3(M)
    else:
        pointing_direction(comps, c, rot_ws, p)  # p holds d
        g0, g1, g2 = goal_rot[c, 0, 0], goal_rot[c, 0, 1], goal_rot[c, 0, 2]
        cx = p[1] * g2 - p[2] * g1
        cy = p[2] * g0 - p[0] * g2
        cz = p[0] * g1 - p[1] * g0
        sn = math.sqrt(cx * cx + cy * cy + cz * cz)
        theta = math.atan2(sn, p[0] * g0 + p[1] * g1 + p[2] * g2)
        if sn > 1e-300:
            ex, ey, ez = theta * cx / sn, theta * cy / sn, theta * cz / sn
        else:  # along the goal (theta = 0), or opposite it: turn about any axis normal to d
            ux, uy, uz = (p[1], -p[0], 0.0) if abs(p[2]) < 0.9 else (0.0, p[2], -p[1])
            un = math.sqrt(ux * ux + uy * uy + uz * uz)
            ex, ey, ez = theta * ux / un, theta * uy / un, theta * uz / un
    e[row], e[row + 1], e[row + 2] = wgt * ex, wgt * ey, wgt * ez
    w.residuals[c] = theta
    i = comps.component_parents[c]
    while i >= 0:
        if kinds[i] == REVOLUTE:
            a0, a1, a2 = axes[i, 0], axes[i, 1], axes[i, 2]
            w0 = rot_ws[i, 0, 0] * a0 + rot_ws[i, 0, 1] * a1 + rot_ws[i, 0, 2] * a2
            w1 = rot_ws[i, 1, 0] * a0 + rot_ws[i, 1, 1] * a1 + rot_ws[i, 1, 2] * a2
            w2 = rot_ws[i, 2, 0] * a0 + rot_ws[i, 2, 1] * a1 + rot_ws[i, 2, 2] * a2
            if pointing:  # the part of the turn normal to d
                dot = w0 * p[0] + w1 * p[1] + w2 * p[2]
                w0, w1, w2 = w0 - dot * p[0], w1 - dot * p[1], w2 - dot * p[2]
            col = q_index[i]
            J[row, col] += wgt * w0
            J[row + 1, col] += wgt * w1
            J[row + 2, col] += wgt * w2
        i = parents[i]
    return wgt * wgt * theta * theta


@njit(cache=True, nogil=True, error_model="numpy", inline="always", **NO_REFCOUNT)
def errors_and_jacobian(robot, w):  # type: ignore[no-untyped-def]
    """Weighted geometric errors ``w.e`` (n_e,), their Jacobian ``w.J`` (n_e, m), ``w.residuals`` (C,).

    The joint frames must be those of the posture (``joints_forward`` into ``robot.rot_ws``,
    ``robot.pos_ws``), the goal in ``w.goal`` (:func:`goal_from_task`). Returns ||e||^2.
    One small function per kind of component: a single function with every kind's code in it
    ran 4 x slower for a position task, whose rows take only the first branch.
    """
    J = w.J
    for a in range(J.shape[0]):
        for b in range(J.shape[1]):
            J[a, b] = 0.0
    kinds, sizes = robot.comps.component_kinds, robot.comps.component_sizes
    total = 0.0
    row = 0
    for c in range(kinds.shape[0]):
        if kinds[c] == POSITION:
            total += _position_rows(robot, w, c, row)
            row += sizes[c]
        else:
            total += _rotation_rows(robot, w, c, row)
            row += 3
    return total


@njit(cache=True, nogil=True, error_model="numpy", inline="always", **NO_REFCOUNT)
def within(robot, residuals, tol, angle_tol):  # type: ignore[no-untyped-def]
    """Whether every position residual is <= ``tol`` [m] and every angle residual <= ``angle_tol`` [rad]."""
    kinds = robot.comps.component_kinds
    for c in range(kinds.shape[0]):  # noqa: SIM110 (a generator does not compile here)
        if residuals[c] > (tol if kinds[c] == POSITION else angle_tol):
            return False
    return True
