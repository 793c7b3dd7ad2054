"""``rng.integers(0, count)`` in compiled code, drawn exactly as numpy draws it, compiled quickly.

numba's ``Generator.integers`` compiles every dtype branch, the argument checks and an array fill
(about 0.8 s on first use); the loop needs one scalar index per goal. This is numpy's algorithm
for an int64 draw in [0, count) (``random_bounded_uint64_fill`` with size 1: Lemire's rejection on
one 32-bit draw when count - 1 < 2^32 - 1, a plain 32-bit draw when it equals it, the 64-bit
Lemire otherwise), so the Generator is advanced identically (tests/test_goal_draw.py).
"""

from __future__ import annotations

from numba import int64, uint64

from gb_pin._jit import njit

try:  # numba's own building blocks of Generator.integers (internal modules: guarded)
    from numba.np.random.generator_core import next_uint32
    from numba.np.random.random_methods import bounded_lemire_uint64

    INTERNALS = True
except ImportError:  # pragma: no cover - a numba that moved them: Generator.integers, the same numbers
    INTERNALS = False

UINT32_MAX = 0xFFFFFFFF


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _integers(rng, count):  # type: ignore[no-untyped-def]
    """The fallback: numba's ``Generator.integers`` (slower to compile, same draws)."""
    return rng.integers(0, count)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _uniform_index(rng, count):  # type: ignore[no-untyped-def]
    """``rng.integers(0, count)`` for ``count >= 1``: the same number and the same Generator state after."""
    r = uint64(count - 1)
    if r == 0:
        return int64(0)
    bitgen = rng.bit_generator
    if r == uint64(UINT32_MAX):
        return int64(next_uint32(bitgen))
    if r > uint64(UINT32_MAX):
        return int64(bounded_lemire_uint64(bitgen, r))
    excl = r + uint64(1)
    m = uint64(next_uint32(bitgen)) * excl
    leftover = m & uint64(UINT32_MAX)
    if leftover < excl:
        threshold = (uint64(UINT32_MAX) - r) % excl
        while leftover < threshold:
            m = uint64(next_uint32(bitgen)) * excl
            leftover = m & uint64(UINT32_MAX)
    return int64(m >> uint64(32))


uniform_index = _uniform_index if INTERNALS else _integers
