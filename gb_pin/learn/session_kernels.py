"""The compiled halves of one babbling step, for runs whose robot lies outside compiled code.

:func:`gb_pin.learn.loop.babble_loop` runs a whole step, forward kinematics included. A robot
on hardware, in a simulator or given as a Python function cannot be called from there, so an
ask/tell run (:mod:`gb_pin.learn.asktell`) splits each step at the forward kinematics (Eq. 1):
:func:`ask_step` chooses the movement if one is due and computes the clipped posture q into
``run.motion.q``; the caller executes it and writes the observed position into
``run.motion.x``; :func:`tell_step` then weights, learns and walks the noise. The two halves
perform exactly the operations of the loop's step, in the same order, on the same arrays, so a
run driven by the chain's own forward kinematics is bit-identical to ``babble_loop``'s
(tests/test_session.py). Every state between the halves is in the run's arrays and counters.
"""

from __future__ import annotations

import math

from gb_pin._jit import njit
from gb_pin.learn.exploration import noise_add, noise_walk
from gb_pin.learn.layout import (
    DONE,
    GOAL,
    KIND,
    MAX_POSTURE,
    MISSING,
    MOVEMENT_DONE,
    MOVEMENTS,
    NEED_CAPACITY,
    NEED_GOAL,
    NEED_RECORD_CAPACITY,
    NONE,
    NOT_FINITE,
    PROTOTYPES,
    REACHED,
    RECORDED,
    STEP,
    STEP_DONE,
    STEPS,
)
from gb_pin.learn.llm_kernels import llm_learn, llm_predict
from gb_pin.learn.loop import begin_movement, end_movement, evaluate_schedule, limit_step, record_step
from gb_pin.learn.weighting import direction_weight, efficiency_weight


@njit(cache=True, nogil=True, error_model="numpy")
def evaluate_due(learner, robot, run, evaluation):  # type: ignore[no-untyped-def]
    """E^X and D^home at the schedule entries due at the current movement count (compiled body).

    Returns True when E^X fell to the run's stopping level (``evaluation.until``).
    """
    return evaluate_schedule(learner, robot, run, evaluation, math.inf) == REACHED


@njit(cache=True, nogil=True, error_model="numpy")
def ask_step(rng, learner, limits, run, goals, rec):  # type: ignore[no-untyped-def]
    """The first half of a step: the next posture q (clipped to the limits) into ``run.motion.q``.

    Between movements it first chooses the next one (home return or goal, consuming the random
    stream as the loop does). The caller evaluates E^X before, when due.

    Args:
        rng: numpy Generator.
        learner: :class:`~gb_pin.learn.layout.Learner`.
        limits: :class:`~gb_pin.learn.layout.Limits`.
        run: :class:`~gb_pin.learn.layout.Run` (its motion buffers persist between the halves).
        goals: :class:`~gb_pin.learn.goals.base.GoalArrays`.
        rec: :class:`~gb_pin.learn.layout.Recorder`.

    Returns:
        DONE (q is ready), NEED_GOAL, NEED_CAPACITY, NEED_RECORD_CAPACITY (do it and call
        again: nothing of the step has happened) or NOT_FINITE.
    """
    counters = run.counters
    if counters[KIND] == NONE and not begin_movement(rng, learner.hyper.p_home, limits, run, goals):
        return NEED_GOAL
    mo = run.motion
    q, target = mo.q, mo.target
    lm = learner.lm
    lower, upper = limits.lower, limits.upper
    if counters[PROTOTYPES] >= lm.prototypes.shape[1]:
        return NEED_CAPACITY
    recording = rec.first <= counters[MOVEMENTS] < rec.last and (counters[STEPS] + 1) % rec.every == 0
    if recording and counters[RECORDED] >= rec.step.shape[0]:
        return NEED_RECORD_CAPACITY
    L = learner.hyper.path_length
    step = counters[STEP] + 1
    a = (L - step) / L
    bw = step / L
    if counters[KIND] == GOAL:
        for j in range(target.shape[0]):
            target[j] = a * mo.path_start[j] + bw * mo.path_end[j]
        llm_predict(target, lm, counters[PROTOTYPES], q)
        noise_add(learner.noise.A, learner.noise.b, target, q)
    else:
        for i in range(q.shape[0]):
            q[i] = a * mo.q_start[i] + bw * mo.q_end[i]
    finite = True
    for i in range(q.shape[0]):
        if not (abs(q[i]) <= MAX_POSTURE):
            finite = False
        q[i] = min(max(q[i], lower[i]), upper[i])
    if not finite:
        return NOT_FINITE
    if limits.max_step < math.inf:
        limit_step(q, mo.q_exec, limits.max_step)
    return DONE


