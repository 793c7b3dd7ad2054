"""Tests of gb_pin.learn.weighting: the example weights of paper Eqs. 4-6."""

from __future__ import annotations

import numpy as np
import pytest

from gb_pin.learn.weighting import direction_weight, efficiency_weight, example_weight


def w_dir(target: np.ndarray, target_prev: np.ndarray, x: np.ndarray, x_prev: np.ndarray) -> float:
    """Eq. 4 in numpy: (1 + cos angle(x*_t - x*_{t-1}, x_t - x_{t-1})) / 2."""
    a = np.asarray(target) - np.asarray(target_prev)
    b = np.asarray(x) - np.asarray(x_prev)
    return 0.5 * (1.0 + float(a @ b) / (np.linalg.norm(a) * np.linalg.norm(b)))


def w_eff(x: np.ndarray, x_prev: np.ndarray, q: np.ndarray, q_prev: np.ndarray) -> float:
    """Eq. 5 in numpy: ||x_t - x_{t-1}|| / ||q_t - q_{t-1}||."""
    return float(np.linalg.norm(np.asarray(x) - x_prev) / np.linalg.norm(np.asarray(q) - q_prev))


def arr(*values: float) -> np.ndarray:
    return np.array(values, dtype=float)


def test_direction_weight_special_angles() -> None:
    """w_dir is 1 for the same direction, 0 for the opposite one, 1/2 for orthogonal ones (Eq. 4)."""
    origin = arr(0.3, -0.1)
    along = origin + arr(0.02, 0.01)
    # Same direction, different lengths: cos = 1 up to rounding of the norms.
    assert direction_weight(along, origin, origin + arr(0.4, 0.2), origin) == pytest.approx(1.0, abs=1e-15)
    assert direction_weight(along, origin, origin - arr(0.4, 0.2), origin) == pytest.approx(0.0, abs=1e-15)
    assert direction_weight(along, origin, origin + arr(-0.1, 0.2), origin) == pytest.approx(0.5, abs=1e-15)
    # Exact for axis-aligned displacements.
    z = np.zeros(3)
    assert direction_weight(arr(1, 0, 0), z, arr(2, 0, 0), z) == 1.0
    assert direction_weight(arr(1, 0, 0), z, arr(-3, 0, 0), z) == 0.0
    assert direction_weight(arr(1, 0, 0), z, arr(0, 0, 5), z) == 0.5


def test_direction_weight_zero_displacement() -> None:
    """w_dir = 1/2 (cosine taken as 0) when the intended or the observed displacement is zero."""
    p = arr(0.5, 0.2)
    moved = arr(0.6, 0.1)
    assert direction_weight(p, p, moved, p) == 0.5
    assert direction_weight(moved, p, p, p) == 0.5
    assert direction_weight(p, p, p, p) == 0.5


def test_direction_weight_stays_in_unit_interval() -> None:
    """Rounding never pushes w_dir outside [0, 1], even for (anti)parallel tiny displacements."""
    rng = np.random.default_rng(0)
    for _ in range(200):
        a = rng.normal(size=3) * 10.0 ** rng.uniform(-8, 2)
        scale = 10.0 ** rng.uniform(-8, 2)
        origin = rng.normal(size=3)
        for sign in (1.0, -1.0):
            w = direction_weight(origin + a, origin, origin + sign * scale * a, origin)
            assert 0.0 <= w <= 1.0


def test_efficiency_weight() -> None:
    """w_eff = ||dx|| / ||dq|| (Eq. 5), and 0 when the posture did not move."""
    x_prev, x = arr(0.0, 0.0), arr(0.3, 0.4)  # ||dx|| = 0.5
    q_prev, q = arr(1.0, 1.0, 1.0), arr(1.0, 3.0, 1.0)  # ||dq|| = 2
    assert efficiency_weight(x, x_prev, q, q_prev) == 0.25
    assert efficiency_weight(x, x_prev, q_prev, q_prev) == 0.0
    assert efficiency_weight(x_prev, x_prev, q_prev, q_prev) == 0.0
    assert efficiency_weight(x_prev, x_prev, q, q_prev) == 0.0


def test_example_weight_is_product() -> None:
    """example_weight = w_dir * w_eff (Eq. 6), accepting lists."""
    w = example_weight([1.0, 0.0], [0.0, 0.0], [0.0, 0.5], [0.0, 0.0], [0.0, 2.0], [0.0, 0.0])
    assert w == 0.5 * 0.25  # orthogonal (w_dir = 1/2), ||dx|| / ||dq|| = 0.5 / 2
    assert example_weight([1.0], [0.0], [-1.0], [0.0], [3.0], [0.0]) == 0.0
    assert isinstance(w, float)


@pytest.mark.parametrize(("n", "m"), [(1, 1), (2, 5), (3, 7), (3, 50)])
def test_weights_match_numpy_formula(n: int, m: int) -> None:
    """Random displacements: the compiled weights equal Eqs. 4-6 written in numpy.

    Both sides compute the same handful of sums and one square root; they agree to a
    few eps relative (1e-13 allows for the differing summation orders).
    """
    rng = np.random.default_rng(10 * n + m)
    for _ in range(50):
        target_prev, x_prev = rng.normal(size=(2, n))
        target = target_prev + rng.normal(scale=0.05, size=n)
        x = x_prev + rng.normal(scale=0.05, size=n)
        q_prev = rng.normal(size=m)
        q = q_prev + rng.normal(scale=0.1, size=m)
        expected_dir = w_dir(target, target_prev, x, x_prev)
        expected_eff = w_eff(x, x_prev, q, q_prev)
        assert direction_weight(target, target_prev, x, x_prev) == pytest.approx(
            expected_dir, rel=1e-13, abs=1e-15
        )
        assert efficiency_weight(x, x_prev, q, q_prev) == pytest.approx(expected_eff, rel=1e-13)
        assert example_weight(target, target_prev, x, x_prev, q, q_prev) == pytest.approx(
            expected_dir * expected_eff, rel=1e-13, abs=1e-15
        )


def test_direction_weight_is_scale_invariant() -> None:
    """w_dir depends only on the angle: scaling either displacement by c > 0 leaves it unchanged.

    Displacements start at the origin so that they are exact; c * a then carries one
    rounding, and w_dir changes by a few eps at most.
    """
    rng = np.random.default_rng(3)
    p = np.zeros(2)
    for _ in range(20):
        a, b = rng.normal(size=(2, 2))
        c = 10.0 ** rng.uniform(-3, 3)
        base = direction_weight(a, p, b, p)
        assert direction_weight(c * a, p, b, p) == pytest.approx(base, abs=1e-14)
        assert direction_weight(a, p, c * b, p) == pytest.approx(base, abs=1e-14)
