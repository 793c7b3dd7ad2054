"""The compiled side of the goal generators, one implementation per family of generators.

:func:`gb_pin.learn.loop.begin_movement` calls :func:`goal_feedback` after every goal-directed
movement (how far the arm missed its goal), :func:`snap_start` to choose where the next path
starts, :func:`next_goal` for its end, and :func:`is_motor` / :func:`motor_posture` for motor
babbling. numba picks each family's implementation by the class of the generator's arrays
(:class:`~gb_pin.learn.goals.base.GoalArrays`: the paper's uniform choice and the cyclic
order, ``DirectionArrays``, ``SelectorArrays``, ``MotorArrays``) when it compiles the loop,
so that each run compiles only its own generator's code.
"""

from __future__ import annotations

import math
from typing import Any

from numba import types
from numba.extending import overload

from gb_pin._jit import NO_REFCOUNT, OVERLOAD_OPTIONS, njit
from gb_pin.learn.goals.base import (
    CURRICULUM,
    CYCLIC,
    ERROR,
    SNAP,
    UNIFORM,
    DirectionArrays,
    MotorArrays,
    SelectorArrays,
)
from gb_pin.learn.goals.directions import DISTANCE
from gb_pin.learn.goals.draw import uniform_index
from gb_pin.learn.goals.motor import SPREAD
from gb_pin.learn.goals.selection import LAST, RATE, SHARE

LOG_FLOOR = 1e-12  # errors below this count as this in log errors [m]
SLOW = 4.0  # the slow average of the progress selector has weight rate / SLOW


def _family(goals: Any) -> type | None:
    """The arrays class of a generator's numba type (None: GoalArrays, the paper's family)."""
    cls = getattr(goals, "instance_class", None) if isinstance(goals, types.BaseNamedTuple) else None
    return cls if cls in (DirectionArrays, SelectorArrays, MotorArrays) else None


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def next_goal(goals, rng, start, out):  # type: ignore[no-untyped-def]
    """Write the next goal into ``out`` (n,) for a built-in generator; False if Python must decide.

    ``UNIFORM``: a target drawn uniformly from X* (Sec. II-A, Eq. 3). ``CYCLIC``: the targets
    in their order (``istate[0]`` is the next index). ``DIRECTIONS``: ``start`` plus
    ``distance`` along a random unit direction. ``ERROR`` / ``PROGRESS``: a target chosen by
    its score (:func:`_select`). A kernel of its own (cached, so that a cold start can compile it
    in another process, :mod:`gb_pin.runs.coldstart`) around the overload per family.
    """
    return _family_goal(goals, rng, start, out)


def _family_goal(goals: Any, rng: Any, start: Any, out: Any) -> bool:
    raise TypeError("_family_goal runs inside compiled code (see next_goal)")


@overload(_family_goal, jit_options=OVERLOAD_OPTIONS)
def _next_goal(goals, rng, start, out):  # type: ignore[no-untyped-def]
    family = _family(goals)
    if family is DirectionArrays:
        return lambda goals, rng, start, out: _direction_goal(goals, rng, start, out)
    if family is SelectorArrays:
        return lambda goals, rng, start, out: _copy_target(goals, _select(goals, rng), out)
    if family is MotorArrays:
        return lambda goals, rng, start, out: False  # motor babbling has no goals
    return lambda goals, rng, start, out: _paper_goal(goals, rng, out)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _paper_goal(goals, rng, out):  # type: ignore[no-untyped-def]
    targets = goals.targets
    if goals.kind == UNIFORM:
        k = uniform_index(rng, targets.shape[0])  # = rng.integers(0, N), draw for draw
    elif goals.kind == CYCLIC:
        k = goals.istate[0]
        goals.istate[0] = (k + 1) % targets.shape[0]
    elif goals.kind == CURRICULUM:
        k = _curriculum_index(goals, rng)
    else:
        return False
    return _copy_target(goals, k, out)


@njit(cache=True, nogil=True, error_model="numpy")
def _curriculum_index(goals, rng):  # type: ignore[no-untyped-def]
    """A target drawn uniformly from the current stage's block (:mod:`gb_pin.learn.goals.curriculum`)."""
    stages = int(goals.params[1])
    count = goals.istate[0]
    s = 0
    end = goals.params[2]
    while s < stages - 1 and count >= end:
        s += 1
        end *= goals.params[3]
    goals.istate[0] = count + 1
    block = goals.targets.shape[0] // stages
    return s * block + uniform_index(rng, block)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _copy_target(goals, k, out):  # type: ignore[no-untyped-def]
    for j in range(goals.targets.shape[1]):
        out[j] = goals.targets[k, j]
    return True


@njit(cache=True, nogil=True, error_model="numpy")
def _direction_goal(goals, rng, start, out):  # type: ignore[no-untyped-def]
    norm = 0.0
    while norm == 0.0:  # an isotropic unit direction (a zero draw has probability 0)
        norm = 0.0
        for j in range(out.shape[0]):
            out[j] = rng.standard_normal()
            norm += out[j] * out[j]
    scale = goals.params[DISTANCE] / math.sqrt(norm)
    for j in range(out.shape[0]):
        out[j] = start[j] + scale * out[j]
    return True


