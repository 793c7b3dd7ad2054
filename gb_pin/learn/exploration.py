"""Structured continuous variation (paper Sec. II-B, Eq. 8): E_t(x) = A_t x + b_t.

Every entry e of A_t (m, n) and b_t (m,) starts i.i.d. N(0, sigma^2) and follows the
normalised Gaussian random walk

    e_{t+1} = sqrt(sigma^2 / (sigma^2 + sigma_delta^2)) * (e_t + delta),  delta ~ N(0, sigma_delta^2),

whose stationary variance stays sigma^2. Random numbers come from an explicit
``numpy.random.Generator`` (numba draws from its bit generator, so a compiled run
and a Python run with the same Generator see the same numbers). Entries are drawn
in the order A row by row, then b.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin._jit import NO_REFCOUNT, njit
from gb_pin._signals import deferring


def noise_init(
    rng: np.random.Generator, sigma: float, A: NDArray[np.float64], b: NDArray[np.float64]
) -> None:
    """Draw A_0 and b_0 with i.i.d. N(0, sigma^2) entries (Eq. 8), A row by row, then b.

    Plain numpy (called once per run, so not compiled): the same draws, in the same order, as
    numba's ``rng.standard_normal()`` one at a time, and the same product ``sigma * z``
    (tests/test_exploration.py).
    """
    m, n = A.shape
    z = rng.standard_normal(m * n + m)
    A[:, :] = sigma * z[: m * n].reshape(m, n)
    b[:] = sigma * z[m * n :]


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def noise_walk(rng, sigma, sigma_delta, A, b):  # type: ignore[no-untyped-def]
    """One step of the normalised Gaussian random walk on every entry (Eq. 8)."""
    # sqrt(sigma^2 / (sigma^2 + sigma_delta^2)), written so that it cannot overflow.
    shrink = 1.0 / math.sqrt(1.0 + (sigma_delta / sigma) ** 2) if sigma > 0.0 else 0.0
    m, n = A.shape
    # A row by row, then b as one more row: one call site, so numba inlines the normal generator once.
    for i in range(m + 1):
        for j in range(n if i < m else m):
            z = rng.standard_normal()
            if i < m:
                A[i, j] = shrink * (A[i, j] + sigma_delta * z)
            else:
                b[j] = shrink * (b[j] + sigma_delta * z)


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def noise_add(A, b, x, q):  # type: ignore[no-untyped-def]
    """q += A x + b (Eq. 2 adds E_t(x*_t) to the inverse estimate)."""
    m, n = A.shape
    for i in range(m):
        v = b[i]
        for j in range(n):
            v += A[i, j] * x[j]
        q[i] += v


class StructuredNoise:
    """The perturbation term E_t(x) = A_t x + b_t of Eq. 8, stepped explicitly.

    Args:
        n_joints: m.
        n_task: n.
        sigma: standard deviation of every entry [rad].
        sigma_delta: standard deviation of each random-walk increment [rad].
        rng: the random generator (explicit; never global state).
    """

    def __init__(
        self, n_joints: int, n_task: int, sigma: float, sigma_delta: float, rng: np.random.Generator
    ) -> None:
        self.sigma = check.nonnegative_float("sigma", sigma)
        self.sigma_delta = check.nonnegative_float("sigma_delta", sigma_delta)
        self.rng = rng
        self.A = np.zeros((check.positive_int("n_joints", n_joints), check.positive_int("n_task", n_task)))
        self.b = np.zeros(n_joints)
        deferring(noise_init, rng, self.sigma, self.A, self.b)

    def step(self) -> None:
        """Advance the random walk by one time step."""
        deferring(noise_walk, self.rng, self.sigma, self.sigma_delta, self.A, self.b)

    def __call__(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """E_t(x) for one input (n,) -> (m,)."""
        out = np.zeros(self.A.shape[0])
        noise_add(self.A, self.b, np.asarray(x, dtype=float), out)
        return out
