"""exp for loops the compiler vectorises, rounded alike on every machine.

The local-linear map evaluates one exponential per prototype, twice per step. ``math.exp`` is a
call into the C library per element (3-4 ns; its last bit depends on the library and on the
variant it picks for the CPU). :func:`vexp` is plain arithmetic that LLVM turns into SIMD code
(about 1 ns per element) and that gives the same bits on any machine that rounds IEEE doubles
(numba never contracts a product and a sum into an FMA unless told to).

vexp(x) = 2^k exp(r), x = k ln2 + r, |r| <= ln2/2: k by rounding x / ln2 (the 1.5 * 2^52 shift),
r by Cody-Waite reduction (ln2 split so that k ln2_hi and x - k ln2_hi are exact), exp(r) - 1 - r
by its Taylor polynomial to degree 13 (truncation below 2^-57 on |r| <= ln2/2), and the final
sum 2^k + 2^k r in Fast2Sum form so that only one rounding of size 1/2 ulp remains. Measured
against correctly rounded values (tests/test_vector_math.py): every result within 1 ulp, about
98.5 % correctly rounded (the C library's: all but about 1 in 10^4). In the map this is far below
what the argument's own rounding moves the result: exp(-s) of a squared distance s known to
1/2 ulp(s) moves by s/2 ulp(1), up to ~50 ulps for the s <= 100 of a prototype's neighbourhood.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from gb_pin._jit import njit

INV_LN2 = float.fromhex("0x1.71547652b82fep+0")  # 1/ln 2, rounded
LN2_HI = float.fromhex("0x1.62e42fee00000p-1")  # ln 2 to 32 bits: k LN2_HI is exact for |k| < 2^21
LN2_LO = float.fromhex("0x1.a39ef35793c76p-33")  # ln 2 - LN2_HI, rounded
SHIFT = float.fromhex("0x1.8p52")  # x + SHIFT rounds x to an integer, kept in the low bits
# 1/j! for j = 2..13, rounded (tests/test_vector_math.py recomputes every constant).
C2, C3, C4, C5, C6, C7, C8, C9, C10, C11, C12, C13 = (1.0 / math.factorial(j) for j in range(2, 14))
BIAS = np.uint64(1023)  # the exponent bias of float64
MANTISSA = np.uint64(52)  # the mantissa's bits
#: vexp's arguments must lie in [-VEXP_LIMIT, VEXP_LIMIT] (results and 2^k r stay normal numbers).
VEXP_LIMIT = 700.0


@intrinsic
def _bits(typingctx: Any, x: Any) -> Any:
    """The IEEE bits of a float64 as a uint64 (a bit cast, no conversion)."""

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        return builder.bitcast(args[0], ir.IntType(64))

    return types.uint64(types.float64), codegen


@intrinsic
def _double(typingctx: Any, b: Any) -> Any:
    """The float64 whose IEEE bits are the uint64 ``b`` (a bit cast)."""

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        return builder.bitcast(args[0], ir.DoubleType())

    return types.float64(types.uint64), codegen


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def vexp(x):  # type: ignore[no-untyped-def]
    """exp(x) within 1 ulp for |x| <= VEXP_LIMIT (not checked: callers take ``math.exp`` outside)."""
    kd = INV_LN2 * x + SHIFT
    ki = _bits(kd)  # the low bits hold k + 2^51
    kd -= SHIFT
    rh = x - kd * LN2_HI  # exact
    rl = -(kd * LN2_LO)
    r = rh + rl
    p = C12 + r * C13
    p = C11 + r * p
    p = C10 + r * p
    p = C9 + r * p
    p = C8 + r * p
    p = C7 + r * p
    p = C6 + r * p
    p = C5 + r * p
    p = C4 + r * p
    p = C3 + r * p
    p = C2 + r * p
    scale = _double((ki + BIAS) << MANTISSA)  # 2^k (the 2^51 of the low bits shifts out)
    a = scale * rh  # exact: a power of two times a double
    s = scale + a
    e = a - (s - scale)  # Fast2Sum: s + e = scale + a exactly
    return s + (e + scale * (rl + r * r * p))
