"""The compiled online goal-babbling loop (paper Sec. II): one call runs many movements.

Everything a step needs lives in preallocated arrays, passed as the named structures of
:mod:`gb_pin.learn.layout`; the loop allocates nothing and creates no Python object per
step. State that must survive between calls (and be checkpointed) is in the counters and
the arrays of the motion, the map, the noise and the goal generator.
"""

from __future__ import annotations

import math

import numpy as np

from gb_pin._jit import NO_REFCOUNT, njit
from gb_pin.learn.body.chain import body_forward
from gb_pin.learn.clock import monotonic
from gb_pin.learn.exploration import noise_add, noise_walk
from gb_pin.learn.goals.kernel import goal_feedback, is_motor, motor_posture, next_goal, snap_start
from gb_pin.learn.layout import (
    BABBLE,
    DONE,
    EVAL_CURSOR,
    GOAL,
    HOME,
    KIND,
    LAST_KIND,
    MAX_POSTURE,
    MISSING,
    MOVEMENTS,
    NEED_CAPACITY,
    NEED_GOAL,
    NEED_RECORD_CAPACITY,
    NONE,
    NOT_FINITE,
    PROTOTYPES,
    REACHED,
    REACHES,
    RECORDED,
    SLICE,
    STEP,
    STEPS,
)
from gb_pin.learn.llm_kernels import llm_jacobian, llm_learn, llm_predict
from gb_pin.learn.metrics import evaluate_model, reach_median
from gb_pin.learn.sensor import observe
from gb_pin.learn.weighting import direction_weight, efficiency_weight


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)  # no reference counting: see below
def babble_loop(rng, stop, learner, robot, run, goals, monitor):  # type: ignore[no-untyped-def]
    """Run goal babbling until ``stop`` movements are complete.

    Args:
        rng: numpy Generator (its bit generator is advanced in place).
        stop: movement count at which to return.
        learner: :class:`~gb_pin.learn.layout.Learner` (hyperparameters, map, noise).
        robot: :class:`~gb_pin.learn.layout.Robot` (limits, compiled forward kinematics).
        run: :class:`~gb_pin.learn.layout.Run` (motion and counters).
        goals: :class:`~gb_pin.learn.goals.base.GoalArrays` of the goal generator.
        monitor: :class:`~gb_pin.learn.layout.Monitor` (evaluation schedule, recording).

    Returns:
        DONE; NEED_CAPACITY (grow the map and call again); NEED_RECORD_CAPACITY (grow the
        recording buffers and call again); NEED_GOAL (write the goal into
        ``run.motion.path_end`` and call again); REACHED (E^X fell to ``evaluation.until``:
        the run is over); SLICE (``evaluation.seconds`` ran out, between movements or inside an
        evaluation: call again to go on, bit-identical); or NOT_FINITE.

    Compiled without reference counting (:data:`gb_pin._jit.NO_REFCOUNT`): the loop allocates
    nothing and keeps no array (its callees that allocate count their own, and none returns an
    array to it). numba's counting of every array it passes on put 1195 calls to the counter in its
    module (239 without, those of the callees) and took 3.45 s of CPU to compile the loop's own
    part against 2.76 s without (README, "The cold first run").
    """
    counters = run.counters
    evaluation = monitor.evaluation
    start_slice(evaluation, counters[MOVEMENTS])
    while True:
        if counters[KIND] == NONE:
            status = evaluate_schedule(learner, robot, run, evaluation, evaluation.progress[DEADLINE])
            if status != DONE:
                return status  # REACHED, or SLICE inside an evaluation
            if counters[MOVEMENTS] >= stop:
                return DONE
            if slice_over(evaluation, counters[MOVEMENTS]):
                return SLICE
            if not begin_movement(rng, learner.hyper.p_home, robot.limits, run, goals):
                return NEED_GOAL
        status = _movement(rng, learner, robot, run, monitor.recorder)
        if status != DONE:
            return status


