"""Tests of gb_pin.learn.vector_math: the map's exp, against correctly rounded values.

References are computed with Python's decimal module at 50 digits and rounded once to a
double (correct rounding). The bound is the module's: every result within 1 ulp; the fraction
of correctly rounded results was measured at 98.5 % over [-700, 700] (the C library's exp: all
but about 1 in 10^4 on the same points), and 95 % is required so that a lost bit of accuracy in
the reduction or the polynomial (which costs a third of the results or more) fails.
"""

from __future__ import annotations

import math
from decimal import Decimal, getcontext

import numpy as np
import pytest
from numba import njit

from gb_pin import LocalLinearMap
from gb_pin.learn import vector_math as vm
from gb_pin.learn.llm_kernels import llm_predict

getcontext().prec = 50


@njit(error_model="numpy")
def _vexp_all(x, out):  # type: ignore[no-untyped-def]
    for k in range(x.shape[0]):  # the loop LLVM vectorises, as in the map
        out[k] = vm.vexp(x[k])


def _vexp(x: np.ndarray) -> np.ndarray:
    out = np.empty_like(x)
    _vexp_all(np.ascontiguousarray(x, dtype=float), out)
    return out


def _exact(x: np.ndarray) -> np.ndarray:
    return np.array([float(Decimal(float(v)).exp()) for v in x])


def _ulps(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs(a.view(np.int64) - b.view(np.int64))  # positive doubles: ulps apart


def test_constants_are_what_their_comments_say() -> None:
    """1/ln 2 and 1/j! rounded to nearest; ln 2 split into 32 exact bits plus the rounded rest."""
    ln2 = Decimal(2).ln()
    assert float(1 / ln2) == vm.INV_LN2
    mantissa, _ = math.frexp(vm.LN2_HI)
    assert mantissa * 2**32 == int(mantissa * 2**32)  # 32 significant bits: k LN2_HI exact for |k| < 2^21
    assert abs(Decimal(vm.LN2_HI) + Decimal(vm.LN2_LO) - ln2) < Decimal(2) ** -85
    for j, c in enumerate([vm.C2, vm.C3, vm.C4, vm.C5, vm.C6, vm.C7, vm.C8, vm.C9, vm.C10, vm.C11, vm.C12,
                           vm.C13], start=2):  # fmt: skip
        assert c == float(1 / Decimal(math.factorial(j)))


def test_vexp_is_within_one_ulp_and_mostly_correctly_rounded() -> None:
    """Over the range the map uses (and its mirror), near 0, and at its ends."""
    rng = np.random.default_rng(0)
    x = np.concatenate([
        -rng.uniform(0, vm.VEXP_LIMIT, 1500), rng.uniform(0, vm.VEXP_LIMIT, 300), rng.uniform(-1, 1, 700),
        rng.uniform(-1e-8, 1e-8, 200), [0.0, -0.0, -vm.VEXP_LIMIT, vm.VEXP_LIMIT, 5e-324, -1e-300],
        np.log(2.0) * np.arange(-10, 11) + 0.5 * np.log(2.0),  # the ends of the reduced range
    ])  # fmt: skip
    got, exact = _vexp(x), _exact(x)
    ulps = _ulps(got, exact)
    assert ulps.max() <= 1
    assert np.mean(ulps == 0) >= 0.95
    assert _vexp(np.array([0.0]))[0] == 1.0


def test_vexp_in_and_out_of_simd_loops_gives_the_same_bits() -> None:
    """One element at a time (scalar code) and whole arrays (SIMD code, with tails) agree."""
    x = -np.random.default_rng(1).uniform(0, 60, 37)
    whole = _vexp(x)
    one_by_one = np.array([_vexp(x[k : k + 1])[0] for k in range(x.shape[0])])
    np.testing.assert_array_equal(whole, one_by_one)


@pytest.mark.parametrize("far", [26.0, 26.9, 27.2, 40.0, 1e6])
def test_prototypes_beyond_the_range_take_the_c_library(far: float) -> None:
    """A prototype ``far`` radii beyond the nearest (||u||^2 - min > 700 from 26.5 radii) gets math.exp."""
    d = 0.1
    lm = LocalLinearMap.from_arrays(
        {"prototypes": np.array([[0.0, 0.0], [far * d, 0.0]]), "matrices": np.zeros((2, 3, 2)),
         "offsets": np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])}, radius=d,
    )  # fmt: skip
    g = lm.predict(np.zeros(2), warn=False)
    u = (0.0 - far * d) * (1.0 / d)  # the kernel's arithmetic
    argument = 0.0 - (0.0 + u * u)
    act = lm.kernel().act[:2]
    if argument >= -vm.VEXP_LIMIT:
        assert act[0] == 1.0 and _ulps(act[1:], _exact(np.array([argument]))).max() <= 1
    else:
        np.testing.assert_array_equal(act, [1.0, math.exp(argument)])  # subnormal or 0: the C library's
    np.testing.assert_allclose(g, [1.0, 2.0, 3.0], rtol=1e-12)


def test_a_nan_input_gives_nan() -> None:
    """NaN distances stay NaN (as math.exp's), whatever the clamp does to vexp's argument."""
    lm = LocalLinearMap(radius=0.1).initialize(np.zeros(2), np.ones(3))
    out = np.empty(3)
    llm_predict(np.array([np.nan, 0.0]), lm.kernel(), 1, out)
    assert np.isnan(lm.kernel().act[0]) and np.all(np.isnan(out))