@njit(cache=True, nogil=True, error_model="numpy")
def _select(goals, rng):  # type: ignore[no-untyped-def]
    """The index of the next goal of an error- or progress-based selector (rules in their classes)."""
    N = goals.targets.shape[0]
    istate = goals.istate
    if rng.random() < goals.params[SHARE]:
        k = uniform_index(rng, N)
    else:
        need = 1 if goals.kind == ERROR else 2  # visits before a target has a score
        untried = 0
        for i in range(N):
            if istate[1 + i] < need:
                untried += 1
        if untried > 0:
            j = uniform_index(rng, untried)
            k = 0
            for i in range(N):
                if istate[1 + i] < need:
                    if j == 0:
                        k = i
                        break
                    j -= 1
        else:
            total = 0.0
            for i in range(N):
                total += _score(goals, i)
            if total > 0.0 and math.isfinite(total):
                u = rng.random() * total
                k = -1
                for i in range(N):
                    w = _score(goals, i)
                    if w > 0.0:
                        k = i
                        u -= w
                        if u < 0.0:
                            break
            else:
                k = uniform_index(rng, N)
    istate[LAST] = k
    return k


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _score(goals, i):  # type: ignore[no-untyped-def]
    """Target i's selection weight: its error (ERROR), or slow - fast average of its log error (PROGRESS)."""
    if goals.kind == ERROR:
        return max(goals.fstate[i], 0.0)
    return max(goals.fstate[goals.targets.shape[0] + i] - goals.fstate[i], 0.0)


def goal_feedback(goals: Any, goal: Any, reached: Any) -> None:
    """After a goal-directed movement: update a selector's score of the goal it chose.

    ERROR: e_k <- (1 - rate) e_k + rate e with e = ||goal - reached|| (e itself at the first
    visit). PROGRESS: a fast (weight rate) and a slow (weight rate / SLOW) running average of
    log e; the score is slow - fast. Other families keep no score. Compiled code only.
    """
    raise TypeError("goal_feedback runs inside compiled code")


@overload(goal_feedback, jit_options=OVERLOAD_OPTIONS)
def _goal_feedback(goals, goal, reached):  # type: ignore[no-untyped-def]
    if _family(goals) is SelectorArrays:
        return lambda goals, goal, reached: _score_feedback(goals, goal, reached)
    return lambda goals, goal, reached: None


@njit(cache=True, nogil=True, error_model="numpy")
def _score_feedback(goals, goal, reached):  # type: ignore[no-untyped-def]
    kind = goals.kind
    istate, fstate = goals.istate, goals.fstate
    k = istate[LAST]
    if k < 0:
        return
    e = 0.0
    for j in range(goal.shape[0]):
        v = goal[j] - reached[j]
        e += v * v
    e = math.sqrt(e)
    rate = goals.params[RATE]
    visits = istate[1 + k]
    if kind == ERROR:
        fstate[k] = e if visits == 0 else (1.0 - rate) * fstate[k] + rate * e
    else:
        # fstate[k]: fast average of log e (weight rate); fstate[N + k]: slow one (rate / SLOW).
        N = goals.targets.shape[0]
        log_e = math.log(max(e, LOG_FLOOR))
        if visits == 0:
            fstate[k] = log_e
            fstate[N + k] = log_e
        else:
            fstate[k] = (1.0 - rate) * fstate[k] + rate * log_e
            slow = rate / SLOW
            fstate[N + k] = (1.0 - slow) * fstate[N + k] + slow * log_e
    istate[1 + k] = visits + 1
    istate[LAST] = -1


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def snap_start(goals, goal, reached):  # type: ignore[no-untyped-def]
    """True if the last goal-directed movement ended farther than ``params[SNAP]`` from its goal."""
    threshold = goals.params[SNAP]
    if math.isinf(threshold):
        return False
    e = 0.0
    for j in range(goal.shape[0]):
        v = goal[j] - reached[j]
        e += v * v
    return math.sqrt(e) > threshold


def is_motor(goals: Any) -> bool:
    """True for motor babbling (a constant of the compiled code). Compiled code only."""
    raise TypeError("is_motor runs inside compiled code")


@overload(is_motor, jit_options=OVERLOAD_OPTIONS)
def _is_motor(goals):  # type: ignore[no-untyped-def]
    motor = _family(goals) is MotorArrays
    return lambda goals: motor


def motor_posture(goals: Any, rng: Any, limits: Any, out: Any) -> None:
    """A random posture q_home + spread * z (z standard normal), clipped to the limits, into ``out``."""
    raise TypeError("motor_posture runs inside compiled code")


@overload(motor_posture, jit_options=OVERLOAD_OPTIONS)
def _motor_posture(goals, rng, limits, out):  # type: ignore[no-untyped-def]
    if _family(goals) is MotorArrays:
        return lambda goals, rng, limits, out: _random_posture(goals, rng, limits, out)
    return lambda goals, rng, limits, out: None


@njit(cache=True, nogil=True, error_model="numpy")
def _random_posture(goals, rng, limits, out):  # type: ignore[no-untyped-def]
    home, lower, upper = limits.home, limits.lower, limits.upper
    spread = goals.params[SPREAD]
    for i in range(out.shape[0]):
        out[i] = min(max(home[i] + spread * rng.standard_normal(), lower[i]), upper[i])
