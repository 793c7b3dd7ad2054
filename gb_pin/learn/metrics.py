"""Evaluation measures of the paper (Sec. III): E^X (Eq. 9), D^home (Eq. 10), S(Q, e) (Eq. 11).

    E^X_r    = 1/N sum_i ||x*_i - f(g(x*_i, theta_rL))||      accuracy   [m]
    D^home_r = 1/N sum_i ||q_home - g(x*_i, theta_rL)||       comfort    [rad]

With joint limits, f is applied to the posture clipped to the limits (what the
robot would execute); D^home uses g itself, as in Eq. 10.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin._jit import NO_REFCOUNT, njit
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.body.chain import body_forward
from gb_pin.learn.body.task import add_component_errors
from gb_pin.learn.clock import monotonic
from gb_pin.learn.llm_kernels import llm_predict


@njit(
    cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT
)  # not inlined: called rarely, kept out of the step loop
def evaluate_model(evaluation, c, robot, lm, K, motion, deadline):  # type: ignore[no-untyped-def]
    """(E^X, D^home) of the current inverse estimate over ``targets`` (N, n) (Eqs. 9, 10), in slices.

    For a stacked task, ``components`` (C,) receives E^X split by component (mean over the
    targets of ||x*[r_c] - x[r_c]|| / s_c: [m] for positions, [deg] for rotations); it is
    empty for the paper's position task.

    The sums run over the targets in order; every 256 targets, once the monotonic clock passes
    ``deadline``, the evaluation stops and keeps where it was in ``progress`` (next target, the sums
    of E^X and D^home so far); the next call goes on from there, so the result is the one of an
    uninterrupted evaluation, bit for bit.

    Args:
        evaluation: :class:`~gb_pin.learn.layout.Evaluation`: the targets (N, n) [m], ``components``
            (T, C) whose row ``c`` receives E^X per component (C = 0 for the paper's task),
            ``progress`` (an evaluation under way, all 0 when none: next target, the two sums) and
            ``clock`` (scratch of the clock).
        c: the schedule entry evaluated.
        robot: :class:`~gb_pin.learn.layout.Robot` (limits, the compiled forward kinematics).
        lm: :class:`~gb_pin.learn.llm_kernels.MapArrays` of the estimate.
        K: prototypes in use.
        motion: :class:`~gb_pin.learn.layout.Motion`, whose ``q`` (m,) and ``x`` (n,) are scratch.
        deadline: when to stop [s on the monotonic clock] (inf: never).

    Returns:
        (finished, E^X, D^home); while not finished, E^X and D^home are NaN.
    """
    targets, components = evaluation.targets, evaluation.components[c]
    progress, clock = evaluation.progress, evaluation.clock
    limits, body, q, x = robot.limits, robot.body, motion.q, motion.x
    home, lower, upper = limits.home, limits.lower, limits.upper
    m = home.shape[0]
    n = targets.shape[1]
    start = int(progress[0])
    error = progress[1]
    distance = progress[2]
    if start == 0:
        for c in range(components.shape[0]):
            components[c] = 0.0
    count = targets.shape[0]
    block = start
    while block < count:
        if block > start and deadline < math.inf and monotonic(clock) >= deadline:
            progress[0] = block
            progress[1] = error
            progress[2] = distance
            return False, math.nan, math.nan
        end = min(count, (block // 256 + 1) * 256)  # blocks of 256 targets, the clock read between
        for r in range(block, end):
            xs = targets[r]
            llm_predict(xs, lm, K, q)
            d = 0.0
            for i in range(m):
                v = home[i] - q[i]
                d += v * v
                q[i] = min(max(q[i], lower[i]), upper[i])
            distance += math.sqrt(d)
            body_forward(q, body, x)
            e = 0.0
            for j in range(n):
                v = xs[j] - x[j]
                e += v * v
            error += math.sqrt(e)
            add_component_errors(body.task, xs, x, components)
        block = end
    progress[0] = 0.0
    progress[1] = 0.0
    progress[2] = 0.0
    for c in range(components.shape[0]):
        components[c] /= count
    return True, error / count, distance / count


MAX_SCHEDULE = 10**7
"""The most entries of an evaluation schedule built by :func:`evaluation_schedule` (80 MB)."""


@njit(cache=True, nogil=True, error_model="numpy")
def reach_median(ring, count):  # type: ignore[no-untyped-def]
    """The median of the last min(count, W) reach errors of the ring (W,) [m]; NaN before any.

    The free measure of progress: what the robot's own observations say of its reaching, at the
    end of each goal-directed movement, with no extra movement (sensor noise included).
    """
    k = min(count, ring.shape[0])
    if k == 0:
        return math.nan
    # np.sort's order (NaNs last) by insertion sort: the window is small (50), and np.sort would
    # compile numba's quicksort, a sixth of a cold start's compile time, for nothing faster here.
    values = ring[:k].copy()
    for i in range(1, k):
        v = values[i]
        j = i - 1
        while j >= 0 and (values[j] > v or (values[j] != values[j] and v == v)):
            values[j + 1] = values[j]
            j -= 1
        values[j + 1] = v
    if k % 2 == 1:
        return values[k // 2]
    return 0.5 * (values[k // 2 - 1] + values[k // 2])


def evaluation_schedule(movements: int, dense_until: int = 1000, per_decade: int = 50) -> NDArray[np.int64]:
    """Movement counts at which E^X and D^home are recorded.

    Every count 0..min(movements, dense_until), then ``per_decade`` log-spaced
    counts per decade up to ``movements`` (always included).

    Args:
        movements: total number of movements of the run.
        dense_until: last movement count recorded after every movement.
        per_decade: log-spaced points per factor of 10 beyond ``dense_until``.
    """
    movements = check.movements("movements", movements, minimum=1)
    dense_until = check.positive_int("dense_until", dense_until, minimum=0, maximum=MAX_SCHEDULE)
    per_decade = check.positive_int("per_decade", per_decade, maximum=MAX_SCHEDULE // 12)
    dense = np.arange(0, min(movements, dense_until) + 1, dtype=np.int64)
    if movements <= dense_until:
        return dense
    start = max(dense_until, 1)
    count = math.ceil(per_decade * math.log10(movements / start)) + 1
    sparse = np.unique(np.round(np.geomspace(start, movements, count)).astype(np.int64))
    return np.unique(np.concatenate([dense, sparse, [movements]]))


def speed(movements: ArrayLike, errors: ArrayLike, quantile: float, level: float) -> int | None:
    """S(Q, e) of Eq. 11: the first recorded movement count at which a fraction >= Q of trials has E^X <= e.

    Args:
        movements: (T,) recorded movement counts.
        errors: (trials, T) E^X of each trial.
        quantile: Q in (0, 1].
        level: e [m].

    Returns:
        The movement count, or None if the fraction is never reached.
    """
    mv = np.asarray(movements)
    err = np.atleast_2d(np.asarray(errors, dtype=float))
    if mv.ndim != 1 or err.ndim != 2 or err.shape[1] != mv.shape[0]:
        raise InvalidArgumentError(
            f"errors must have shape (trials, {mv.shape[0] if mv.ndim == 1 else '?'}) to match movements "
            f"of shape {mv.shape}, got {err.shape}"
        )
    if not 0.0 < quantile <= 1.0:
        raise InvalidArgumentError(f"quantile must be in (0, 1], got {quantile!r}")
    fraction = np.mean(err <= level, axis=0)
    hit = np.flatnonzero(fraction >= quantile)
    return int(mv[hit[0]]) if hit.size else None
