"""Tests of gb_pin.learn.exploration: the structured continuous variation of paper Sec. II-B (Eq. 8).

Statistical tolerances: a sum of k squared i.i.d. N(0, s^2) values divided by s^2 is
chi-square with k degrees of freedom; its bounds are taken at +-Z standard normal
quantiles with the Wilson-Hilferty approximation (accurate to < 1e-3 relative for
k > 1000). Z = 5 makes a false failure of any one check a ~6e-7 event, so the seeds
below are not tuned to pass.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gb_pin import InvalidArgumentError
from gb_pin.learn.exploration import StructuredNoise, noise_add, noise_init, noise_walk

Z = 5.0


def chi2_bounds(k: int, z: float = Z) -> tuple[float, float]:
    """(lower, upper) quantiles of chi-square(k) at -z and +z standard deviations (Wilson-Hilferty)."""
    c = 2.0 / (9.0 * k)
    return k * (1.0 - c - z * math.sqrt(c)) ** 3, k * (1.0 - c + z * math.sqrt(c)) ** 3


def assert_variance(values: np.ndarray, sigma: float) -> None:
    """Zero-mean values are i.i.d. N(0, sigma^2) as far as their sum of squares can tell."""
    k = values.size
    lo, hi = chi2_bounds(k)
    stat = float(np.sum(values**2)) / sigma**2
    assert lo < stat < hi, f"sum e^2 / sigma^2 = {stat:.1f} not in ({lo:.1f}, {hi:.1f}) for k = {k}"
    # The mean of k N(0, sigma^2) values has standard deviation sigma / sqrt(k).
    assert abs(values.mean()) < Z * sigma / math.sqrt(k)


def test_chi2_bounds_sanity() -> None:
    """The chi-square helper brackets k and widens like sqrt(2k) (mean k, variance 2k)."""
    lo, hi = chi2_bounds(10_000)
    assert lo < 10_000 < hi
    assert hi - lo == pytest.approx(2 * Z * math.sqrt(2 * 10_000), rel=0.01)


@pytest.mark.parametrize("sigma", [0.05, 1.0])
def test_initial_entries_are_normal_with_variance_sigma2(sigma: float) -> None:
    """A_0 and b_0 have i.i.d. N(0, sigma^2) entries (Eq. 8)."""
    noise = StructuredNoise(200, 50, sigma, 0.1 * sigma, np.random.default_rng(1))
    assert noise.A.shape == (200, 50)
    assert noise.b.shape == (200,)
    assert_variance(np.concatenate([noise.A.ravel(), noise.b]), sigma)


@pytest.mark.parametrize(("sigma", "sigma_delta"), [(0.05, 0.005), (1.0, 1.0)])
def test_walk_keeps_variance_sigma2(sigma: float, sigma_delta: float) -> None:
    """The normalised walk keeps every entry N(0, sigma^2) over hundreds of steps (Eq. 8).

    Sized to its margin: k = 2000 entries put the chi-square bounds at about +-16 % of
    k (Z = 5). An unnormalised walk would have variance (1 + t sigma_delta^2 / sigma^2)
    sigma^2: 2 sigma^2 at t = 100 and 5 sigma^2 at t = 400 for the paper's sigma_delta =
    0.1 sigma, and 2 sigma^2 from t = 1 for sigma_delta = sigma, far outside the bounds.
    """
    rng = np.random.default_rng(2)
    A = np.empty((200, 9))
    b = np.empty(200)
    noise_init(rng, sigma, A, b)
    checkpoints = {1, 10, 100, 400}
    for t in range(1, 401):
        noise_walk(rng, sigma, sigma_delta, A, b)
        if t in checkpoints:
            assert_variance(np.concatenate([A.ravel(), b]), sigma)
    # Explicitly: nowhere near the unnormalised sigma^2 + t sigma_delta^2.
    variance = np.mean(np.concatenate([A.ravel(), b]) ** 2)
    assert variance < 0.5 * (sigma**2 + (sigma**2 + 400 * sigma_delta**2))


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_walk_increments_are_small_and_correlation_is_rho() -> None:
    """Successive values have lag-1 correlation rho = sqrt(sigma^2 / (sigma^2 + sigma_delta^2)).

    With e_{t+1} = rho (e_t + delta): the pooled slope sum e_t e_{t+1} / sum e_t^2 over
    N entries and T steps estimates rho with standard deviation rho sigma_delta / (sigma sqrt(N T))
    (~2e-5 here), far below 1 - rho = 0.005 (an unnormalised walk has slope 1).
    The increments delta = e_{t+1} / rho - e_t are i.i.d. N(0, sigma_delta^2).
    """
    sigma, sigma_delta = 0.05, 0.005
    rho = math.sqrt(sigma**2 / (sigma**2 + sigma_delta**2))
    rng = np.random.default_rng(3)
    A = np.empty((1000, 10))
    b = np.empty(1000)
    noise_init(rng, sigma, A, b)
    T = 2000
    N = A.size + b.size
    cross = 0.0
    square = 0.0
    delta_square = 0.0
    prev = np.concatenate([A.ravel(), b])
    for _ in range(T):
        noise_walk(rng, sigma, sigma_delta, A, b)
        now = np.concatenate([A.ravel(), b])
        cross += float(prev @ now)
        square += float(prev @ prev)
        delta_square += float(np.sum((now / rho - prev) ** 2))
        prev = now
    slope = cross / square
    sd = rho * sigma_delta / (sigma * math.sqrt(N * T))
    assert abs(slope - rho) < Z * sd
    lo, hi = chi2_bounds(N * T)
    assert lo < delta_square / sigma_delta**2 < hi


def test_same_seed_same_noise() -> None:
    """Two StructuredNoise with Generators of the same seed draw identical A_t, b_t; another seed differs."""
    runs = []
    for seed in (4, 4, 5):
        noise = StructuredNoise(5, 2, 0.05, 0.005, np.random.default_rng(seed))
        history = []
        for _ in range(50):
            noise.step()
            history.append(np.concatenate([noise.A.ravel(), noise.b]))
        runs.append(np.array(history))
    np.testing.assert_array_equal(runs[0], runs[1])
    assert not np.array_equal(runs[0], runs[2])


@pytest.mark.parametrize("seed", [0, 1, 12345])
def test_compiled_draws_equal_numpy_draws(seed: int) -> None:
    """noise_init/noise_walk consume the Generator exactly as numpy does: A row-major, then b.

    noise_init(seed) equals sigma * rng.standard_normal(m n + m); one walk step equals
    rho (e + sigma_delta z) with the next m n + m numpy draws; afterwards both
    Generators are in the same state.
    """
    m, n, sigma, sigma_delta = 7, 3, 0.05, 0.005
    rng = np.random.default_rng(seed)
    A = np.empty((m, n))
    b = np.empty(m)
    noise_init(rng, sigma, A, b)
    ref = np.random.default_rng(seed)
    z = ref.standard_normal(m * n + m)
    np.testing.assert_array_equal(A, sigma * z[: m * n].reshape(m, n))
    np.testing.assert_array_equal(b, sigma * z[m * n :])

    rho = math.sqrt(sigma * sigma / (sigma * sigma + sigma_delta * sigma_delta))
    A0, b0 = A.copy(), b.copy()
    noise_walk(rng, sigma, sigma_delta, A, b)
    z = ref.standard_normal(m * n + m)
    # Same operations in the same order: equal up to at most one rounding (1 ulp).
    np.testing.assert_allclose(A, rho * (A0 + sigma_delta * z[: m * n].reshape(m, n)), rtol=2 * 2.0**-52)
    np.testing.assert_allclose(b, rho * (b0 + sigma_delta * z[m * n :]), rtol=2 * 2.0**-52)
    assert rng.standard_normal() == ref.standard_normal()


def test_structured_noise_uses_the_given_generator() -> None:
    """StructuredNoise draws A_0, b_0 from the Generator it is given (no global state)."""
    noise = StructuredNoise(4, 2, 0.3, 0.01, np.random.default_rng(8))
    z = np.random.default_rng(8).standard_normal(12)
    np.testing.assert_array_equal(noise.A, 0.3 * z[:8].reshape(4, 2))
    np.testing.assert_array_equal(noise.b, 0.3 * z[8:])


def test_noise_add_is_affine_map() -> None:
    """noise_add adds A x + b to q in place; StructuredNoise(x) returns E(x) = A x + b (Eq. 8)."""
    rng = np.random.default_rng(9)
    A = rng.normal(size=(5, 3))
    b = rng.normal(size=5)
    x = rng.normal(size=3)
    q = rng.normal(size=5)
    expected = q + A @ x + b
    noise_add(A, b, x, q)
    # Three-term dot products plus b: a few eps of the magnitudes involved.
    np.testing.assert_allclose(q, expected, rtol=0, atol=1e-14 * (np.abs(expected).max() + 1.0))

    noise = StructuredNoise(5, 3, 0.05, 0.005, np.random.default_rng(10))
    E = noise(x)
    assert E.shape == (5,)
    np.testing.assert_allclose(E, noise.A @ x + noise.b, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(noise(np.zeros(3)), noise.b)


def test_zero_sigma_gives_zero_noise() -> None:
    """sigma = 0 gives E = 0 at every step (the walk's normalisation factor is 0)."""
    noise = StructuredNoise(3, 2, 0.0, 0.01, np.random.default_rng(11))
    for _ in range(5):
        noise.step()
        np.testing.assert_array_equal(noise.A, 0.0)
        np.testing.assert_array_equal(noise.b, 0.0)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"sigma": -0.1},
        {"sigma": np.nan},
        {"sigma_delta": -0.01},
        {"sigma_delta": np.inf},
        {"n_joints": 0},
        {"n_task": 0},
        {"n_joints": 2.5},
    ],
)
def test_structured_noise_rejects_bad_arguments(kwargs: dict[str, object]) -> None:
    """Negative or non-finite deviations and non-positive sizes raise InvalidArgumentError."""
    args: dict[str, object] = {"n_joints": 3, "n_task": 2, "sigma": 0.05, "sigma_delta": 0.005}
    args.update(kwargs)
    with pytest.raises(InvalidArgumentError, match=next(iter(kwargs))):
        StructuredNoise(rng=np.random.default_rng(0), **args)  # type: ignore[arg-type]
