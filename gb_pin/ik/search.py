"""The compiled batch driver: seeds, restarts within a budget, several solutions, closest ones, paths.

For each target x* (a row of X): start the clock, convert x* to its geometric goal, take the
seed (given, the learned estimate g(x*) or the nearest prototype's local model), and refine it
(:func:`~gb_pin.ik.solver.refine`). While the budget lasts (``timeout`` seconds of the clock
and/or ``max_restarts``), restart from postures drawn uniformly within the limits (the
target's own splitmix64 stream) until ``solutions`` distinct solutions are found; with a
reference posture (``closest``, or the previous point of a path) solutions are ranked by their
distance to it, and ``closest`` searches the whole budget for the nearest. A target with no
solution returns the best posture found (the smallest error), marked unsuccessful. The time of
each query, seed included, is measured on the settings' clock (wall or the thread's CPU time).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin._jit import NO_REFCOUNT, njit
from gb_pin.ik.clock import now, stream_seed, uniform
from gb_pin.ik.geometry import goal_from_task
from gb_pin.ik.solver import Work, evaluate, refine, work_buffers
from gb_pin.learn.body.components import components_forward
from gb_pin.learn.llm_kernels import MapArrays

__all__ = [
    "SEED_GIVEN", "SEED_LEARNED", "SEED_NEAREST", "IKOut", "IKSeeds", "SearchScratch", "search_scratch",
    "solve_batch",
]  # fmt: skip

SEED_GIVEN = 0
SEED_LEARNED = 1
SEED_NEAREST = 2


class IKSeeds(NamedTuple):
    """Where each target's first attempt starts.

    Attributes:
        mode: ``SEED_GIVEN`` (``postures``), ``SEED_LEARNED`` (g(x*)) or ``SEED_NEAREST`` (the
            local model o_k + W_k (x* - p_k) / d of the prototype nearest to x*).
        postures: (N, m) the given seeds, or (1, m): one for every target (``SEED_GIVEN``).
        model: the learned map (any, with ``prototypes`` 0, for ``SEED_GIVEN``).
        prototypes: prototypes in use K.
        cut: prototypes whose activation is below exp(-cut) of the nearest one's are left out of g.
        reference: (N, m) or (1, m) postures the solutions are ranked by (closest first), when ``ranked``.
        ranked: rank solutions by their distance to ``reference`` (a path ranks by the previous point).
        base: the run's random seed (uint64) of the restart streams.
    """

    mode: int
    postures: NDArray[np.float64]
    model: MapArrays
    prototypes: int
    cut: float
    reference: NDArray[np.float64]
    ranked: bool
    base: np.uint64


class SearchScratch(NamedTuple):
    """The batch's scratch, allocated by the caller (the kernels here allocate nothing)."""

    work: Work  # one attempt's buffers
    q: NDArray[np.float64]  # (m,) the posture being refined
    best: NDArray[np.float64]  # (m,) the best unsuccessful posture
    kept: NDArray[np.float64]  # (k, m) the solutions kept
    dist: NDArray[np.float64]  # (k,) their distances to the reference (or their order)
    state: NDArray[np.uint64]  # (1,) the restart stream


def search_scratch(n_e: int, m: int, C: int, k: int) -> SearchScratch:
    """Scratch for a task of ``n_e`` error rows, ``m`` joints, ``C`` components and ``k`` solutions."""
    return SearchScratch(
        work_buffers(n_e, m, C),
        np.empty(m),
        np.empty(m),
        np.empty((k, m)),
        np.empty(k),
        np.zeros(1, np.uint64),
    )


