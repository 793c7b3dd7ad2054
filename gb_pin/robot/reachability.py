"""Reachability of points on the task axes: seeded posture sampling and local refinement.

A point x* on the task axes is *reachable* if some posture within the joint limits
puts the frame there. gb_pin checks it the way a user would by hand, but seeded so
that the answer is the same every time:

1. sample postures uniformly within the joint limits (``[-pi, pi]`` for an
   unbounded revolute joint, ``[-1, 1]`` m for an unbounded prismatic one) and
   compute their positions with the compiled forward kinematics;
2. from the few sampled postures whose positions lie closest to x*, run a damped
   least-squares (Levenberg-Marquardt) descent on ||x* - f(q)||, the posture clipped
   to the limits after every update (a projected method: it never leaves the limits);
3. x* is reachable if one of these descents ends within ``tolerance`` of it.

A success is a proof (the posture is returned); a failure is evidence only: a point
reachable through a narrow region that no sample came near can be missed.
:func:`beyond_reach` is the cheap one-sided check: points farther than the arm's length.

This module imports neither pinocchio nor meshcat, nor the robot class: it works on
anything with a :class:`~gb_pin.learn.body.chain.KinematicChain`, a home posture and
joint limits (:class:`Robot`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin._jit import njit
from gb_pin.learn.body.chain import PRISMATIC, KinematicChain, body_forward
from gb_pin.learn.body.kinematics import Kinematics

SAMPLES = 20000  # postures sampled per check (about 5 ms of forward kinematics for 7 joints)
MAX_SAMPLES = 10**7  # the most postures sampled (arrays of about 1 GB for 7 joints)
STARTS = 8  # descents started from the sampled postures closest to each point
ITERATIONS = 200  # damped least-squares iterations per descent
TOLERANCE = 1e-4  # a point is reached when the frame is this close [m]
_FD_STEP = 1e-7  # finite-difference step of the Jacobian [rad] or [m]
_UNBOUNDED_PRISMATIC = 1.0  # sampling range of an unbounded prismatic joint [m]


Robot = Kinematics
"""What the reachability checks need of a robot: chain, home, lower, upper (a KinematicTarget is one)."""


@dataclass(frozen=True, eq=False)
class Reachability:
    """Outcome of :func:`check_reachable`.

    Attributes:
        reachable: (N,) bool, whether a posture within the limits reaches each point.
        postures: (N, m) the best posture found for each point (within the limits).
        residual: (N,) distance from each point to the frame at that posture [m].
    """

    reachable: NDArray[np.bool_]
    postures: NDArray[np.float64]
    residual: NDArray[np.float64]


@njit(cache=True, nogil=True)
def positions(Q, body, out):  # type: ignore[no-untyped-def]
    """Frame positions of every posture row of Q (N, m) into out (N, n)."""
    for r in range(Q.shape[0]):
        body_forward(Q[r], body, out[r])


@njit(cache=True, nogil=True)
def _solve_small(A, b, x):  # type: ignore[no-untyped-def]
    """Solve A x = b for a small symmetric positive definite A (n <= 3) by Gaussian elimination."""
    n = b.shape[0]
    M = A.copy()
    v = b.copy()
    for c in range(n):
        p = c
        for r in range(c + 1, n):
            if abs(M[r, c]) > abs(M[p, c]):
                p = r
        if p != c:
            for k in range(n):
                M[c, k], M[p, k] = M[p, k], M[c, k]
            v[c], v[p] = v[p], v[c]
        for r in range(c + 1, n):
            f = M[r, c] / M[c, c]
            for k in range(c, n):
                M[r, k] -= f * M[c, k]
            v[r] -= f * v[c]
    for c in range(n - 1, -1, -1):
        s = v[c]
        for k in range(c + 1, n):
            s -= M[c, k] * x[k]
        x[c] = s / M[c, c]


@njit(cache=True, nogil=True)
def _descend(target, q, bounds, body, iterations, tolerance):  # type: ignore[no-untyped-def]
    """Projected Levenberg-Marquardt on ||target - f(q)|| from q (modified in place); returns the residual.

    ``bounds`` is (lower, upper), the joint limits (m,) each.
    """
    lower, upper = bounds
    m = q.shape[0]
    n = target.shape[0]
    x = np.empty(n)
    xp = np.empty(n)
    e = np.empty(n)
    J = np.empty((n, m))
    JJ = np.empty((n, n))
    y = np.empty(n)
    trial = np.empty(m)
    xt = np.empty(n)
    body_forward(q, body, x)
    err = 0.0
    for j in range(n):
        e[j] = target[j] - x[j]
        err += e[j] * e[j]
    err = math.sqrt(err)
    damping = 1e-2
    for _ in range(iterations):
        if err < tolerance:
            break
        for i in range(m):
            keep = q[i]
            q[i] = keep + 1e-7
            body_forward(q, body, xp)
            q[i] = keep
            for j in range(n):
                J[j, i] = (xp[j] - x[j]) / 1e-7
        improved = False
        for _attempt in range(8):
            for a in range(n):
                for b in range(n):
                    s = 0.0
                    for i in range(m):
                        s += J[a, i] * J[b, i]
                    JJ[a, b] = s
                JJ[a, a] += damping * damping
            _solve_small(JJ, e, y)
            for i in range(m):
                s = 0.0
                for j in range(n):
                    s += J[j, i] * y[j]
                trial[i] = min(max(q[i] + s, lower[i]), upper[i])
            body_forward(trial, body, xt)
            new = 0.0
            for j in range(n):
                d = target[j] - xt[j]
                new += d * d
            new = math.sqrt(new)
            if new < err:
                for i in range(m):
                    q[i] = trial[i]
                for j in range(n):
                    x[j] = xt[j]
                    e[j] = target[j] - xt[j]
                err = new
                damping = max(damping * 0.3, 1e-6)
                improved = True
                break
            damping *= 4.0
        if not improved:
            break
    return err


@njit(cache=True, nogil=True)
def _reach_all(points, starts, bounds, body, iterations, tolerance, best_q, residual):  # type: ignore[no-untyped-def]
    """For each point, descend from its start postures (points, S, m); keep the best posture and residual."""
    m = bounds[0].shape[0]
    q = np.empty(m)
    for p in range(points.shape[0]):
        residual[p] = np.inf
        for s in range(starts.shape[1]):
            for i in range(m):
                q[i] = starts[p, s, i]
            err = _descend(points[p], q, bounds, body, iterations, tolerance)
            if err < residual[p]:
                residual[p] = err
                for i in range(m):
                    best_q[p, i] = q[i]
            if err < tolerance:
                break


def sampling_bounds(robot: Robot) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per-joint sampling interval: the joint limits, ``[-pi, pi]`` or ``[-1, 1]`` m where unbounded."""
    kinds = np.asarray(robot.chain.kinds)
    order = np.empty_like(kinds)
    order[np.asarray(robot.chain.q_index)] = kinds  # kinds in the order of q
    free = np.where(order == PRISMATIC, _UNBOUNDED_PRISMATIC, math.pi)
    lower = np.where(np.isfinite(robot.lower), robot.lower, -free)
    upper = np.where(np.isfinite(robot.upper), robot.upper, free)
    return lower.astype(float), upper.astype(float)


