"""Damped least squares on the learner's compiled kinematics: one attempt from one seed.

One iteration at posture q with weighted geometric error e (n_e,) and its Jacobian J
(n_e, m) (:mod:`gb_pin.ik.geometry`):

    dq = J^T (J J^T + lambda^2 I)^-1 e   (n_e <= m)   or   (J^T J + lambda^2 I)^-1 J^T e   (n_e > m)
    q <- clip(q + dq, lower, upper)                    (full step, within the joint limits)
    lambda^2 = damping^2 + error_damping ||e||^2       (Levenberg-Marquardt damping, Sugihara 2011)

The damping that shrinks with the error is strong far from the goal (steps no longer than the
linearisation deserves) and vanishes near it (Newton steps, quadratic convergence even close to a
singular posture, where a fixed 1e-3 m crawled). Measured on 3000 FK-sampled targets (restarts
up to 300, docs/IK.md): SO-101 pointing 30 failures and 9.7 restarts per target with a fixed
lambda = 1e-3 m, none and 1.6 with 1e-5 m + 0.1 ||e||^2; Panda pose 1.65 -> 0.58 restarts.

A step that does not reduce the error is halved, at most ``backtracks`` times; when no part
of it does, the posture is a local minimum of the error within the limits (or the target is
out of reach) and the attempt stops there, so the error never grows. ``backtracks=0``: full
steps, always taken. Joints sitting at a limit whose step points out of the range are frozen
for that iteration (their columns removed and dq recomputed once), so the other joints take
over. An attempt stops on success (every component within its tolerance), after
``max_iterations`` steps, when the step vanishes, when the error stops changing (by 1e-4 of itself), or at the
deadline. Nothing is allocated per iteration.

The kernels here, in :mod:`~gb_pin.ik.geometry` and :mod:`~gb_pin.ik.search` allocate nothing
and are compiled without numba's reference counting (:data:`gb_pin._jit.NO_REFCOUNT`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin._jit import NO_REFCOUNT, njit
from gb_pin.ik.clock import now
from gb_pin.ik.geometry import errors_and_jacobian, within
from gb_pin.learn.body.joints import Joints, joints_forward
from gb_pin.learn.body.task import StackedTaskArrays

__all__ = ["IKRobot", "IKSettings", "Work", "dls_step", "evaluate", "refine", "work_buffers"]

STALLED = 1e-14  # a step below this [rad or m] in every joint changes nothing: stop
STAGNANT = 1e-12  # an error changing by less than this [m] in one step has converged (unreachable)
PROGRESS = 1e-4  # ... or by less than this fraction of itself: crawling (measured: an unreachable TALOS
# target then stops after 10 steps instead of 100, and no FK-sampled target of docs/IK.md is lost)


class IKSettings(NamedTuple):
    """The solver's parameters.

    Attributes:
        tol: success when every position residual is <= tol [m].
        angle_tol: ... and every orientation or pointing residual <= angle_tol [rad].
        damping: the least damping lambda [m] of the damped least squares.
        error_damping: lambda^2 = damping^2 + error_damping ||e||^2 is added to J J^T (unitless).
        max_iterations: the most steps of one attempt (from one seed).
        backtracks: the most halvings of a step that does not reduce the error.
        timeout: seconds per target (inf: none), restarts included.
        max_restarts: restarts from random postures after the first seed (-1: until the timeout).
        solutions: distinct solutions wanted per target (k).
        min_distance: two solutions are distinct when a joint differs by at least this [rad] or [m].
        closest: keep the solutions closest to the reference postures, searching the whole budget.
        follow: a path: each target after the first starts from the previous target's solution.
        clock: the clock id of :func:`~gb_pin.ik.clock.now` (-1: none), read at each query's start and
            end, after each attempt and every 8 steps of an attempt.
    """

    tol: float
    angle_tol: float
    damping: float
    max_iterations: int
    backtracks: int
    error_damping: float
    timeout: float
    max_restarts: int
    solutions: int
    min_distance: float
    closest: bool
    follow: bool
    clock: int


class IKRobot(NamedTuple):
    """The robot as the solver sees it.

    Attributes:
        joints: the kinematic tree (``KinematicChain.joints``).
        comps: the task map as components (a position task is one position component).
        weights: (C,) weight of each component's rows: 1 for positions, [m/rad] for rotations.
        rot_ws: (m, 3, 3) scratch for the joint rotations.
        pos_ws: (m, 3) scratch for the joint positions.
        lower: (m,) lower joint limits, -inf where unbounded.
        upper: (m,) upper joint limits, +inf where unbounded.
        sample_lower: (m,) lower bounds of random restarts (home - pi where unbounded).
        sample_upper: (m,) upper bounds of random restarts (home + pi where unbounded).
        periodic: (m,) 1.0 for revolute entries whose range exceeds 2 pi (a turn of 2 pi reaches the
            same pose), else 0.0.
    """

    joints: Joints
    comps: StackedTaskArrays
    weights: NDArray[np.float64]
    rot_ws: NDArray[np.float64]
    pos_ws: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    sample_lower: NDArray[np.float64]
    sample_upper: NDArray[np.float64]
    periodic: NDArray[np.float64]


class Work(NamedTuple):
    """Scratch of one attempt (allocated once per batch)."""

    J: NDArray[np.float64]  # (n_e, m) weighted error Jacobian
    A: NDArray[np.float64]  # (d, d), d = min(n_e, m)
    e: NDArray[np.float64]  # (n_e,) weighted error
    y: NDArray[np.float64]  # (d,)
    dq: NDArray[np.float64]  # (m,)
    free: NDArray[np.float64]  # (m,) 1.0 for joints that move, 0.0 for frozen ones
    q_old: NDArray[np.float64]  # (m,) the posture before the step
    residuals: NDArray[np.float64]  # (C,) per component [m] or [rad]
    goal: tuple[NDArray[np.float64], NDArray[np.float64]]  # (C, 3) positions, (C, 3, 3) rotations
    geo: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]  # W, p, M
    clock_buf: NDArray[np.int64]  # (2,) timespec
    stop: NDArray[np.int64]  # (1,) set to 1 from another thread (Ctrl-C): the batch returns at once


def work_buffers(n_e: int, m: int, C: int) -> Work:
    """Fresh :class:`Work` for a task of ``n_e`` error rows, ``m`` joints and ``C`` components."""
    d = min(n_e, m)
    return Work(
        np.empty((n_e, m)), np.empty((d, d)), np.empty(n_e), np.empty(d), np.empty(m), np.empty(m),
        np.empty(m), np.empty(C), (np.zeros((C, 3)), np.zeros((C, 3, 3))),
        (np.empty((3, 3)), np.empty(3), np.empty((3, 3))), np.zeros(2, dtype=np.int64),
        np.zeros(1, dtype=np.int64),
    )  # fmt: skip


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def _cholesky_solve(A, y):  # type: ignore[no-untyped-def]
    """y <- A^-1 y for symmetric positive definite A (its lower triangle is overwritten)."""
    d = y.shape[0]
    for a in range(d):
        for b in range(a + 1):
            s = A[a, b]
            for c in range(b):
                s -= A[a, c] * A[b, c]
            A[a, b] = math.sqrt(s) if a == b else s / A[b, b]
    for a in range(d):
        s = y[a]
        for c in range(a):
            s -= A[a, c] * y[c]
        y[a] = s / A[a, a]
    for a in range(d - 1, -1, -1):
        s = y[a]
        for c in range(a + 1, d):
            s -= A[c, a] * y[c]
        y[a] = s / A[a, a]


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def _damped_solve(w, lam2):  # type: ignore[no-untyped-def]
    """The damped least-squares step over the free joints into ``w.dq``."""
    J, A, e, y, dq, free = w.J, w.A, w.e, w.y, w.dq, w.free
    n, m = J.shape
    if n <= m:  # dq = J^T (J J^T + lam2 I)^-1 e
        for a in range(n):
            for b in range(a + 1):
                s = 0.0
                for c in range(m):
                    s += J[a, c] * J[b, c] * free[c]
                A[a, b] = s + (lam2 if a == b else 0.0)
            y[a] = e[a]
        _cholesky_solve(A, y)
        for c in range(m):
            s = 0.0
            for a in range(n):
                s += J[a, c] * y[a]
            dq[c] = s * free[c]
    else:  # dq = (J^T J + lam2 I)^-1 J^T e
        for a in range(m):
            for b in range(a + 1):
                s = 0.0
                for r in range(n):
                    s += J[r, a] * J[r, b]
                A[a, b] = s * free[a] * free[b] + (lam2 if a == b else 0.0)
            s = 0.0
            for r in range(n):
                s += J[r, a] * e[r]
            y[a] = s * free[a]
        _cholesky_solve(A, y)
        for c in range(m):
            dq[c] = y[c] * free[c]


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def dls_step(q, robot, lam2, w):  # type: ignore[no-untyped-def]
    """The damped least-squares step ``w.dq`` (m,) for error ``w.e`` and Jacobian ``w.J`` at ``q``.

    Joints at a limit whose step leaves the range are frozen and the step recomputed once.
    Returns the largest |dq_i| of the step.
    """
    lower, upper = robot.lower, robot.upper
    free = w.free
    m = q.shape[0]
    for c in range(m):
        free[c] = 1.0
    _damped_solve(w, lam2)
    frozen = False
    for c in range(m):
        if (q[c] <= lower[c] and w.dq[c] < 0.0) or (q[c] >= upper[c] and w.dq[c] > 0.0):
            free[c] = 0.0
            frozen = True
    if frozen:
        _damped_solve(w, lam2)
    largest = 0.0
    for c in range(m):
        largest = max(largest, abs(w.dq[c]))
    return largest


@njit(cache=True, nogil=True, error_model="numpy", inline="always", **NO_REFCOUNT)
def evaluate(q, robot, w):  # type: ignore[no-untyped-def]
    """The errors, Jacobian and residuals at ``q`` into ``w``; returns the weighted error norm."""
    joints_forward(q, robot.joints, robot.rot_ws, robot.pos_ws)
    return math.sqrt(errors_and_jacobian(robot, w))


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def refine(q, robot, settings, w, deadline):  # type: ignore[no-untyped-def]
    """Refine ``q`` (m,) in place towards the goal in ``w.goal``; returns (error norm, steps, success).

    ``deadline``: clock time [s] at which to stop (inf: none). Every 8 steps it also stops when
    ``w.stop[0]`` is set (Ctrl-C, from the calling thread: :func:`~gb_pin.ik.search.solve_batch`).
    """
    lower, upper = robot.lower, robot.upper
    lam2 = settings.damping * settings.damping
    m = q.shape[0]
    for c in range(m):
        q[c] = min(max(q[c], lower[c]), upper[c])
    cost = evaluate(q, robot, w)
    steps = 0
    previous = np.inf
    timed = deadline < np.inf
    while True:
        if within(robot, w.residuals, settings.tol, settings.angle_tol):
            return cost, steps, True
        if (
            steps >= settings.max_iterations
            or not math.isfinite(cost)
            or abs(previous - cost) < STAGNANT + PROGRESS * cost
        ):
            return cost, steps, False
        # a read of the stop flag (and of the clock) every 8 steps
        if steps % 8 == 0 and (w.stop[0] != 0 or (timed and now(settings.clock, w.clock_buf) >= deadline)):
            return cost, steps, False
        # Levenberg-Marquardt damping that shrinks with the error (Sugihara 2011): strong far from
        # the goal, where the linearisation is poor, vanishing at it, where Newton steps converge fast
        if dls_step(q, robot, lam2 + settings.error_damping * cost * cost, w) < STALLED:
            return cost, steps, False
        previous = cost
        for c in range(m):
            w.q_old[c] = q[c]
        scale = 1.0
        for _ in range(settings.backtracks + 1):
            for c in range(m):
                q[c] = min(max(w.q_old[c] + scale * w.dq[c], lower[c]), upper[c])
            cost = evaluate(q, robot, w)
            if cost < previous or settings.backtracks == 0:
                break
            scale *= 0.5
        if cost >= previous and settings.backtracks > 0:
            # no part of the step reduces the error: a local minimum of it (within the limits)
            for c in range(m):
                q[c] = w.q_old[c]
            return evaluate(q, robot, w), steps, False
        steps += 1
