"""The loop's uniform goal index draws exactly what numpy's Generator.integers(0, N) draws."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from gb_pin.learn.goals.draw import _integers, uniform_index


@njit(cache=True)
def _draws(rng, count, out):  # type: ignore[no-untyped-def]
    for i in range(out.shape[0]):
        out[i] = uniform_index(rng, count)


@pytest.mark.parametrize(
    "count", [1, 2, 3, 7, 25, 1000, 10**6, 2**31 + 5, 2**32 - 1, 2**32, 2**32 + 1, 3 * 2**40]
)
@pytest.mark.parametrize("seed", [0, 1, 12345])
def test_uniform_index_equals_numpy(count: int, seed: int) -> None:
    """Same numbers, and the Generators in the same state afterwards (the rejections included)."""
    rng = np.random.default_rng(seed)
    ref = np.random.default_rng(seed)
    out = np.empty(2000, dtype=np.int64)
    _draws(rng, count, out)
    expected = np.array([ref.integers(0, count) for _ in range(out.shape[0])], dtype=np.int64)
    np.testing.assert_array_equal(out, expected)
    assert out.min() >= 0 and out.max() < count
    assert rng.random() == ref.random()
    assert rng.bit_generator.state == ref.bit_generator.state


def test_uniform_index_after_a_half_used_uint32() -> None:
    """A 32-bit draw after a single 32-bit draw uses the buffered half, as numpy does."""
    rng = np.random.default_rng(5)
    ref = np.random.default_rng(5)
    out = np.empty(5, dtype=np.int64)
    _draws(rng, 2**32, out[:1])  # one plain 32-bit draw: half a 64-bit word left
    ref.integers(0, 2**32)
    _draws(rng, 25, out)
    np.testing.assert_array_equal(out, [ref.integers(0, 25) for _ in range(5)])
    assert rng.bit_generator.state == ref.bit_generator.state


@njit(cache=True)
def _fallback_draws(rng, count, out):  # type: ignore[no-untyped-def]
    for i in range(out.shape[0]):
        out[i] = _integers(rng, count)


@pytest.mark.parametrize("count", [1, 25, 2**32 + 1])
def test_the_fallback_for_another_numba_draws_the_same(count: int) -> None:
    """Should numba move its internals, Generator.integers is used: the same numbers again."""
    a, b = np.random.default_rng(3), np.random.default_rng(3)
    out_a, out_b = np.empty(500, dtype=np.int64), np.empty(500, dtype=np.int64)
    _draws(a, count, out_a)
    _fallback_draws(b, count, out_b)
    np.testing.assert_array_equal(out_a, out_b)
    assert a.bit_generator.state == b.bit_generator.state