DEADLINE = 3  # evaluation.progress[DEADLINE]: when this call's slice ends [s, monotonic clock]
FIRST = 4  # evaluation.progress[FIRST]: the movement count when this call began


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def start_slice(evaluation, movements):  # type: ignore[no-untyped-def]
    """Note when this call of the loop must return (``evaluation.seconds`` from now) and where it began.

    The slice's state is kept in ``evaluation.progress`` rather than in the loop's own variables,
    which would stay live across the inlined step loop.
    """
    p = evaluation.progress
    sliced = evaluation.seconds < math.inf
    p[DEADLINE] = monotonic(evaluation.clock) + evaluation.seconds if sliced else math.inf
    p[FIRST] = movements


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def slice_over(evaluation, movements):  # type: ignore[no-untyped-def]
    """Whether the slice is up: after at least one movement of this call, every 8th, by the clock."""
    p = evaluation.progress
    return (
        p[DEADLINE] < math.inf
        and movements > p[FIRST]
        and movements % 8 == 0
        and monotonic(evaluation.clock) >= p[DEADLINE]
    )


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def evaluate_schedule(learner, robot, run, evaluation, deadline):  # type: ignore[no-untyped-def]
    """E^X and D^home at every schedule entry equal to the movement count r (Eqs. 9, 10).

    Returns REACHED when one of them found E^X <= ``evaluation.until`` (the stopping level),
    SLICE when the clock passed ``deadline`` inside an evaluation (the cursor stays on it, its
    progress in ``evaluation.progress``: the next call goes on with it), else DONE.
    """
    counters = run.counters
    reached = False
    r = counters[MOVEMENTS]
    c = counters[EVAL_CURSOR]
    at = evaluation.at
    while c < at.shape[0] and at[c] <= r:
        if at[c] == r:
            finished, e, d = evaluate_model(
                evaluation, c, robot, learner.lm, counters[PROTOTYPES], run.motion,
                math.inf if reached else deadline,
            )  # fmt: skip
            if not finished:
                counters[EVAL_CURSOR] = c
                return SLICE
            evaluation.errors[c] = e
            evaluation.distances[c] = d
            evaluation.reach[c] = reach_median(run.reach, counters[REACHES])
            reached = reached or e <= evaluation.until
        c += 1
    counters[EVAL_CURSOR] = c
    return REACHED if reached else DONE


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def begin_movement(rng, p_home, limits, run, goals):  # type: ignore[no-untyped-def]
    """Choose the next movement: a home return (Eq. 7), a goal-directed path (Eq. 3) or motor babbling.

    After a goal-directed movement the goal generator learns how far the arm missed its goal,
    and the arm returns home with probability p_home; the first movement and the one after a
    home return are goal-directed (Sec. II-A). A goal path starts at the last goal, or where
    the arm got to if it missed by more than the generator's snap threshold. Returns False
    when a Python goal generator must write the goal into ``path_end``.
    """
    counters = run.counters
    mo = run.motion
    counters[STEP] = 0
    after_goal = counters[LAST_KIND] == GOAL
    if after_goal:
        goal_feedback(goals, mo.path_end, mo.x_prev)
    if after_goal and rng.random() < p_home:
        counters[KIND] = HOME
        for i in range(mo.q_start.shape[0]):
            mo.q_start[i] = mo.q_exec[i]
            mo.q_end[i] = limits.home[i]
        return True
    if is_motor(goals):
        counters[KIND] = BABBLE
        for i in range(mo.q_start.shape[0]):
            mo.q_start[i] = mo.q_exec[i]
        motor_posture(goals, rng, limits, mo.q_end)
        return True
    counters[KIND] = GOAL
    if after_goal and snap_start(goals, mo.path_end, mo.x_prev):
        # The arm lags its last goal: the new path starts where it got to. (Eq. 4's x*_{t-1} stays
        # the last target: resetting it too measured worse, docs/GOALS.md.)
        for j in range(mo.path_start.shape[0]):
            mo.path_start[j] = mo.x_prev[j]
    else:
        for j in range(mo.path_start.shape[0]):
            mo.path_start[j] = mo.path_end[j]
    return next_goal(goals, rng, mo.path_start, mo.path_end)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _movement(rng, learner, robot, run, rec):  # type: ignore[no-untyped-def]
    """The remaining steps of the current movement (Eqs. 1-7); DONE when it is complete.

    Returns early with NEED_CAPACITY / NEED_RECORD_CAPACITY when a buffer is full (the step is
    then redone after the caller grew it) or NOT_FINITE when the estimate diverged. The arrays
    are taken out of their structures once per movement, not once per step.
    """
    counters = run.counters
    mo = run.motion
    q, x, target = mo.q, mo.x, mo.target
    q_prev, q_start, q_end, q_exec = mo.q_prev, mo.q_start, mo.q_end, mo.q_exec
    x_prev, target_prev = mo.x_prev, mo.target_prev
    path_start, path_end = mo.path_start, mo.path_end
    hyper = learner.hyper
    lm, scratch = learner.lm, learner.scratch
    A, b = learner.noise.A, learner.noise.b
    lower, upper = robot.limits.lower, robot.limits.upper
    max_step = robot.limits.max_step
    limited = max_step < math.inf
    body, sensor = robot.body, robot.sensor
    eta, sigma, sigma_delta = hyper.learning_rate, hyper.sigma, hyper.sigma_delta
    capacity = lm.prototypes.shape[1]
    L = hyper.path_length
    m = q.shape[0]
    n = x.shape[0]
    kind = counters[KIND]
    while True:
        if counters[PROTOTYPES] >= capacity:
            return NEED_CAPACITY
        recording = rec.first <= counters[MOVEMENTS] < rec.last and (counters[STEPS] + 1) % rec.every == 0
        if recording and counters[RECORDED] >= rec.step.shape[0]:
            return NEED_RECORD_CAPACITY
        step = counters[STEP] + 1
        a = (L - step) / L
        bw = step / L
        if kind == GOAL:
            # Eq. 3: linear target path; Eq. 2: q_t = g(x*_t) + E_t(x*_t).
            for j in range(n):
                target[j] = a * path_start[j] + bw * path_end[j]
            llm_predict(target, lm, counters[PROTOTYPES], q)
            noise_add(A, b, target, q)
        else:
            # Eq. 7: linear path in joint space from the last posture to home (or, motor
            # babbling, to a random posture).
            for i in range(m):
                q[i] = a * q_start[i] + bw * q_end[i]
        finite = True
        for i in range(m):
            # A posture beyond 1e6 (rad or m) means the estimate has exploded.
            if not (abs(q[i]) <= MAX_POSTURE):
                finite = False
            q[i] = min(max(q[i], lower[i]), upper[i])  # the robot executes the clipped posture
        if not finite:
            return NOT_FINITE
        if limited:
            limit_step(q, q_exec, max_step)
        body_forward(q, body, x)  # Eq. 1
        observed = observe(sensor, x)  # the reading: x itself without a sensor (the paper's)
        if recording:
            record_step(counters, rec, q, x, target, kind, observed)
        if observed:
            w = efficiency_weight(x, x_prev, q, q_prev)  # Eq. 5
            if kind == GOAL:
                w *= direction_weight(target, target_prev, x, x_prev)  # Eqs. 4, 6
            counters[PROTOTYPES] = llm_learn(x, q, w, eta, lm, counters[PROTOTYPES], scratch)
        else:
            counters[MISSING] += 1
        noise_walk(rng, sigma, sigma_delta, A, b)
        for i in range(m):
            q_exec[i] = q[i]
            if observed:
                q_prev[i] = q[i]
        if observed:
            for j in range(n):
                x_prev[j] = x[j]
                if kind == GOAL:
                    target_prev[j] = target[j]
        counters[STEP] = step
        counters[STEPS] += 1
        if step == L:
            end_movement(counters, mo, run.reach, kind, observed, learner, lower, upper)
            return DONE


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def limit_step(q, q_exec, max_step):  # type: ignore[no-untyped-def]
    """No joint moves farther than ``max_step`` from the last executed posture (in place)."""
    for i in range(q.shape[0]):
        q[i] = min(max(q[i], q_exec[i] - max_step), q_exec[i] + max_step)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def end_movement(counters, mo, reach, kind, observed, learner, lower, upper):  # type: ignore[no-untyped-def]
    """Close the movement: after a joint-space one the next path starts where the arm was last seen.

    At the end of a goal-directed movement whose last reading arrived, its reach error without the
    exploration noise's share (:func:`noise_free_reach`) goes to the reach ring (the free measure of
    progress, no extra movement).
    """
    n = mo.x_prev.shape[0]
    if kind != GOAL:
        # The next goal path starts at f(q_home), which is where the arm is.
        for j in range(n):
            mo.path_end[j] = mo.x_prev[j]
            mo.target_prev[j] = mo.x_prev[j]
    elif observed:
        reach[counters[REACHES] % reach.shape[0]] = noise_free_reach(
            mo.path_end, mo.x_prev, mo.q_exec, learner, counters[PROTOTYPES], lower, upper
        )
        counters[REACHES] += 1
    counters[LAST_KIND] = kind
    counters[KIND] = NONE
    counters[MOVEMENTS] += 1


