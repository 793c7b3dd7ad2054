"""The compiled online goal-babbling loop (paper Sec. II): one call runs many movements.

Everything a step needs lives in preallocated arrays; the loop allocates nothing and
creates no Python object per step. State that must survive between calls (and be
checkpointed) is in ``istate`` and the float arrays of ``fstate``.
"""

from __future__ import annotations

import math

from numba import njit

from gb_pin.chain import chain_position
from gb_pin.exploration import noise_add, noise_walk
from gb_pin.llm import llm_learn, llm_predict
from gb_pin.metrics import evaluate_model
from gb_pin.weighting import direction_weight, efficiency_weight

# Indices into istate.
MOVEMENTS = 0  # r: completed movements, home returns included
STEP = 1  # l: steps done in the current movement (0..L)
KIND = 2  # kind of the current movement, NONE between movements
LAST_KIND = 3  # kind of the previous movement
PROTOTYPES = 4  # K
EVAL_CURSOR = 5  # next entry of the evaluation schedule
STEPS = 6  # total steps t
RECORDED = 7  # entries written to the recording buffers
ISTATE_SIZE = 8

NONE = -1
GOAL = 0
HOME = 1

# Status codes returned by babble_loop.
DONE = 0
NEED_CAPACITY = 1
NOT_FINITE = 2
NEED_RECORD_CAPACITY = 3

MAX_POSTURE = 1e6


@njit(cache=True, nogil=True, error_model="numpy")
def babble_loop(  # type: ignore[no-untyped-def]
    rng,
    stop,
    params,
    problem,
    chain,
    model,
    noise,
    fstate,
    istate,
    scratch,
    schedule,
    evaluation,
    record,
):
    """Run goal babbling until ``stop`` movements are complete.

    Args:
        rng: numpy Generator (its bit generator is advanced in place).
        stop: movement count at which to return.
        params: (learning_rate, sigma, sigma_delta, radius, path_length, p_home).
        problem: (home (m,), lower (m,), upper (m,), targets (N, n)).
        chain: KinematicChain.as_tuple().
        model: local-linear map storage (P, W, O).
        noise: (A, b) of Eq. 8.
        fstate: (q_prev, q_start, x_prev, target_prev, path_start, path_end).
        istate: int64 counters, see the module's index constants.
        scratch: (q, x, target, act, g, y, J, rot_ws, pos_ws).
        schedule: (movement counts to evaluate at, eval targets (N', n)).
        evaluation: (errors, home distances) output arrays, one entry per schedule count.
        record: (every, first, last, step, movement, posture, target, position): every
            ``every``-th step of movements first <= r < last is written to the buffers
            (target NaN during home returns).

    Returns:
        DONE, NEED_CAPACITY (grow P, W, O and call again), NEED_RECORD_CAPACITY
        (grow the recording buffers and call again) or NOT_FINITE.
    """
    eta, sigma, sigma_delta, radius, path_length, p_home = params
    home, lower, upper, targets = problem
    P, W, O = model
    A, b = noise
    q_prev, q_start, x_prev, target_prev, path_start, path_end = fstate
    q, x, target, act, g, y, J, rot_ws, pos_ws = scratch
    eval_at, eval_targets = schedule
    errors, distances = evaluation
    rec_every, rec_first, rec_last, rec_step, rec_movement, rec_q, rec_target, rec_x = record
    L = int(path_length)
    m = home.shape[0]
    n = targets.shape[1]
    capacity = P.shape[0]
    while True:
        if istate[KIND] == NONE:
            r = istate[MOVEMENTS]
            c = istate[EVAL_CURSOR]
            while c < eval_at.shape[0] and eval_at[c] <= r:
                if eval_at[c] == r:
                    e, d = evaluate_model(
                        eval_targets, home, lower, upper, chain, rot_ws, pos_ws,
                        P, W, O, istate[PROTOTYPES], radius, act, q, x,
                    )  # fmt: skip
                    errors[c] = e
                    distances[c] = d
                c += 1
            istate[EVAL_CURSOR] = c
            if r >= stop:
                return DONE
            # Eq. 7: after a goal-directed movement, return home with probability p_home.
            # The first movement and the one after a home return are goal-directed (Sec. II-A).
            if istate[LAST_KIND] == GOAL and rng.random() < p_home:
                istate[KIND] = HOME
                for i in range(m):
                    q_start[i] = q_prev[i]
            else:
                istate[KIND] = GOAL
                k = rng.integers(0, targets.shape[0])
                for j in range(n):
                    path_start[j] = path_end[j]
                    path_end[j] = targets[k, j]
            istate[STEP] = 0
        if istate[PROTOTYPES] >= capacity:
            return NEED_CAPACITY
        recording = rec_first <= istate[MOVEMENTS] < rec_last and (istate[STEPS] + 1) % rec_every == 0
        if recording and istate[RECORDED] >= rec_step.shape[0]:
            return NEED_RECORD_CAPACITY
        step = istate[STEP] + 1
        kind = istate[KIND]
        a = (L - step) / L
        bw = step / L
        if kind == GOAL:
            # Eq. 3: linear target path; Eq. 2: q_t = g(x*_t) + E_t(x*_t).
            for j in range(n):
                target[j] = a * path_start[j] + bw * path_end[j]
            llm_predict(target, P, W, O, istate[PROTOTYPES], radius, act, q)
            noise_add(A, b, target, q)
        else:
            # Eq. 7: linear path in joint space from the last posture to home.
            for i in range(m):
                q[i] = a * q_start[i] + bw * home[i]
        finite = True
        for i in range(m):
            # A posture beyond 1e6 (rad or m) means the estimate has exploded.
            if not (abs(q[i]) <= MAX_POSTURE):
                finite = False
            q[i] = min(max(q[i], lower[i]), upper[i])  # the robot executes the clipped posture
        if not finite:
            return NOT_FINITE
        chain_position(q, chain, rot_ws, pos_ws, x)  # Eq. 1
        if recording:
            c = istate[RECORDED]
            rec_step[c] = istate[STEPS] + 1
            rec_movement[c] = istate[MOVEMENTS]
            for i in range(m):
                rec_q[c, i] = q[i]
            for j in range(n):
                rec_target[c, j] = target[j] if kind == GOAL else math.nan
                rec_x[c, j] = x[j]
            istate[RECORDED] = c + 1
        w = efficiency_weight(x, x_prev, q, q_prev)  # Eq. 5
        if kind == GOAL:
            w *= direction_weight(target, target_prev, x, x_prev)  # Eqs. 4, 6
        istate[PROTOTYPES] = llm_learn(x, q, w, eta, P, W, O, istate[PROTOTYPES], radius, act, g, y, J)
        noise_walk(rng, sigma, sigma_delta, A, b)
        for i in range(m):
            q_prev[i] = q[i]
        for j in range(n):
            x_prev[j] = x[j]
            if kind == GOAL:
                target_prev[j] = target[j]
        istate[STEP] = step
        istate[STEPS] += 1
        if step == L:
            if kind == HOME:
                # The next goal path starts at f(q_home), which is where the arm is.
                for j in range(n):
                    path_end[j] = x[j]
                    target_prev[j] = x[j]
            istate[LAST_KIND] = kind
            istate[KIND] = NONE
            istate[MOVEMENTS] += 1
