"""A monotonic clock and a counter-based random stream for compiled code (the solver's budget and restarts).

numba has no clock in nopython mode; :func:`now` calls the C library's ``clock_gettime``
(:func:`gb_pin.learn.clock.clock_gettime`, shared with the babbling loop's slices).
:data:`CLOCKS`: ``"wall"`` is ``time.CLOCK_MONOTONIC`` (about 40 ns a call here), the budget of the
field's protocol; ``"cpu"`` is ``time.CLOCK_THREAD_CPUTIME_ID``, the time the query itself ran on
its core (about 0.7 us a call: a system call), which a busy machine's preemptions do not eat into
(-1 where the platform has no such clock: no time limit can be kept, and the API says so).

Restarts draw their postures from a splitmix64 stream of their own per target (seeded by the
run's seed and the target's index), so a target's answer does not depend on the other targets
in the batch nor on how many draws they used.
"""

from __future__ import annotations

import time

import numpy as np

from gb_pin._jit import NO_REFCOUNT, njit
from gb_pin.learn.clock import clock_gettime as _clock_gettime

__all__ = ["CLOCKS", "now", "stream_seed", "uniform"]

CLOCKS: dict[str, int] = {
    "wall": int(getattr(time, "CLOCK_MONOTONIC", -1)),
    "cpu": int(getattr(time, "CLOCK_THREAD_CPUTIME_ID", -1)),
}
"""The clocks :func:`now` reads, by name (-1: not on this platform)."""

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)


@njit(cache=True, nogil=True, **NO_REFCOUNT)
def now(clock, buf):  # type: ignore[no-untyped-def]
    """Seconds on the monotonic clock ``clock`` (``buf``: int64 (2,) scratch for the timespec); 0 if none."""
    if clock < 0:
        return 0.0
    _clock_gettime(np.int32(clock), buf.ctypes.data)
    return float(buf[0]) + 1e-9 * float(buf[1])


@njit(cache=True, nogil=True, **NO_REFCOUNT)
def stream_seed(base, index, state):  # type: ignore[no-untyped-def]
    """Start the stream of target ``index`` in ``state`` (uint64 (1,)) from the run's ``base`` (uint64)."""
    state[0] = base ^ (np.uint64(index) * _GOLDEN)


@njit(cache=True, nogil=True, **NO_REFCOUNT)
def uniform(state):  # type: ignore[no-untyped-def]
    """A float uniform in [0, 1) from the splitmix64 stream in ``state`` (uint64 (1,)), advanced."""
    state[0] += _GOLDEN
    z = state[0]
    z = (z ^ (z >> np.uint64(30))) * _MIX1
    z = (z ^ (z >> np.uint64(27))) * _MIX2
    z = z ^ (z >> np.uint64(31))
    return float(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)