def sample_positions(
    robot: Robot, samples: int = SAMPLES, seed: int | np.random.Generator = 0
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Uniform postures within the limits and their frame positions: (samples, m), (samples, n) [m]."""
    samples = check.positive_int("samples", samples, maximum=MAX_SAMPLES)
    rng = check.generator(seed)
    lo, hi = sampling_bounds(robot)
    Q = lo + (hi - lo) * rng.random((samples, lo.shape[0]))
    X = np.empty((samples, robot.chain.n_task))
    positions(Q, robot.chain.kernel(), X)
    return Q, X


def check_reachable(
    robot: Robot,
    points: ArrayLike,
    *,
    seed: int | np.random.Generator = 0,
    samples: int = SAMPLES,
    tolerance: float = TOLERANCE,
    sampled: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
) -> Reachability:
    """Which points a posture within the joint limits reaches (see the module docstring).

    Args:
        robot: anything with chain, home, lower and upper (:class:`Robot`), e.g. a
            :class:`~gb_pin.robot.target.KinematicTarget`.
        points: (N, n) points on the robot's task axes [m].
        seed: seed of the posture sampling; same seed, same answer.
        samples: postures sampled.
        tolerance: a point counts as reached when the frame is this close [m].
        sampled: postures and positions from :func:`sample_positions`, to reuse them.

    Returns:
        A :class:`Reachability` (per point: reachable, best posture, residual).
    """
    chain = robot.chain
    X = check.points("points", points, chain.n_task)
    tolerance = check.positive_float("tolerance", tolerance)
    Q, P = sample_positions(robot, samples, seed) if sampled is None else sampled
    lower = np.ascontiguousarray(robot.lower, dtype=float)
    upper = np.ascontiguousarray(robot.upper, dtype=float)
    count = min(STARTS, Q.shape[0])
    # The home posture first (it is inside the limits), then the nearest samples.
    d2 = ((X[:, None, :] - P[None, :, :]) ** 2).sum(axis=2)
    nearest = np.argsort(d2, axis=1)[:, : count - 1]
    starts = np.empty((X.shape[0], count, Q.shape[1]))
    starts[:, 0] = np.clip(robot.home, lower, upper)
    starts[:, 1:] = Q[nearest]
    best = np.empty((X.shape[0], Q.shape[1]))
    residual = np.empty(X.shape[0])
    _reach_all(X, starts, (lower, upper), chain.kernel(), ITERATIONS, tolerance, best, residual)
    return Reachability(reachable=residual < tolerance, postures=best, residual=residual)


def beyond_reach(
    chain: KinematicChain, lower: ArrayLike, upper: ArrayLike, points: ArrayLike
) -> NDArray[np.bool_]:
    """Which points are certainly unreachable: farther from the chain's fixed root than the arm's length.

    The root is the first moved joint on the path from the world to the frame (it
    does not move); the length bound is the sum of the joint-to-joint and
    joint-to-frame distances on that path plus the stroke of every prismatic joint
    on it. Distances on a subset of the axes are at most the 3-D distances, so the
    test holds for any task axes. Infinite strokes give no bound (nothing flagged), nor
    does a stacked task (orientations, several frames).

    Args:
        chain: the robot's compiled kinematics.
        lower: (m,) lower joint limits.
        upper: (m,) upper joint limits.
        points: (N, n) points on the chain's task axes [m].

    Returns:
        (N,) bool, True where the point is farther than the bound.
    """
    X = np.atleast_2d(np.asarray(points, dtype=float))
    if chain.components is not None:  # a stacked task: no cheap bound (check_reachable decides)
        return np.zeros(X.shape[0], dtype=bool)
    lo = np.asarray(lower, dtype=float)
    hi = np.asarray(upper, dtype=float)
    path = []
    j = int(chain.frame_parent)
    while j >= 0:
        path.append(j)
        j = int(chain.parents[j])
    if not path:
        root = np.asarray(chain.frame_translation, dtype=float)
        bound = 0.0
    else:
        root = np.asarray(chain.translations[path[-1]], dtype=float)
        bound = float(np.linalg.norm(chain.frame_translation))
        bound += sum(float(np.linalg.norm(chain.translations[i])) for i in path[:-1])
        for i in path:
            if chain.kinds[i] == PRISMATIC:
                a = int(chain.q_index[i])
                bound += max(abs(lo[a]), abs(hi[a]))
    if not math.isfinite(bound):
        return np.zeros(X.shape[0], dtype=bool)
    with np.errstate(over="ignore", invalid="ignore"):  # absurdly far points: an inf distance, flagged
        distance = np.linalg.norm(X - root[np.asarray(chain.task_axes)], axis=1)
    return np.asarray(distance > bound * (1.0 + 1e-9) + 1e-9)