@njit(cache=True, nogil=True, error_model="numpy")
def noise_free_reach(goal, reached, q_exec, learner, K, lower, upper):  # type: ignore[no-untyped-def]
    """||x_L - W^+ delta - x*||: the reach error of the last step less the exploration noise's share.

    The arm executed q_L = clip(g(x*) + E(x*)) and was seen at x_L; the learner's own estimate of
    what the noise-free posture clip(g(x*)) reaches is x_L - W^+ (q_L - clip(g(x*))), W = dg/dx at
    the goal (the learned Jacobian, :func:`~gb_pin.learn.llm_kernels.llm_jacobian`; W^+ its
    pseudo-inverse, (W^T W)^-1 W^T, which inverts f's Jacobian where the map is right). Only
    readings and the learner's state are used, so a session on hardware measures it too. Measured
    on the mis-calibrated SO-101 (docs/WORKSPACE.md): the observed end ||x_L - x*|| stayed at
    15-35 mm, the exploration's, while E^X fell from 13 to 1.2 mm; this follows E^X down.
    Falls back to ||x_L - x*|| where W^T W is singular. Allocates two small arrays per movement.
    """
    scratch = learner.scratch
    llm_jacobian(goal, learner.lm, K, scratch)
    W, g, d = scratch.J, scratch.g, scratch.y
    m, n = W.shape
    for i in range(m):
        d[i] = q_exec[i] - min(max(g[i], lower[i]), upper[i])
    G = np.empty((n, n + 1))  # [W^T W | W^T d], then its Cholesky factor and the solution
    trace = 0.0
    for a in range(n):
        for c in range(a, n):
            v = 0.0
            for i in range(m):
                v += W[i, a] * W[i, c]
            G[a, c] = v
            G[c, a] = v
        v = 0.0
        for i in range(m):
            v += W[i, a] * d[i]
        G[a, n] = v
        trace += G[a, a]
    usable = trace > 0.0 and math.isfinite(trace)
    for a in range(n):  # Cholesky: G = R^T R, R in the upper triangle
        if not usable:
            break
        v = G[a, a]
        for k in range(a):
            v -= G[k, a] * G[k, a]
        if not v > 1e-12 * trace:
            usable = False
            break
        G[a, a] = math.sqrt(v)
        for c in range(a + 1, n):
            v = G[a, c]
            for k in range(a):
                v -= G[k, a] * G[k, c]
            G[a, c] = v / G[a, a]
    z = np.zeros(n)
    if usable:
        for a in range(n):  # R^T y = W^T d
            v = G[a, n]
            for k in range(a):
                v -= G[k, a] * z[k]
            z[a] = v / G[a, a]
        for a in range(n - 1, -1, -1):  # R z = y
            v = z[a]
            for k in range(a + 1, n):
                v -= G[a, k] * z[k]
            z[a] = v / G[a, a]
    e = 0.0
    for j in range(n):
        v = reached[j] - z[j] - goal[j]
        e += v * v
    return math.sqrt(e)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def record_step(counters, rec, q, x, target, kind, observed):  # type: ignore[no-untyped-def]
    """Write this step to the recording buffers (target NaN during home returns, position NaN if missing)."""
    c = counters[RECORDED]
    rec.step[c] = counters[STEPS] + 1
    rec.movement[c] = counters[MOVEMENTS]
    for i in range(q.shape[0]):
        rec.posture[c, i] = q[i]
    for j in range(x.shape[0]):
        rec.target[c, j] = target[j] if kind == GOAL else math.nan
        rec.position[c, j] = x[j] if observed else math.nan
    counters[RECORDED] = c + 1