@njit(cache=True, nogil=True, error_model="numpy")
def tell_step(rng, learner, limits, run, rec, observed):  # type: ignore[no-untyped-def]
    """The second half of a step, with the observed position in ``run.motion.x`` (Eqs. 4-6, 8).

    ``observed`` False: the reading is missing; nothing is learnt from the step, the noise
    walks and the movement goes on (as the loop does with a sensor that lost a reading).

    Returns:
        MOVEMENT_DONE when the step completed the movement, else STEP_DONE.

    The operations are the loop's (``_movement``), written out again: the loop takes its arrays
    out of their structures once per movement, which a shared per-step helper would not allow
    at the same cost; tests/test_session.py holds both equal bit for bit. (Measured: the two
    halves shared with the loop as ``inline="always"`` helpers made the loop's step 0.6-0.8 us
    slower, 1.15-1.57x on planar5, planar50, talos_left_arm and panda; as called functions
    1.2-1.6x; and a recording call nested two inlined levels deep lost its writes under numba's
    inliner, which the fingerprint test caught.)
    """
    counters = run.counters
    mo = run.motion
    q, x, target = mo.q, mo.x, mo.target
    q_prev, x_prev, target_prev, q_exec = mo.q_prev, mo.x_prev, mo.target_prev, mo.q_exec
    hyper = learner.hyper
    lm = learner.lm
    kind = counters[KIND]
    m = q.shape[0]
    n = x.shape[0]
    L = hyper.path_length
    step = counters[STEP] + 1
    recording = rec.first <= counters[MOVEMENTS] < rec.last and (counters[STEPS] + 1) % rec.every == 0
    if recording:
        record_step(counters, rec, q, x, target, kind, observed)
    if observed:
        w = efficiency_weight(x, x_prev, q, q_prev)
        if kind == GOAL:
            w *= direction_weight(target, target_prev, x, x_prev)
        counters[PROTOTYPES] = llm_learn(
            x, q, w, hyper.learning_rate, lm, counters[PROTOTYPES], learner.scratch
        )
    else:
        counters[MISSING] += 1
    noise_walk(rng, hyper.sigma, hyper.sigma_delta, learner.noise.A, learner.noise.b)
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
        end_movement(counters, mo, run.reach, kind, observed, learner, limits.lower, limits.upper)
        return MOVEMENT_DONE
    return STEP_DONE


@njit(nogil=True, error_model="numpy")
def kernel_movement(rng, learner, limits, run, goals, rec, forward):  # type: ignore[no-untyped-def]
    """The rest of the current movement with a compiled forward model ``forward(q, x)`` (writes x in place).

    Not cached on disk: numba compiles it once per process and forward function.

    Returns:
        MOVEMENT_DONE, or a status of :func:`ask_step` other than DONE (handle it and call again).
    """
    while True:
        status = ask_step(rng, learner, limits, run, goals, rec)
        if status != DONE:
            return status
        forward(run.motion.q, run.motion.x)
        if tell_step(rng, learner, limits, run, rec, True) == MOVEMENT_DONE:
            return MOVEMENT_DONE
