"""Tests of gb_pin.learn.llm: the local-linear map of paper Sec. II-C.

Expected values are recomputed here in plain numpy from the formulas of Sec. II-C
(and the module's documented conventions: W_k acts on u_k = (x - p_k) / d, the
factor 2 of the gradient is folded into the learning rate), never read back from
the compiled kernels.
"""

from __future__ import annotations

import numpy as np
import pytest

from gb_pin import InvalidArgumentError, LocalLinearMap


def random_map(
    seed: int, n: int, m: int, radius: float = 0.3, eta: float = 0.5, samples: int = 40
) -> tuple[LocalLinearMap, np.random.Generator]:
    """A map with several prototypes and non-trivial W_k, o_k, learnt from random data."""
    rng = np.random.default_rng(seed)
    llm = LocalLinearMap(radius=radius, learning_rate=eta).initialize(
        rng.uniform(-1.0, 1.0, n), rng.normal(size=m)
    )
    X = rng.uniform(-1.0, 1.0, (samples, n))
    Q = rng.normal(size=(samples, m))
    w = rng.uniform(0.0, 1.0, samples)
    llm.partial_fit(X, Q, w)
    return llm, rng


def reference(x: np.ndarray, llm: LocalLinearMap) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(g(x), beta (K,), U (K, n)) from the soft-max formula of Sec. II-C, unshifted.

    Only valid near the prototypes (no underflow guard), which is where it is used.
    """
    d = llm.radius
    U = (x - llm.prototypes_) / d
    a = np.exp(-np.sum(U**2, axis=1))
    beta = a / a.sum()
    Y = np.einsum("kij,kj->ki", llm.matrices_, U) + llm.offsets_
    return beta @ Y, beta, U


# -- (a) initial map ---------------------------------------------------------------------
@pytest.mark.parametrize(("n", "m"), [(1, 1), (2, 5), (3, 7)])
def test_initial_map_is_constant_home_posture(n: int, m: int) -> None:
    """initialize(x0, q0) gives g(x) = q0 everywhere, with one prototype at x0 and W = 0."""
    rng = np.random.default_rng(100 + n * 10 + m)
    x0 = rng.uniform(-1.0, 1.0, n)
    q0 = rng.normal(size=m)
    llm = LocalLinearMap(radius=0.1, learning_rate=0.1).initialize(x0, q0)
    assert llm.n_prototypes_ == 1
    np.testing.assert_array_equal(llm.prototypes_, x0[None])
    np.testing.assert_array_equal(llm.matrices_, np.zeros((1, m, n)))
    # Near x0, far from it (u^2 ~ 1e6) and at x0 itself: a single normalised
    # responsibility is exactly 1, so the output is q0 exactly.
    X = np.vstack([x0, x0 + rng.normal(scale=0.05, size=(20, n)), x0 + 100.0])
    np.testing.assert_array_equal(llm.predict(X), np.tile(q0, (X.shape[0], 1)))
    np.testing.assert_array_equal(llm.jacobian(x0 + 0.3), np.zeros((m, n)))


def test_predict_matches_soft_max_formula() -> None:
    """predict equals g(x) = sum_k beta_k (W_k u_k + o_k) with normalised Gaussian beta_k (Sec. II-C)."""
    for seed in range(3):
        llm, rng = random_map(seed, n=2, m=4)
        assert llm.n_prototypes_ > 3
        for x in rng.uniform(-1.2, 1.2, (10, 2)):
            g, _, _ = reference(x, llm)
            # Rounding of a K-term convex combination: a few eps times the largest term.
            scale = np.abs(llm.offsets_).max() + np.abs(llm.matrices_).max() * 10.0
            np.testing.assert_allclose(llm.predict(x), g, rtol=0, atol=1e-13 * scale)


# -- (b) Jacobian vs finite differences ---------------------------------------------------
@pytest.mark.parametrize("m", range(1, 8))
@pytest.mark.parametrize("n", [1, 2, 3])
def test_jacobian_matches_central_differences(n: int, m: int) -> None:
    """jacobian(x) equals central finite differences of predict, responsibilities' derivative included.

    With step h = 1e-6 and the map's length scale d = 0.3, the central-difference
    truncation error is ~ (h/d)^2 |g|/d ~ 1e-11 |g|/d and the rounding error
    ~ eps |g| / h ~ 2e-10 |g|; both are far below the 1e-6 relative tolerance.
    """
    h = 1e-6
    for seed in range(3):
        llm, rng = random_map(1000 * n + 10 * m + seed, n, m)
        assert llm.n_prototypes_ > 1  # the responsibilities vary, their derivative matters
        for x in rng.uniform(-1.2, 1.2, (4, n)):
            J = llm.jacobian(x)
            assert J.shape == (m, n)
            fd = np.empty((m, n))
            for j in range(n):
                step = np.zeros(n)
                step[j] = h
                fd[:, j] = (llm.predict(x + step) - llm.predict(x - step)) / (2.0 * h)
            scale = np.abs(J).max() + np.abs(llm.predict(x)).max() / llm.radius
            np.testing.assert_allclose(J, fd, rtol=0, atol=1e-6 * scale)


# -- (c), (d) prototype insertion ----------------------------------------------------------
def far_enough_point(llm: LocalLinearMap, rng: np.random.Generator, factor: float) -> np.ndarray:
    """A point whose nearest prototype is at distance factor * d (factor >= 1)."""
    d = llm.radius
    n = llm.n_inputs_
    for _ in range(10_000):
        k = rng.integers(llm.n_prototypes_)
        direction = rng.normal(size=n)
        x = llm.prototypes_[k] + factor * d * direction / np.linalg.norm(direction)
        if np.linalg.norm(llm.prototypes_ - x, axis=1).min() >= factor * d * (1 - 1e-12):
            return x
    raise AssertionError("no point found")


@pytest.mark.parametrize(("n", "m"), [(1, 3), (2, 5), (3, 7)])
def test_insertion_keeps_value_and_jacobian(n: int, m: int) -> None:
    """Inserting a prototype at x sets o_new = g(x), W_new = d J(x) and leaves g and J at x unchanged.

    With sample_weight = 0 the step inserts and does nothing else. The new prototype's
    responsibility at x enters a convex combination of equal values (g) and of equal
    slopes (J) in exact arithmetic; what remains is rounding, a few eps times the scale.
    """
    for seed in range(3):
        llm, rng = random_map(7000 + 10 * n + m + 100 * seed, n, m)
        K = llm.n_prototypes_
        x = far_enough_point(llm, rng, factor=1.2)
        g0 = llm.predict(x)
        J0 = llm.jacobian(x)
        llm.partial_fit(x[None], rng.normal(size=(1, m)), sample_weight=[0.0])
        assert llm.n_prototypes_ == K + 1
        np.testing.assert_array_equal(llm.prototypes_[-1], x)
        np.testing.assert_array_equal(llm.offsets_[-1], g0)
        np.testing.assert_allclose(llm.matrices_[-1], llm.radius * J0, rtol=1e-14, atol=0)
        g_scale = np.abs(g0).max()
        j_scale = np.abs(J0).max() + g_scale / llm.radius
        np.testing.assert_allclose(llm.predict(x), g0, rtol=0, atol=1e-12 * g_scale)
        np.testing.assert_allclose(llm.jacobian(x), J0, rtol=0, atol=1e-12 * j_scale)


def test_insertion_threshold_is_the_radius() -> None:
    """A prototype is inserted at distance >= d from all prototypes (1.001 d), not closer (0.999 d)."""
    for seed in range(3):
        llm, rng = random_map(seed, n=2, m=3)
        K = llm.n_prototypes_
        P, W, O = llm.prototypes_.copy(), llm.matrices_.copy(), llm.offsets_.copy()
        near = far_enough_point(llm, rng, factor=1.0)
        # Move it just inside the radius of the nearest prototype.
        k = np.argmin(np.linalg.norm(P - near, axis=1))
        inside = P[k] + 0.999 * (near - P[k])
        llm.partial_fit(inside[None], np.zeros((1, 3)), sample_weight=[0.0])
        assert llm.n_prototypes_ == K
        # Weight 0 and no insertion: nothing at all changes.
        np.testing.assert_array_equal(llm.prototypes_, P)
        np.testing.assert_array_equal(llm.matrices_, W)
        np.testing.assert_array_equal(llm.offsets_, O)
        outside = far_enough_point(llm, rng, factor=1.001)
        llm.partial_fit(outside[None], np.zeros((1, 3)), sample_weight=[0.0])
        assert llm.n_prototypes_ == K + 1


def test_first_distant_sample_creates_second_prototype() -> None:
    """From the initial map, a sample at distance >= d adds prototype 2 with o = q_home and W = 0.

    The initial map is constant, so g(x) = q_home and J(x) = 0 there (Sec. II-C insertion rule).
    """
    q0 = np.array([0.3, -0.2, 0.1])
    llm = LocalLinearMap(radius=0.1, learning_rate=0.1).initialize([0.5, 0.0], q0)
    llm.partial_fit([[0.5, 0.25]], [[1.0, 1.0, 1.0]], sample_weight=[0.0])
    assert llm.n_prototypes_ == 2
    np.testing.assert_array_equal(llm.offsets_[1], q0)
    np.testing.assert_array_equal(llm.matrices_[1], np.zeros((3, 2)))


# -- (e), (f) the gradient step -------------------------------------------------------------
@pytest.mark.parametrize(("n", "m"), [(1, 2), (2, 5), (3, 4)])
def test_gradient_step_formula(n: int, m: int) -> None:
    """One step is o_k += eta w beta_k e, W_k += eta w beta_k e u_k^T with e = q - g(x) (Sec. II-C)."""
    for seed in range(3):
        llm, rng = random_map(300 + 10 * n + m + 100 * seed, n, m, eta=0.3)
        k = rng.integers(llm.n_prototypes_)
        x = llm.prototypes_[k] + rng.uniform(-0.3, 0.3, n) * llm.radius / np.sqrt(n)
        q = rng.normal(size=m)
        w = rng.uniform(0.2, 2.0)
        eta = llm.learning_rate
        g, beta, U = reference(x, llm)
        e = q - g
        O_expected = llm.offsets_ + eta * w * beta[:, None] * e[None, :]
        W_expected = llm.matrices_ + eta * w * beta[:, None, None] * e[None, :, None] * U[:, None, :]
        K = llm.n_prototypes_
        llm.partial_fit(x[None], q[None], sample_weight=[w])
        assert llm.n_prototypes_ == K
        scale = np.abs(llm.offsets_).max() + np.abs(llm.matrices_).max()
        np.testing.assert_allclose(llm.offsets_, O_expected, rtol=0, atol=1e-13 * scale)
        np.testing.assert_allclose(llm.matrices_, W_expected, rtol=0, atol=1e-13 * scale)


def test_small_step_reduces_weighted_error_exactly_as_predicted() -> None:
    """A step reduces w ||q - g(x)||^2 by the factor (1 - eta w s)^2, s = sum_k beta_k^2 (1 + ||u_k||^2).

    g is linear in (W_k, o_k), so after the step g changes by
    sum_k beta_k (dW_k u_k + do_k) = eta w s e exactly: the new error is (1 - eta w s) e.
    With 0 < eta w s < 2 the weighted squared error decreases.
    """
    for seed in range(5):
        llm, rng = random_map(seed, n=2, m=5, eta=0.05)
        k = rng.integers(llm.n_prototypes_)
        x = llm.prototypes_[k] + rng.uniform(-0.5, 0.5, 2) * llm.radius
        q = llm.predict(x) + rng.normal(size=5)
        w = 0.7
        _, beta, U = reference(x, llm)
        s = np.sum(beta**2 * (1.0 + np.sum(U**2, axis=1)))
        eta = llm.learning_rate
        assert 0.0 < eta * w * s < 2.0
        before = w * np.sum((q - llm.predict(x)) ** 2)
        llm.partial_fit(x[None], q[None], sample_weight=[w])
        after = w * np.sum((q - llm.predict(x)) ** 2)
        assert after < before
        np.testing.assert_allclose(after, (1.0 - eta * w * s) ** 2 * before, rtol=1e-10)


def test_zero_weight_changes_nothing_near_prototypes() -> None:
    """An example with weight 0 inside the radius of a prototype leaves every parameter as it was."""
    llm, _ = random_map(11, n=2, m=3)
    state = (llm.prototypes_.copy(), llm.matrices_.copy(), llm.offsets_.copy())
    llm.partial_fit(llm.prototypes_[:1] + 0.01, [[5.0, 5.0, 5.0]], sample_weight=[0.0])
    for now, before in zip((llm.prototypes_, llm.matrices_, llm.offsets_), state, strict=True):
        np.testing.assert_array_equal(now, before)


# -- (g) far from all prototypes --------------------------------------------------------------
def test_predict_far_away_is_finite_and_equals_soft_max() -> None:
    """100 m from every prototype (||u||^2 ~ 1e5, exp(-||u||^2) underflows to 0) predict stays finite.

    The value must still be the soft-max of Sec. II-C, evaluated here in the stable
    form beta_k = exp(-(||u_k||^2 - min_j ||u_j||^2)) / sum (same ratio, no underflow).
    Far away the responsibilities concentrate on a few nearest prototypes.
    """
    for seed in range(3):
        llm, rng = random_map(seed, n=2, m=4)
        for _ in range(5):
            direction = rng.normal(size=2)
            x = 100.0 * direction / np.linalg.norm(direction)
            U = (x - llm.prototypes_) / llm.radius
            sq = np.sum(U**2, axis=1)
            assert np.exp(-sq).sum() == 0.0  # the naive formula would divide 0 by 0
            a = np.exp(-(sq - sq.min()))
            beta = a / a.sum()
            expected = beta @ (np.einsum("kij,kj->ki", llm.matrices_, U) + llm.offsets_)
            g = llm.predict(x, warn=False)  # far on purpose
            assert np.all(np.isfinite(g))
            # Terms W_k u_k are ~ |W| * 1e3: rounding is a few eps of that magnitude.
            scale = np.abs(llm.matrices_).max() * np.abs(U).max() + np.abs(llm.offsets_).max()
            np.testing.assert_allclose(g, expected, rtol=0, atol=1e-13 * scale)
            assert np.all(np.isfinite(llm.jacobian(x)))


# -- (h) shapes and storage ------------------------------------------------------------------
def test_predict_shapes() -> None:
    """predict of (n,) gives (m,), of (N, n) gives (N, m), row by row the same values."""
    llm, rng = random_map(5, n=3, m=6)
    X = rng.uniform(-1.0, 1.0, (7, 3))
    G = llm.predict(X)
    assert G.shape == (7, 6)
    assert llm.predict(X[0]).shape == (6,)
    assert llm.predict(X[:1]).shape == (1, 6)
    for x, g in zip(X, G, strict=True):
        np.testing.assert_array_equal(llm.predict(x), g)
    assert llm.jacobian(X[0]).shape == (6, 3)
    assert (llm.n_inputs_, llm.n_outputs_) == (3, 6)


def test_storage_growth_keeps_the_map() -> None:
    """Growing the storage (capacity 1 growing on demand, or reserve()) changes no parameter or output."""
    rng = np.random.default_rng(21)
    x0, q0 = rng.uniform(-1, 1, 2), rng.normal(size=4)
    X, Q, w = rng.uniform(-1, 1, (60, 2)), rng.normal(size=(60, 4)), rng.uniform(0, 1, 60)
    small = LocalLinearMap(0.3, 0.5).initialize(x0, q0, capacity=1).partial_fit(X, Q, w)
    large = LocalLinearMap(0.3, 0.5).initialize(x0, q0, capacity=1000).partial_fit(X, Q, w)
    assert small.n_prototypes_ == large.n_prototypes_ > 5
    np.testing.assert_array_equal(small.prototypes_, large.prototypes_)
    np.testing.assert_array_equal(small.matrices_, large.matrices_)
    np.testing.assert_array_equal(small.offsets_, large.offsets_)
    probe = rng.uniform(-1.2, 1.2, (30, 2))
    before = small.predict(probe)
    np.testing.assert_array_equal(before, large.predict(probe))
    small.reserve(5000)
    small.reserve(3)  # no-op: never shrinks
    np.testing.assert_array_equal(small.predict(probe), before)
    np.testing.assert_array_equal(small.jacobian(probe[0]), large.jacobian(probe[0]))


# -- (i) argument errors -------------------------------------------------------------------
@pytest.mark.parametrize("bad", [-0.1, 0.0, np.nan, np.inf, "0.1", None, True])
@pytest.mark.parametrize("name", ["radius", "learning_rate"])
def test_initialize_rejects_bad_hyperparameters(name: str, bad: object) -> None:
    """A radius or learning rate that is not a positive finite number raises InvalidArgumentError."""
    llm = LocalLinearMap(**{name: bad})  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match=name):
        llm.initialize([0.0, 0.0], [0.0])


def test_invalid_argument_error_is_value_error() -> None:
    """InvalidArgumentError subclasses ValueError, so generic handlers still catch it."""
    assert issubclass(InvalidArgumentError, ValueError)


def test_initialize_rejects_non_vectors() -> None:
    """x0 and q0 must be vectors."""
    with pytest.raises(InvalidArgumentError):
        LocalLinearMap().initialize([[0.0, 0.0]], [0.0])
    with pytest.raises(InvalidArgumentError):
        LocalLinearMap().initialize([0.0, 0.0], 1.0)


def test_methods_before_initialize_raise() -> None:
    """predict, jacobian, partial_fit and the learned attributes need initialize() first."""
    llm = LocalLinearMap()
    with pytest.raises(InvalidArgumentError, match="initialize"):
        llm.predict([0.0, 0.0])
    with pytest.raises(InvalidArgumentError):
        llm.jacobian([0.0, 0.0])
    with pytest.raises(InvalidArgumentError):
        llm.partial_fit([[0.0, 0.0]], [[0.0]])
    with pytest.raises(InvalidArgumentError):
        _ = llm.prototypes_


@pytest.mark.parametrize(
    "X",
    [
        [0.0, 0.0, 0.0],  # wrong n
        [[0.0], [1.0]],  # wrong n, 2-D
        np.zeros((0, 2)),  # no rows
        np.zeros((2, 2, 2)),  # 3-D
        [np.nan, 0.0],
        [[0.0, np.inf]],
    ],
)
def test_predict_rejects_bad_inputs(X: object) -> None:
    """predict and jacobian reject wrong shapes and non-finite inputs."""
    llm = LocalLinearMap().initialize([0.0, 0.0], [0.0, 1.0, 2.0])
    with pytest.raises(InvalidArgumentError):
        llm.predict(X)
    with pytest.raises(InvalidArgumentError):
        llm.jacobian(X)


@pytest.mark.parametrize("X", ["abc", [[0.0], [0.0, 1.0]]])
def test_predict_rejects_non_numeric_inputs(X: object) -> None:
    """predict rejects non-numeric or ragged input with InvalidArgumentError (as partial_fit does)."""
    llm = LocalLinearMap().initialize([0.0, 0.0], [0.0, 1.0, 2.0])
    with pytest.raises(InvalidArgumentError):
        llm.predict(X)


def test_partial_fit_rejects_bad_inputs() -> None:
    """partial_fit rejects wrong shapes, mismatched rows, non-finite data and bad sample weights."""
    llm = LocalLinearMap().initialize([0.0, 0.0], [0.0, 1.0, 2.0])
    X = np.zeros((2, 2))
    Q = np.zeros((2, 3))
    cases = [
        (np.zeros((2, 3)), Q, None),
        (X, np.zeros((2, 2)), None),
        (X, np.zeros((3, 3)), None),
        (np.array([[0.0, np.nan], [0.0, 0.0]]), Q, None),
        (np.array([[0.0, np.inf], [0.0, 0.0]]), Q, None),
        (X, np.array([[0.0, 0.0, np.nan], [0.0, 0.0, 0.0]]), None),
        (X, Q, [1.0, -0.5]),
        (X, Q, [1.0, np.nan]),
        (X, Q, [1.0, np.inf]),
        (X, Q, [1.0]),
        (X, Q, 1.0),
    ]
    for Xc, Qc, w in cases:
        with pytest.raises(InvalidArgumentError):
            llm.partial_fit(Xc, Qc, sample_weight=w)
    # None of the rejected calls touched the map.
    assert llm.n_prototypes_ == 1
    np.testing.assert_array_equal(llm.offsets_, [[0.0, 1.0, 2.0]])


def test_partial_fit_rechecks_learning_rate() -> None:
    """A learning rate made invalid after initialize is rejected at the next partial_fit."""
    llm = LocalLinearMap().initialize([0.0, 0.0], [0.0])
    llm.learning_rate = -1.0
    with pytest.raises(InvalidArgumentError, match="learning_rate"):
        llm.partial_fit([[0.0, 0.0]], [[1.0]])


def test_predict_warns_far_outside_the_learned_region() -> None:
    """Queries many radii from every prototype warn (ExtrapolationWarning); queries near them do not."""
    import warnings

    import gb_pin
    from gb_pin.exceptions import ExtrapolationWarning, GbPinWarning

    result = gb_pin.babble("planar5", movements=50, seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result.inverse(result.model.prototypes_)  # no warning
        result.model.predict([[3.0, 3.0]], warn=False)
    with pytest.warns(ExtrapolationWarning, match=r"\[3.0, 3.0\]"):
        result.inverse([[3.0, 3.0]])
    assert issubclass(ExtrapolationWarning, GbPinWarning)
