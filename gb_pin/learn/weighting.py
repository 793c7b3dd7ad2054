"""Example weights of goal babbling (paper Eqs. 4-6).

    w_dir = (1 + cos angle(x*_t - x*_{t-1}, x_t - x_{t-1})) / 2      (Eq. 4)
    w_eff = ||x_t - x_{t-1}|| / ||q_t - q_{t-1}||                    (Eq. 5)
    w     = w_dir * w_eff                                            (Eq. 6)

Conventions where the paper is silent: w_eff = 0 when the posture did not move
(||q_t - q_{t-1}|| = 0), and the cosine is taken as 0 (w_dir = 1/2) when either
displacement is zero. Home-return steps use w_eff alone (Sec. II-A).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from gb_pin._jit import NO_REFCOUNT, njit


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def direction_weight(target, target_prev, x, x_prev):  # type: ignore[no-untyped-def]
    """w_dir of Eq. 4 from the intended and the observed displacement."""
    dot = 0.0
    na = 0.0
    nb = 0.0
    for j in range(x.shape[0]):
        a = target[j] - target_prev[j]
        b = x[j] - x_prev[j]
        dot += a * b
        na += a * a
        nb += b * b
    # sqrt(na) * sqrt(nb), not sqrt(na * nb): the product of two tiny squares can underflow to 0.
    norms = math.sqrt(na) * math.sqrt(nb)
    if norms == 0.0:
        return 0.5
    cos = dot / norms
    # Rounding can push |cos| a hair above 1.
    cos = min(1.0, max(-1.0, cos))
    return 0.5 * (1.0 + cos)


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def efficiency_weight(x, x_prev, q, q_prev):  # type: ignore[no-untyped-def]
    """w_eff of Eq. 5: effector displacement per joint displacement (0 if q did not move)."""
    dq = 0.0
    for i in range(q.shape[0]):
        d = q[i] - q_prev[i]
        dq += d * d
    if dq == 0.0:
        return 0.0
    dx = 0.0
    for j in range(x.shape[0]):
        d = x[j] - x_prev[j]
        dx += d * d
    return math.sqrt(dx) / math.sqrt(dq)


def example_weight(
    target: ArrayLike,
    target_prev: ArrayLike,
    x: ArrayLike,
    x_prev: ArrayLike,
    q: ArrayLike,
    q_prev: ArrayLike,
) -> float:
    """w = w_dir * w_eff (Eq. 6) for one goal-directed example; arrays of shape (n,) and (m,)."""
    arrays = [np.asarray(a, dtype=float) for a in (target, target_prev, x, x_prev, q, q_prev)]
    return float(direction_weight(*arrays[:4]) * efficiency_weight(*arrays[2:]))
