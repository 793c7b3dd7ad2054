"""Damped least squares on the learner's compiled kinematics: refine postures to reach targets.

One iteration at posture q with task error e = x* - f(q) (n,) and Jacobian J (n, m):

    dq = J^T (J J^T + lambda^2 I)^-1 e                (damped least squares)
    q <- clip(q + dq, lower, upper)                    (full step, within the joint limits)

A step that does not reduce the error is halved, at most ``backtracks`` times; when no part
of it does, the posture is a local minimum of the error within the limits (or the target is
out of reach) and the iteration stops there, so the error never grows. Learned and home seeds
almost never need a halving, random seeds do. ``backtracks=0``: full steps, always taken.

Joints sitting at a limit whose step points out of the range are frozen for that iteration
(their columns of J removed and dq recomputed once), so the other joints take over instead
of the step being cut by the clip. The iteration stops when ||e|| <= tol (success), after
``max_iterations`` steps, when the step vanishes (every helpful joint at a limit), or when
the error stops changing (an unreachable target: the closest point is found).
Everything runs in compiled code on :class:`~gb_pin.learn.body.chain.Body` arrays; nothing
is allocated per iteration.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin._jit import njit
from gb_pin.ik.jacobian import body_jacobian
from gb_pin.learn.body.chain import Body

__all__ = ["IKBuffers", "IKRobot", "IKSettings", "dls_step", "refine_batch"]

STALLED = 1e-14  # a step below this [rad or m] in every joint changes nothing: stop
STAGNANT = 1e-12  # an error changing by less than this [m] in one step has converged (unreachable)


class IKSettings(NamedTuple):
    """The solver's parameters (what :func:`refine_batch` takes).

    Attributes:
        tol: success when the task error ||x* - f(q)|| <= tol [m].
        damping: lambda of the damped least squares [m]; lambda^2 is added to J J^T.
        max_iterations: the most steps per target.
        backtracks: the most halvings of a step that does not reduce the error (0: full steps,
            always taken; else the error never grows and a local minimum ends the iteration).
    """

    tol: float
    damping: float
    max_iterations: int
    backtracks: int


class IKRobot(NamedTuple):
    """The robot as the solver sees it.

    Attributes:
        body: compiled forward kinematics (``KinematicChain.kernel()``).
        lower: (m,) lower joint limits, -inf where unbounded.
        upper: (m,) upper joint limits, +inf where unbounded.
    """

    body: Body
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]


class IKBuffers(NamedTuple):
    """A batch's postures (seeds in, solutions out) and what the solver measured.

    Attributes:
        q: (N, m) the seeds on entry, the refined postures on return.
        x: (N, n) f(q) of the returned postures [m].
        residual: (N,) ||x* - f(q)|| [m].
        iterations: (N,) int64, the steps taken.
    """

    q: NDArray[np.float64]
    x: NDArray[np.float64]
    residual: NDArray[np.float64]
    iterations: NDArray[np.int64]


class _Work(NamedTuple):
    J: NDArray[np.float64]  # (n, m)
    A: NDArray[np.float64]  # (n, n)
    e: NDArray[np.float64]  # (n,)
    y: NDArray[np.float64]  # (n,)
    dq: NDArray[np.float64]  # (m,)
    free: NDArray[np.float64]  # (m,) 1.0 for joints that move, 0.0 for frozen ones
    q_old: NDArray[np.float64]  # (m,) the posture before the step


@njit(cache=True, nogil=True, error_model="numpy")
def _damped_solve(w, lam2):  # type: ignore[no-untyped-def]
    """dq = J_free^T (J_free J_free^T + lam2 I)^-1 e into ``w.dq``, by Cholesky (n <= a few)."""
    J, A, e, y, dq, free = w.J, w.A, w.e, w.y, w.dq, w.free
    n, m = J.shape
    for a in range(n):
        for b in range(a + 1):
            s = 0.0
            for c in range(m):
                s += J[a, c] * J[b, c] * free[c]
            A[a, b] = s + (lam2 if a == b else 0.0)
    for a in range(n):  # lower-triangular Cholesky factor, in place
        for b in range(a + 1):
            s = A[a, b]
            for c in range(b):
                s -= A[a, c] * A[b, c]
            A[a, b] = math.sqrt(s) if a == b else s / A[b, b]
    for a in range(n):  # forward then backward substitution: y = A^-1 e
        s = e[a]
        for c in range(a):
            s -= A[a, c] * y[c]
        y[a] = s / A[a, a]
    for a in range(n - 1, -1, -1):
        s = y[a]
        for c in range(a + 1, n):
            s -= A[c, a] * y[c]
        y[a] = s / A[a, a]
    for c in range(m):
        s = 0.0
        for a in range(n):
            s += J[a, c] * y[a]
        dq[c] = s * free[c]


@njit(cache=True, nogil=True, error_model="numpy")
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


@njit(cache=True, nogil=True, error_model="numpy")
def _refine(target, q, robot, settings, w, x):  # type: ignore[no-untyped-def]
    """Refine one posture ``q`` (m,) in place towards ``target`` (n,); returns (residual, steps)."""
    lower, upper = robot.lower, robot.upper
    lam2 = settings.damping * settings.damping
    for c in range(q.shape[0]):
        q[c] = min(max(q[c], lower[c]), upper[c])
    residual = _evaluate(target, q, robot, w, x)
    steps = 0
    previous = np.inf
    while True:
        if residual <= settings.tol or steps >= settings.max_iterations or not math.isfinite(residual):
            return residual, steps
        if abs(previous - residual) < STAGNANT:
            return residual, steps
        if dls_step(q, robot, lam2, w) < STALLED:
            return residual, steps
        previous = residual
        for c in range(q.shape[0]):
            w.q_old[c] = q[c]
        scale = 1.0
        for _ in range(settings.backtracks + 1):
            for c in range(q.shape[0]):
                q[c] = min(max(w.q_old[c] + scale * w.dq[c], lower[c]), upper[c])
            residual = _evaluate(target, q, robot, w, x)
            if residual < previous or settings.backtracks == 0:
                break
            scale *= 0.5
        if residual >= previous and settings.backtracks > 0:
            # no part of the step reduces the error: a local minimum of it (within the limits)
            for c in range(q.shape[0]):
                q[c] = w.q_old[c]
            return _evaluate(target, q, robot, w, x), steps
        steps += 1


@njit(cache=True, nogil=True, error_model="numpy")
def _evaluate(target, q, robot, w, x):  # type: ignore[no-untyped-def]
    """f(q) into ``x``, the Jacobian into ``w.J``, the error into ``w.e``; returns ||e||."""
    body_jacobian(q, robot.body, x, w.J)
    s = 0.0
    for a in range(target.shape[0]):
        w.e[a] = target[a] - x[a]
        s += w.e[a] * w.e[a]
    return math.sqrt(s)


@njit(cache=True, nogil=True, error_model="numpy")
def refine_batch(X, robot, settings, out):  # type: ignore[no-untyped-def]
    """Refine every seed ``out.q[r]`` towards ``X[r]`` (N, n); fills ``out``."""
    N, n = X.shape
    m = out.q.shape[1]
    w = _Work(
        np.empty((n, m)), np.empty((n, n)), np.empty(n), np.empty(n), np.empty(m), np.empty(m), np.empty(m)
    )
    for r in range(N):
        residual, steps = _refine(X[r], out.q[r], robot, settings, w, out.x[r])
        out.residual[r] = residual
        out.iterations[r] = steps
