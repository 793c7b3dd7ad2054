"""The compiled side of the goal generators: one dispatch on the generator's kind."""

from __future__ import annotations

from numba import njit

from gb_pin.learn.goals.base import CYCLIC, UNIFORM
from gb_pin.learn.goals.draw import uniform_index


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def next_goal(goals, rng, out):  # type: ignore[no-untyped-def]
    """Write the next goal into ``out`` (n,) for a built-in generator; False if Python must decide.

    ``UNIFORM``: a target drawn uniformly from X* (Sec. II-A, Eq. 3). ``CYCLIC``: the targets
    in their order, round and round (``istate[0]`` is the next index).
    """
    targets = goals.targets
    if goals.kind == UNIFORM:
        k = uniform_index(rng, targets.shape[0])  # = rng.integers(0, N), draw for draw
    elif goals.kind == CYCLIC:
        k = goals.istate[0]
        goals.istate[0] = (k + 1) % targets.shape[0]
    else:
        return False
    for j in range(targets.shape[1]):
        out[j] = targets[k, j]
    return True
