"""Tests of gb_pin.learn.metrics: the evaluation schedule and the speed measure S(Q, e) of paper Eq. 11."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gb_pin import InvalidArgumentError, evaluation_schedule, speed


def check_schedule(schedule: np.ndarray, movements: int, dense_until: int) -> None:
    """Integer, starts at 0, strictly increasing, dense part complete, ends at ``movements``."""
    assert np.issubdtype(schedule.dtype, np.integer)
    assert schedule[0] == 0
    assert np.all(np.diff(schedule) > 0)  # sorted and unique
    assert schedule[-1] == movements
    dense = np.arange(0, min(movements, dense_until) + 1)
    np.testing.assert_array_equal(schedule[: dense.size], dense)


@pytest.mark.parametrize("movements", [1, 7, 999, 1000])
def test_schedule_up_to_dense_limit_is_every_movement(movements: int) -> None:
    """Up to 1000 movements every count 0..movements is recorded."""
    schedule = evaluation_schedule(movements)
    check_schedule(schedule, movements, 1000)
    np.testing.assert_array_equal(schedule, np.arange(movements + 1))


@pytest.mark.parametrize("movements", [1001, 1234, 10_000, 12_345, 10**7])
def test_schedule_beyond_dense_limit(movements: int) -> None:
    """Beyond 1000: at least 50 log-spaced counts per decade, including the final count.

    The log-spaced points have log10 step log10(M / 1000) / ceil(50 log10(M / 1000)) <= 1/50;
    rounding to integers moves log10 of a count c by at most 0.5 / (c ln 10).
    """
    schedule = evaluation_schedule(movements)
    check_schedule(schedule, movements, 1000)
    sparse = schedule[schedule >= 1000].astype(float)
    decades = math.log10(movements / 1000)
    steps = math.ceil(50 * decades)
    assert sparse.size == steps + 1
    step = decades / steps
    assert step <= 1 / 50 + 1e-15
    rounding = 0.5 / (sparse[:-1] * math.log(10)) + 0.5 / (sparse[1:] * math.log(10))
    assert np.all(np.abs(np.diff(np.log10(sparse)) - step) <= rounding + 1e-12)


def test_schedule_per_decade_count() -> None:
    """Exactly per_decade counts per decade when the run spans whole decades."""
    schedule = evaluation_schedule(10**6, per_decade=10)
    for lo in (10**3, 10**4, 10**5):
        assert np.sum((schedule > lo) & (schedule <= 10 * lo)) == 10
    np.testing.assert_array_equal(schedule[schedule >= 1000][::10], [10**3, 10**4, 10**5, 10**6])


def test_schedule_dense_until_options() -> None:
    """dense_until changes the dense part; dense_until = 0 starts the log spacing at 1."""
    check_schedule(evaluation_schedule(500, dense_until=100), 500, 100)
    schedule = evaluation_schedule(50, dense_until=0)
    check_schedule(schedule, 50, 0)
    assert schedule[1] == 1


@pytest.mark.parametrize(
    "kwargs",
    [{"movements": 0}, {"movements": -5}, {"movements": 2.5}, {"movements": 10, "per_decade": 0}],
)
def test_schedule_rejects_bad_arguments(kwargs: dict[str, object]) -> None:
    """movements must be an integer >= 1, per_decade >= 1."""
    with pytest.raises(InvalidArgumentError):
        evaluation_schedule(**kwargs)  # type: ignore[arg-type]


MOVEMENTS = np.array([0, 10, 20, 30, 40])
ERRORS = np.array(
    [
        [1.0, 0.5, 0.09, 0.05, 0.01],
        [1.0, 0.08, 0.2, 0.05, 0.02],  # reaches 0.1 at 10, leaves it again at 20
        [1.0, 0.9, 0.7, 0.1, 0.05],  # exactly at the level at 30
        [1.0, 1.0, 1.0, 1.0, 0.5],  # never reaches 0.1
    ]
)
# Fraction of trials with E <= 0.1 per column: 0, 1/4, 1/4, 3/4, 3/4.


@pytest.mark.parametrize(
    ("quantile", "level", "expected"),
    [
        (0.25, 0.1, 10),
        (0.5, 0.1, 30),
        (0.75, 0.1, 30),  # needs E <= e inclusive (trial 3 has exactly 0.1)
        (1.0, 0.1, None),
        (0.5, 0.05, 30),
        (0.5, 0.01, None),
        (1.0, 1.0, 0),
        (1.0, 0.5, 40),
    ],
)
def test_speed_on_hand_made_trials(quantile: float, level: float, expected: int | None) -> None:
    """S(Q, e) is the first recorded count where a fraction >= Q of trials has E <= e (Eq. 11), else None."""
    assert speed(MOVEMENTS, ERRORS, quantile, level) == expected


def test_speed_returns_counts_not_indices() -> None:
    """The result is the recorded movement count, for a non-uniform schedule too, as a Python int."""
    movements = np.array([0, 1, 2, 5, 100, 3000])
    errors = np.array([[0.9, 0.8, 0.7, 0.6, 0.05, 0.01], [0.9, 0.8, 0.7, 0.6, 0.5, 0.01]])
    result = speed(movements, errors, 0.5, 0.1)
    assert result == 100
    assert type(result) is int
    assert speed(movements, errors, 1.0, 0.1) == 3000


def test_speed_single_trial() -> None:
    """A 1-D error curve is one trial."""
    assert speed([0, 10, 20], [0.3, 0.2, 0.1], 1.0, 0.2) == 10
    assert speed([0, 10, 20], [0.3, 0.2, 0.1], 1.0, 0.05) is None


@pytest.mark.parametrize("quantile", [0.0, -0.5, 1.5, float("nan")])
def test_speed_rejects_bad_quantile(quantile: float) -> None:
    """Q must lie in (0, 1]."""
    with pytest.raises(InvalidArgumentError, match="quantile"):
        speed(MOVEMENTS, ERRORS, quantile, 0.1)


def test_speed_rejects_mismatched_lengths() -> None:
    """errors must have as many columns as there are recorded movement counts."""
    with pytest.raises(InvalidArgumentError):
        speed([0, 10, 20], [[1.0, 0.05, 0.01, 0.0]], 1.0, 0.1)


def test_reach_median_equals_the_median_of_np_sort_nans_last() -> None:
    """reach_median's insertion sort gives np.sort's median bit for bit (NaNs last, ties, any count)."""
    from gb_pin.learn.metrics import reach_median

    rng = np.random.default_rng(0)
    for t in range(2000):
        width = int(rng.integers(1, 60))
        ring = rng.exponential(size=width)
        if t % 3 == 0:
            ring[rng.integers(0, width, size=rng.integers(0, 3))] = np.nan
        if t % 5 == 0:
            ring = np.round(ring, 1)  # ties
        count = int(rng.integers(0, 80))
        k = min(count, width)
        values = np.sort(ring[:k])
        expected = (
            np.nan if k == 0 else values[k // 2] if k % 2 else 0.5 * (values[k // 2 - 1] + values[k // 2])
        )
        got = reach_median(ring, count)
        assert (np.isnan(expected) and np.isnan(got)) or got == expected
