"""A closed-form reference of Online Goal Babbling on the paper's planar arms, in one compiled function.

The yardstick of gb_pin's speed (issue 26): the same algorithm as ``gb_pin.babble`` on a
``planarN`` preset, written as simply as possible, with nothing general about it: forward
kinematics by cumulative angles (x = sum_i l cos(q_1 + ... + q_i), y likewise), the local-linear
map as per-prototype loops, the weights, the noise random walk and the paper's linear target
paths, all in :func:`reference_run`. It uses gb_pin's conventions where the paper is silent (see
tests/reference.py) and draws the same random numbers in the same order from the same numpy
Generator, so the two runs agree to rounding for the first movements and in their E^X statistics
after (``python scripts/bench_reference.py`` prints both). It imports only numpy and numba.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

GOAL, HOME = 0, 1


@njit(cache=True, error_model="numpy")
def forward(q, length, x):  # type: ignore[no-untyped-def]
    """Planar arm of equal links ``length`` [m]: x = sum_i l (cos, sin)(q_1 + ... + q_i) (Eq. 1)."""
    angle = 0.0
    x[0] = 0.0
    x[1] = 0.0
    for i in range(q.shape[0]):
        angle += q[i]
        x[0] += length * math.cos(angle)
        x[1] += length * math.sin(angle)


@njit(cache=True, error_model="numpy")
def predict(x, P, W, O, K, d, out, U, act):  # type: ignore[no-untyped-def]
    """g(x) into ``out`` (Sec. II-C); U (K, n) gets u_k, act (K,) the activations; returns (total, min)."""
    n, m = x.shape[0], out.shape[0]
    smallest = np.inf
    for k in range(K):
        s = 0.0
        for j in range(n):
            U[k, j] = (x[j] - P[k, j]) / d
            s += U[k, j] * U[k, j]
        act[k] = s
        smallest = min(smallest, s)
    total = 0.0
    out[:] = 0.0
    for k in range(K):
        act[k] = math.exp(smallest - act[k])
        total += act[k]
        for i in range(m):
            y = O[k, i]
            for j in range(n):
                y += W[k, i, j] * U[k, j]
            out[i] += act[k] * y
    out /= total
    return total, smallest


@njit(cache=True, error_model="numpy")
def reference_run(rng, m, targets, home, hyper, movements, eval_at, errors):  # type: ignore[no-untyped-def]
    """Run ``movements`` movements of goal babbling on planar arm of m joints (total length 1 m).

    Args:
        rng: numpy Generator.
        m: joints.
        targets: (N, 2) target set X* [m].
        home: (m,) q_home [rad].
        hyper: (learning_rate, sigma, sigma_delta, radius, path_length, p_home).
        movements: movements to run (home returns included).
        eval_at: increasing movement counts at which to record E^X (Eq. 9).
        errors: (len(eval_at),) output, E^X [m].

    Returns:
        The number of prototypes at the end.
    """
    eta, sigma, sigma_delta, d, L, p_home = hyper[0], hyper[1], hyper[2], hyper[3], int(hyper[4]), hyper[5]
    n, length = 2, 1.0 / m
    cap = 16
    P, W, O = np.zeros((cap, n)), np.zeros((cap, m, n)), np.zeros((cap, m))
    U, act = np.zeros((cap, n)), np.zeros(cap)
    A, b = np.empty((m, n)), np.empty(m)
    for i in range(m):  # Eq. 8: A_0 row by row, then b_0
        for j in range(n):
            A[i, j] = sigma * rng.standard_normal()
    for i in range(m):
        b[i] = sigma * rng.standard_normal()
    shrink = math.sqrt(sigma**2 / (sigma**2 + sigma_delta**2))
    q, x, target, g, J, yk = np.empty(m), np.empty(n), np.empty(n), np.empty(m), np.empty((m, n)), np.empty(m)
    q_prev, q_start = home.copy(), home.copy()
    x_home = np.empty(n)
    forward(home, length, x_home)
    P[0] = x_home  # g(x) = q_home, its one prototype at f(q_home)
    O[0] = home
    K = 1
    x_prev, target_prev, path_start, path_end = x_home.copy(), x_home.copy(), x_home.copy(), x_home.copy()
    last, c = -1, 0
    for r in range(movements + 1):
        while c < eval_at.shape[0] and eval_at[c] == r:  # E^X (Eq. 9) with theta_{rL}
            e = 0.0
            for t in range(targets.shape[0]):
                predict(targets[t], P, W, O, K, d, g, U, act)
                forward(g, length, x)
                e += math.sqrt((targets[t, 0] - x[0]) ** 2 + (targets[t, 1] - x[1]) ** 2)
            errors[c] = e / targets.shape[0]
            c += 1
        if r == movements:
            break
        kind = GOAL
        if last == GOAL and rng.random() < p_home:  # Eq. 7: home return
            kind = HOME
            q_start[:] = q_prev
        else:  # Eq. 3: a linear path from the last goal to a new one
            path_start[:] = path_end
            path_end[:] = targets[rng.integers(0, targets.shape[0])]
        for step in range(1, L + 1):
            a, bw = (L - step) / L, step / L
            if kind == GOAL:  # Eq. 2: q = g(x*) + A x* + b
                for j in range(n):
                    target[j] = a * path_start[j] + bw * path_end[j]
                predict(target, P, W, O, K, d, q, U, act)
                for i in range(m):
                    q[i] += b[i] + A[i, 0] * target[0] + A[i, 1] * target[1]
            else:
                for i in range(m):
                    q[i] = a * q_start[i] + bw * home[i]
            forward(q, length, x)
            # Eqs. 4-6: w = w_dir * w_eff (home returns: w_eff only).
            dq = 0.0
            for i in range(m):
                dq += (q[i] - q_prev[i]) ** 2
            dx0, dx1 = x[0] - x_prev[0], x[1] - x_prev[1]
            w = 0.0 if dq == 0.0 else math.sqrt(dx0 * dx0 + dx1 * dx1) / math.sqrt(dq)
            if kind == GOAL:
                da0, da1 = target[0] - target_prev[0], target[1] - target_prev[1]
                norms = math.sqrt(da0 * da0 + da1 * da1) * math.sqrt(dx0 * dx0 + dx1 * dx1)
                cos = 0.0 if norms == 0.0 else min(1.0, max(-1.0, (da0 * dx0 + da1 * dx1) / norms))
                w *= 0.5 * (1.0 + cos)
            # Sec. II-C: insert a prototype at x if none is within d (o = g(x), W = d dg/dx), then descend.
            total, smallest = predict(x, P, W, O, K, d, g, U, act)
            if smallest >= 1.0:
                if cap == K:
                    cap *= 2
                    P, W, O = _grow(P, cap), _grow(W, cap), _grow(O, cap)
                    U, act = np.zeros((cap, n)), np.zeros(cap)
                J[:] = 0.0
                for k in range(K):
                    for i in range(m):
                        yk[i] = O[k, i] + W[k, i, 0] * U[k, 0] + W[k, i, 1] * U[k, 1]
                        for j in range(n):
                            J[i, j] += act[k] / total * (W[k, i, j] - 2.0 * (yk[i] - g[i]) * U[k, j])
                P[K] = x
                O[K] = g
                W[K] = J  # W = d * dg/dx = d * (J / d)
                K += 1
                total, smallest = predict(x, P, W, O, K, d, g, U, act)
            if w != 0.0:  # o_k += eta w beta_k e, W_k += eta w beta_k e u_k^T, e = q - g(x)
                for i in range(m):
                    yk[i] = q[i] - g[i]
                scale = eta * w / total
                for k in range(K):
                    for i in range(m):
                        ce = scale * act[k] * yk[i]
                        O[k, i] += ce
                        for j in range(n):
                            W[k, i, j] += ce * U[k, j]
            for i in range(m):  # Eq. 8: the noise walks, A row by row, then b
                for j in range(n):
                    A[i, j] = shrink * (A[i, j] + sigma_delta * rng.standard_normal())
            for i in range(m):
                b[i] = shrink * (b[i] + sigma_delta * rng.standard_normal())
            q_prev[:] = q
            x_prev[:] = x
            if kind == GOAL:
                target_prev[:] = target
        if kind == HOME:  # the next path starts at f(q_home)
            path_end[:] = x
            target_prev[:] = x
        last = kind
    return K


@njit(cache=True)
def _grow(a, cap):  # type: ignore[no-untyped-def]
    out = np.zeros((cap, *a.shape[1:]))
    out[: a.shape[0]] = a
    return out


def planar_home(m: int) -> np.ndarray:
    """The paper's home posture: q_1 = -pi/3, q_i = 2 pi / (3 (m - 1)) [rad]."""
    home = np.full(m, 2.0 * math.pi / (3.0 * (m - 1)))
    home[0] = -math.pi / 3.0
    return home