class IKOut(NamedTuple):
    """What the batch returns (k = ``solutions``; rows beyond ``found`` stay NaN).

    Attributes:
        q: (N, k, m) solutions, ranked; row 0 holds the best posture found when there is none.
        x: (N, k, n) f(q), the task vectors they reach.
        residual: (N, k) ||x* - f(q)|| in task units.
        errors: (N, k, C) residual of each component: [m] for positions, [rad] for rotations.
        found: (N,) int64, distinct solutions found.
        iterations: (N,) int64, steps over all attempts.
        restarts: (N,) int64, attempts after the first.
        seconds: (N,) time of each query, seed included [s] (0 without a clock).
        seeds: (N, m) the first attempt's seed, clipped to the limits.
    """

    q: NDArray[np.float64]
    x: NDArray[np.float64]
    residual: NDArray[np.float64]
    errors: NDArray[np.float64]
    found: NDArray[np.int64]
    iterations: NDArray[np.int64]
    restarts: NDArray[np.int64]
    seconds: NDArray[np.float64]
    seeds: NDArray[np.float64]


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def _learned_seed(x, seeds, nearest_only, q):  # type: ignore[no-untyped-def]
    """g(x) (the paper's local-linear map, Sec. II-C) into ``q``, over the prototypes that count.

    A first pass finds the squared scaled distances ||u_k||^2 and their minimum; only prototypes
    whose activation exp(-(||u_k||^2 - min)) exceeds exp(-``seeds.cut``) of the nearest's enter
    the sum, so that g costs K n operations plus n m per prototype near x instead of K n m (cut
    16: within 1e-6 rad of g on the Panda's 588- and 1500-prototype maps, at 2/3 of the cost;
    docs/IK.md). ``nearest_only``: the local model o_k + W_k u_k of the nearest prototype alone.
    """
    lm, K, cut = seeds.model, seeds.prototypes, seeds.cut
    P, M, act, inv = lm.prototypes, lm.models, lm.act, 1.0 / lm.radius
    n, m = x.shape[0], q.shape[0]
    smallest, nearest = np.inf, 0
    for k in range(K):
        s = 0.0
        for j in range(n):
            u = (x[j] - P[j, k]) * inv
            s += u * u
        act[k] = s
        if s < smallest:
            smallest, nearest = s, k
    for i in range(m):
        q[i] = 0.0
    total = 0.0
    for k in range(K):
        if nearest_only and k != nearest:
            continue
        if act[k] - smallest > cut:
            continue
        a = math.exp(smallest - act[k])
        total += a
        for i in range(
            m
        ):  # the map's storage: P[j, k] = (p_k)_j, M[k, 0, i] = (o_k)_i, M[k, 1 + j, i] = (W_k)_ij
            y = M[k, 0, i]
            for j in range(n):
                y += M[k, 1 + j, i] * ((x[j] - P[j, k]) * inv)
            q[i] += a * y
    for i in range(m):
        q[i] /= total


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def _first_seed(r, x, seeds, q):  # type: ignore[no-untyped-def]
    """The seed of target ``r`` into ``q`` (m,)."""
    if seeds.mode == SEED_GIVEN:
        row = min(r, seeds.postures.shape[0] - 1)  # one row: the same seed for every target
        for i in range(q.shape[0]):
            q[i] = seeds.postures[row, i]
    else:
        _learned_seed(x, seeds, seeds.mode == SEED_NEAREST, q)


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def _copy(src, dst):  # type: ignore[no-untyped-def]
    """dst[:] = src, element by element (a slice assignment may allocate a temporary)."""
    for i in range(dst.shape[0]):
        dst[i] = src[i]


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def _turn_towards(q, ref, robot):  # type: ignore[no-untyped-def]
    """Turn each periodic joint of solution ``q`` by whole turns towards ``ref``, within the limits.

    The same pose (a revolute joint turned by 2 pi), nearer the reference: a path through a UR5's
    +/- 2 pi joints or a Kinova's continuous ones need not jump by a turn.
    """
    lower, upper, periodic = robot.lower, robot.upper, robot.periodic
    turn = 2.0 * math.pi
    for i in range(q.shape[0]):
        if periodic[i] == 0.0:
            continue
        while q[i] - ref[i] > math.pi and q[i] - turn >= lower[i]:
            q[i] -= turn
        while ref[i] - q[i] > math.pi and q[i] + turn <= upper[i]:
            q[i] += turn


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def _distance(a, b):  # type: ignore[no-untyped-def]
    s = 0.0
    for i in range(a.shape[0]):
        s += (a[i] - b[i]) * (a[i] - b[i])
    return math.sqrt(s)


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def _keep(q, kept, dist, count, ref, ranked, min_distance):  # type: ignore[no-untyped-def]
    """Add solution ``q`` to ``kept`` (k, m) (``count`` used, ranked by ``dist``); returns the new count."""
    k = kept.shape[0]
    d = _distance(q, ref) if ranked else float(count)
    for s in range(count):
        close = True
        for i in range(q.shape[0]):
            if abs(q[i] - kept[s, i]) >= min_distance:
                close = False
                break
        if close:  # the same solution: keep the nearer of the two
            if not (ranked and d < dist[s]):
                return count
            for t in range(s, count - 1):  # drop it, then insert q below
                dist[t] = dist[t + 1]
                _copy(kept[t + 1], kept[t])
            count -= 1
            break
    if count == k and not (ranked and d < dist[k - 1]):
        return count
    slot = min(count, k - 1)
    while slot > 0 and ranked and dist[slot - 1] > d:
        dist[slot] = dist[slot - 1]
        _copy(kept[slot - 1], kept[slot])
        slot -= 1
    dist[slot] = d
    _copy(q, kept[slot])
    return min(count + 1, k)


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def _report(X, robot, w, r, out, count):  # type: ignore[no-untyped-def]
    """f(q), residuals and component errors of target ``r``'s first ``count`` postures."""
    n = X.shape[1]
    for s in range(count):
        q = out.q[r, s]
        evaluate(q, robot, w)  # the joint frames at q, and the component errors
        components_forward(robot.comps, robot.rot_ws, robot.pos_ws, out.x[r, s])
        total = 0.0
        for a in range(n):
            v = X[r, a] - out.x[r, s, a]
            total += v * v
        out.residual[r, s] = math.sqrt(total)
        for c in range(w.residuals.shape[0]):
            out.errors[r, s, c] = w.residuals[c]


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def solve_batch(X, robot, settings, seeds, out, scratch):  # type: ignore[no-untyped-def]
    """Solve every row of ``X`` (N, n) into ``out`` (see the module)."""
    N, m, k = X.shape[0], out.q.shape[2], out.q.shape[1]
    w, q, best, kept, dist, state = scratch
    lower, upper, lo, hi = robot.lower, robot.upper, robot.sample_lower, robot.sample_upper
    for r in range(N):
        if w.stop[0] != 0:  # interrupted (Ctrl-C): the caller raises KeyboardInterrupt
            return
        start = now(settings.clock, w.clock_buf)
        deadline = start + settings.timeout if settings.timeout < np.inf else np.inf
        goal_from_task(robot.comps, X[r], w.goal[0], w.goal[1])
        if settings.follow and r > 0:
            _copy(out.q[r - 1, 0], q)
        else:
            _first_seed(r, X[r], seeds, q)
        ref = (
            out.q[r - 1, 0]
            if settings.follow and r > 0
            else seeds.reference[min(r, seeds.reference.shape[0] - 1)]
        )
        ranked = seeds.ranked or (settings.follow and r > 0)
        for i in range(m):
            if not math.isfinite(q[i]):  # a learned seed far outside the map: start mid-range
                q[i] = 0.5 * (lo[i] + hi[i])
            q[i] = min(max(q[i], lower[i]), upper[i])
            out.seeds[r, i] = q[i]
        stream_seed(seeds.base, r, state)
        count, steps, restarts, best_cost, search_all = 0, 0, 0, np.inf, settings.closest
        while True:
            cost, taken, success = refine(q, robot, settings, w, deadline)
            steps += taken
            if success:
                if ranked:
                    _turn_towards(q, ref, robot)
                count = _keep(q, kept, dist, count, ref, ranked, settings.min_distance)
            elif cost < best_cost or restarts == 0:
                best_cost = cost
                _copy(q, best)
            if restarts == 0:
                # a path point whose warm start failed searches the whole budget for the nearest
                search_all = settings.closest or (settings.follow and r > 0 and not success)
            if (count == k and not search_all) or w.stop[0] != 0:
                break
            if settings.max_restarts >= 0 and restarts >= settings.max_restarts:
                break
            if deadline == np.inf and settings.max_restarts < 0:
                break
            if deadline < np.inf and now(settings.clock, w.clock_buf) >= deadline:
                break
            restarts += 1
            for i in range(m):
                q[i] = lo[i] + (hi[i] - lo[i]) * uniform(state)
        for s in range(k):
            for i in range(m):
                out.q[r, s, i] = kept[s, i] if s < count else (best[i] if s == 0 else np.nan)
        _report(X, robot, w, r, out, max(count, 1))
        out.found[r] = count
        out.iterations[r] = steps
        out.restarts[r] = restarts
        out.seconds[r] = now(settings.clock, w.clock_buf) - start
