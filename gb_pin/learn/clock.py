"""The monotonic clock of compiled code: how long loops return to Python so that Ctrl-C lands.

numba has no clock in nopython mode; :func:`clock_gettime` calls the C library's function of that
name (declared by name, so that the compiled code stays cacheable: the symbol is resolved when the
cache is loaded). :func:`monotonic` reads ``CLOCK_MONOTONIC`` (about 40 ns a call). The IK's budget
(:mod:`gb_pin.ik.clock`) and the slices of the babbling loop (:data:`SLICE_SECONDS`) read it.

Python handles a signal only between bytecodes, so a compiled call that runs for minutes (a dense
evaluation schedule over 10^5 test targets: 163 s measured) ignored Ctrl-C for as long. The loop
reads this clock between movements and every 256 evaluation targets, and returns ``SLICE`` once
a slice's time is up; Python then looks for Ctrl-C and calls it again, where it left off.
"""

from __future__ import annotations

import time

import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from gb_pin._jit import njit

__all__ = ["MONOTONIC", "SLICE_SECONDS", "clock_gettime", "monotonic"]

MONOTONIC = int(getattr(time, "CLOCK_MONOTONIC", -1))
"""The clock id of ``CLOCK_MONOTONIC`` (-1 where the platform has none: no slicing)."""

SLICE_SECONDS = 0.1
"""The longest the babbling loop runs before it returns to Python [s] (a step or a block of 256
evaluation targets more: milliseconds)."""


@intrinsic
def clock_gettime(typingctx, clock, address):  # type: ignore[no-untyped-def]
    """The C library's ``clock_gettime(clock, (struct timespec *) address)``."""
    sig = types.int32(types.int32, types.intp)

    def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
        pointer = ir.IntType(8).as_pointer()
        fnty = ir.FunctionType(ir.IntType(32), [ir.IntType(32), pointer])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "clock_gettime")
        return builder.call(fn, [args[0], builder.inttoptr(args[1], pointer)])

    return sig, codegen


@njit(cache=True, nogil=True, inline="always")
def monotonic(buf):  # type: ignore[no-untyped-def]
    """Seconds on ``CLOCK_MONOTONIC`` (``buf``: int64 (2,) scratch for the timespec); 0 if none."""
    if MONOTONIC < 0:
        return 0.0
    clock_gettime(np.int32(MONOTONIC), buf.ctypes.data)
    return float(buf[0]) + 1e-9 * float(buf[1])
