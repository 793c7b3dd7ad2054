"""Tests of gb_pin.learn.babbling and the compiled loop (paper Sec. II) against an independent reference.

``tests/reference.py`` re-implements online goal babbling in plain numpy from the paper, with its own
closed-form forward kinematics of the planar arm. gb_pin and the reference see the same random numbers
(same Generator calls in the same order), so they must produce the same run up to floating-point
summation order: ~1e-16 per operation, amplified by the learning feedback loop to at most ~1e-11 over
the runs used here. ``ATOL = 1e-9`` leaves three orders of margin, while any real difference (a weight,
an index, a draw out of order, an off-by-one in a path) changes E^X or the model by 1e-3 or more.

Behavioural thresholds come from Sec. III of the paper: E^X ~ 0.04 m after 100 movements for the 5-DOF
arm with eta = 0.1 (Fig. 4a), E^X ~ 0.01 m after 1000 movements for 20 DOF (Fig. 7a; Fig. 3c gives 0.011 m
for 5 DOF), E_0 the error of the constant initial estimate g = q_home.
"""

from __future__ import annotations

import numpy as np
import pytest
from reference import GOAL, HOME, ReferenceRun, planar_forward, planar_home, reference_babble

import gb_pin
from gb_pin import GoalBabbling, InvalidArgumentError

ATOL = 1e-9  # [m], [rad] and model parameters; see the module docstring
MOVEMENTS = 20

# (robot, keyword arguments): the paper's defaults, and a configuration with many home returns.
CASES = [
    ("planar5", {}),
    ("planar3", {"learning_rate": 0.3, "p_home": 0.5}),
    ("planar20", {}),
]


def n_joints(robot: str) -> int:
    return int(robot.removeprefix("planar"))


def grid() -> np.ndarray:
    """The planar presets' target set X* (the same for every planarN)."""
    targets = gb_pin.load_robot("planar5").targets
    assert targets is not None
    return targets


def assert_same_model(prototypes: np.ndarray, matrices: np.ndarray, offsets: np.ndarray, ref: tuple) -> None:
    """gb_pin's (P, W, O) equal the reference's, prototype by prototype."""
    P, W, O = ref
    assert prototypes.shape == P.shape, "different numbers of prototypes"
    np.testing.assert_allclose(prototypes, P, rtol=0, atol=ATOL)
    np.testing.assert_allclose(matrices, W, rtol=0, atol=ATOL)
    np.testing.assert_allclose(offsets, O, rtol=0, atol=ATOL)


def assert_same_run(result: gb_pin.BabbleResult, ref: ReferenceRun) -> None:
    """Same E^X and D^home at every movement and the same final local-linear map."""
    movements = len(ref.errors) - 1
    np.testing.assert_array_equal(result.history.movements, np.arange(movements + 1))
    np.testing.assert_allclose(result.history.error, ref.errors, rtol=0, atol=ATOL)
    np.testing.assert_allclose(result.history.home_distance, ref.home_distances, rtol=0, atol=ATOL)
    model = result.model
    assert_same_model(
        model.prototypes_, model.matrices_, model.offsets_, (ref.prototypes, ref.matrices, ref.offsets)
    )


# -- agreement with the reference -------------------------------------------------------------------
@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize(("robot", "kwargs"), CASES)
def test_babble_matches_reference(robot: str, kwargs: dict, seed: int) -> None:
    """babble() gives the reference's E^X and D^home at every movement and its final map (Eqs. 2-10)."""
    result = gb_pin.babble(robot=robot, movements=MOVEMENTS, seed=seed, **kwargs)
    ref = reference_babble(n_joints(robot), grid(), MOVEMENTS, seed, **kwargs)
    if kwargs.get("p_home") == 0.5:
        assert HOME in ref.kinds, "this case is meant to exercise home returns"
    assert_same_run(result, ref)


def test_model_and_noise_match_reference_after_every_movement() -> None:
    """After each movement r (home returns included) the map and the noise (A, b) equal the reference's.

    A run of r movements is a prefix of a longer run with the same seed, so fitting r = 1..R movements
    observes the learner's state movement by movement; the noise pins down the Generator draw order.
    """
    kwargs = {"learning_rate": 0.3, "p_home": 0.5}
    target = gb_pin.load_robot("planar3")
    ref = reference_babble(3, grid(), MOVEMENTS, 0, record=True, **kwargs)
    assert ref.kinds.count(HOME) >= 3
    for r in range(1, MOVEMENTS + 1):
        learner = GoalBabbling(**kwargs).fit(target, grid(), r, seed=0)
        P, W, O, A, b = ref.snapshots[r - 1]
        model = learner.model_
        assert_same_model(model.prototypes_, model.matrices_, model.offsets_, (P, W, O))
        np.testing.assert_allclose(learner.noise_[0], A, rtol=0, atol=ATOL)
        np.testing.assert_allclose(learner.noise_[1], b, rtol=0, atol=ATOL)


@pytest.mark.parametrize("seed", [1, 2])
def test_matches_reference_beyond_initial_storage(seed: int) -> None:
    """With more than 256 prototypes (the initial storage, grown mid-run) the run still equals the reference.

    Wide exploration (sigma = sigma_delta = 0.5 rad) and a small radius (d = 0.02 m) insert a prototype at
    almost every step.
    """
    kwargs = {"sigma": 0.5, "sigma_delta": 0.5, "radius": 0.02}
    result = gb_pin.babble("planar5", movements=15, seed=seed, **kwargs)
    ref = reference_babble(5, grid(), 15, seed, **kwargs)
    assert result.n_prototypes > 256
    assert_same_run(result, ref)


def test_generator_draws_match_reference_exactly() -> None:
    """gb_pin consumes exactly the reference's random numbers: both Generators end in the same state."""
    mine, theirs = np.random.default_rng(7), np.random.default_rng(7)
    result = gb_pin.babble("planar3", movements=MOVEMENTS, seed=mine, p_home=0.5)
    ref = reference_babble(3, grid(), MOVEMENTS, theirs, p_home=0.5)
    assert_same_run(result, ref)
    assert mine.bit_generator.state == theirs.bit_generator.state


# -- paths (Eqs. 3 and 7), read from gb_pin's own recording of every step ---------------------------
PATH_MOVEMENTS = 40
PATH_KWARGS = {"learning_rate": 0.3, "p_home": 0.5}


@pytest.fixture(scope="module")
def recorded() -> tuple[gb_pin.BabbleResult, ReferenceRun]:
    """planar3 with many home returns, every step recorded, by gb_pin and by the reference."""
    result = gb_pin.babble(
        "planar3", movements=PATH_MOVEMENTS, seed=3, record=gb_pin.Recording(every=1), **PATH_KWARGS
    )
    ref = reference_babble(3, grid(), PATH_MOVEMENTS, 3, record=True, **PATH_KWARGS)
    return result, ref


def movements_of(steps: gb_pin.RecordedSteps) -> list[dict[str, np.ndarray]]:
    """gb_pin's recorded steps grouped by movement: targets (NaN on home returns), postures, positions."""
    return [
        {
            "target": steps.target[steps.movement == r],
            "q": steps.posture[steps.movement == r],
            "x": steps.position[steps.movement == r],
        }
        for r in range(int(steps.movement.max()) + 1)
    ]


def is_home_return(movement: dict[str, np.ndarray]) -> bool:
    return bool(np.all(np.isnan(movement["target"])))


def test_recorded_steps_match_reference(recorded: tuple[gb_pin.BabbleResult, ReferenceRun]) -> None:
    """Every step's target, executed posture and reached position equal the reference's (Eqs. 1-3, 7)."""
    result, ref = recorded
    steps = result.recording
    assert steps is not None
    assert_same_run(result, ref)
    np.testing.assert_array_equal(steps.step, np.arange(1, PATH_MOVEMENTS * 25 + 1))
    np.testing.assert_array_equal(steps.movement, [s.movement for s in ref.steps])
    targets = np.array([np.full(2, np.nan) if s.target is None else s.target for s in ref.steps])
    np.testing.assert_allclose(steps.target, targets, rtol=0, atol=ATOL)
    np.testing.assert_allclose(steps.posture, [s.q for s in ref.steps], rtol=0, atol=ATOL)
    np.testing.assert_allclose(steps.position, [s.x for s in ref.steps], rtol=0, atol=ATOL)
    assert [HOME if is_home_return(mv) else GOAL for mv in movements_of(steps)] == ref.kinds


def test_goal_paths_are_linear_and_end_exactly_at_grid_targets(
    recorded: tuple[gb_pin.BabbleResult, ReferenceRun],
) -> None:
    """Each goal path moves in L equal steps (Eq. 3) from the previous endpoint exactly to a grid target.

    The first path starts at x*_0 = f(q_home), and so does the first path after a home return (Sec. II-A).
    """
    result, _ = recorded
    assert result.recording is not None
    movements = movements_of(result.recording)
    x_home = planar_forward(planar_home(3))
    assert not is_home_return(movements[0])
    start = x_home
    for movement in movements:
        if is_home_return(movement):
            start = x_home
            continue
        path = movement["target"]
        L = len(path)
        end = path[-1]
        assert np.any(np.all(grid() == end, axis=1)), f"{end} is not a grid target"
        steps = np.diff(np.vstack([start, path]), axis=0)
        np.testing.assert_allclose(steps, np.tile((end - start) / L, (L, 1)), rtol=0, atol=1e-15)
        start = end


def test_home_returns_are_linear_in_joint_space_and_end_exactly_at_home(
    recorded: tuple[gb_pin.BabbleResult, ReferenceRun],
) -> None:
    """A home return goes linearly (Eq. 7) from the last posture exactly to q_home, after a goal movement."""
    result, _ = recorded
    assert result.recording is not None
    movements = movements_of(result.recording)
    home = planar_home(3)
    homes = [r for r, movement in enumerate(movements) if is_home_return(movement)]
    assert len(homes) >= 5
    for r in homes:
        assert not is_home_return(movements[r - 1]), "a home return follows only a goal-directed movement"
        start = movements[r - 1]["q"][-1]
        postures = movements[r]["q"]
        L = len(postures)
        np.testing.assert_array_equal(postures[-1], home)
        np.testing.assert_allclose(movements[r]["x"][-1], planar_forward(home), rtol=0, atol=1e-15)
        fractions = np.arange(1, L + 1)[:, None] / L
        np.testing.assert_allclose(postures, (1 - fractions) * start + fractions * home, rtol=0, atol=1e-15)


@pytest.mark.parametrize("path_length", [25, 7])
def test_movement_count_includes_home_returns(path_length: int) -> None:
    """steps == movements * L: every movement, home returns included, has L steps."""
    result = gb_pin.babble("planar3", movements=MOVEMENTS, seed=0, p_home=0.5, path_length=path_length)
    ref = reference_babble(3, grid(), MOVEMENTS, 0, p_home=0.5, path_length=path_length, record=True)
    assert HOME in ref.kinds
    assert len(ref.kinds) == MOVEMENTS
    assert len(ref.steps) == MOVEMENTS * path_length
    assert result.movements == MOVEMENTS
    assert result.steps == MOVEMENTS * path_length
    assert_same_run(result, ref)


# -- determinism ------------------------------------------------------------------------------------
def test_same_seed_is_bit_identical() -> None:
    """The same seed gives a bit-identical history and model."""
    a = gb_pin.babble("planar5", movements=30, seed=4)
    b = gb_pin.babble("planar5", movements=30, seed=4)
    np.testing.assert_array_equal(a.history.error, b.history.error)
    np.testing.assert_array_equal(a.history.home_distance, b.history.home_distance)
    np.testing.assert_array_equal(a.model.prototypes_, b.model.prototypes_)
    np.testing.assert_array_equal(a.model.matrices_, b.model.matrices_)
    np.testing.assert_array_equal(a.model.offsets_, b.model.offsets_)


def test_different_seeds_differ() -> None:
    """Different seeds give different runs from the first movement on (E_0 is the same)."""
    a = gb_pin.babble("planar5", movements=30, seed=0)
    b = gb_pin.babble("planar5", movements=30, seed=1)
    assert a.history.error[0] == b.history.error[0]
    assert np.all(a.history.error[1:] != b.history.error[1:])


def test_generator_seed_equals_int_seed_and_is_advanced() -> None:
    """A Generator may replace the int seed: default_rng(s) gives seed s's run and is advanced in place."""
    rng = np.random.default_rng(9)
    before = rng.bit_generator.state
    from_generator = gb_pin.babble("planar5", movements=MOVEMENTS, seed=rng)
    from_int = gb_pin.babble("planar5", movements=MOVEMENTS, seed=9)
    assert rng.bit_generator.state != before
    assert from_generator.seed is None
    assert from_int.seed == 9
    np.testing.assert_array_equal(from_generator.history.error, from_int.history.error)
    np.testing.assert_array_equal(from_generator.model.offsets_, from_int.model.offsets_)
    # The same Generator again continues its stream: a different run.
    again = gb_pin.babble("planar5", movements=MOVEMENTS, seed=rng)
    assert not np.array_equal(again.history.error, from_int.history.error)


def test_long_runs_are_extensions_of_short_runs() -> None:
    """The first 150 movements of a 300-movement run (run in chunks) equal a 150-movement run."""
    short = gb_pin.babble("planar5", movements=150, seed=2)
    long = gb_pin.babble("planar5", movements=300, seed=2)
    np.testing.assert_array_equal(long.history.error[:151], short.history.error)
    np.testing.assert_array_equal(long.history.home_distance[:151], short.history.home_distance)


# -- behaviour over seeds (paper Sec. III) ------------------------------------------------------------
PLANAR5_SEEDS = range(20)


@pytest.fixture(scope="module")
def planar5_runs() -> list[gb_pin.BabbleResult]:
    """planar5, eta = 0.1, 100 movements, seeds 0..19 (the setting of Fig. 4a)."""
    return [gb_pin.babble("planar5", movements=100, seed=s, learning_rate=0.1) for s in PLANAR5_SEEDS]


def independent_error(result: gb_pin.BabbleResult) -> float:
    """E^X (Eq. 9) of the final model with the closed-form forward kinematics, not gb_pin's."""
    X = result.targets
    return float(np.mean(np.linalg.norm(X - planar_forward(result.inverse(X)), axis=1)))


@pytest.mark.slow
def test_initial_error_and_home_distance(planar5_runs: list[gb_pin.BabbleResult]) -> None:
    """E^X_0 is the mean distance from the grid to f(q_home) (E_0) and D^home_0 = 0 (g = q_home)."""
    e0 = np.mean(np.linalg.norm(grid() - planar_forward(planar_home(5)), axis=1))
    for result in planar5_runs:
        assert result.history.movements[0] == 0
        assert result.history.error[0] == pytest.approx(e0, abs=1e-12)
        assert result.history.home_distance[0] == 0.0


@pytest.mark.slow
def test_planar5_median_error_after_100_movements(planar5_runs: list[gb_pin.BabbleResult]) -> None:
    """Median E^X after 100 movements (eta = 0.1, 20 seeds) is within [0.03, 0.06] m (paper: 0.04 m).

    E^X is recomputed from result.inverse with the closed-form kinematics. The per-seed spread at 100
    movements (interquartile range about 0.015 m) gives the median of 20 seeds a standard error of
    about 0.003 m, so the window is several standard errors wide on each side of the paper's value.
    """
    errors = np.array([independent_error(r) for r in planar5_runs])
    recorded = np.array([r.history.error[-1] for r in planar5_runs])
    np.testing.assert_allclose(errors, recorded, rtol=0, atol=1e-12)
    assert 0.03 <= np.median(errors) <= 0.06


@pytest.mark.slow
def test_error_decreases(planar5_runs: list[gb_pin.BabbleResult]) -> None:
    """After 100 movements the median E^X is below 20% of E_0 (the error falls rapidly, Fig. 4a)."""
    e0 = planar5_runs[0].history.error[0]
    assert np.median([r.history.error[-1] for r in planar5_runs]) < 0.2 * e0


@pytest.mark.slow
def test_planar20_is_accurate_after_1000_movements() -> None:
    """planar20 reaches a median E^X <= 0.02 m after 1000 movements over 9 seeds (paper ~0.01 m, Fig. 7a).

    At most one of the 9 seeds may stay above 10% of E_0 (the paper's speed level, Eq. 11, which 90% of
    trials reach within a few hundred movements even for 50 DOF). A per-seed bound of 0.02 m would not be
    sound: a few percent of trials are still converging at 1000 movements.
    """
    results = [gb_pin.babble("planar20", movements=1000, seed=s, schedule=[0, 1000]) for s in range(9)]
    e0 = results[0].history.error[0]
    errors = np.array([independent_error(r) for r in results])
    np.testing.assert_allclose(errors, [r.error for r in results], rtol=0, atol=1e-12)
    assert np.median(errors) <= 0.02
    assert np.sum(errors > 0.1 * e0) <= 1


# -- the GoalBabbling learner (scikit-learn conventions) ----------------------------------------------
def test_init_only_stores_hyperparameters() -> None:
    """__init__ stores its arguments as given and learns nothing (no attribute ends with '_')."""
    learner = GoalBabbling(learning_rate=0.2, sigma=None, p_home=0.3)
    assert vars(learner) == {
        "learning_rate": 0.2,
        "sigma": None,
        "sigma_delta": None,
        "radius": 0.1,
        "path_length": 25,
        "p_home": 0.3,
        "cutoff": None,
    }
    assert not [name for name in vars(learner) if name.endswith("_")]


def test_fit_returns_self_with_learned_attributes() -> None:
    """fit returns self; what it learns ends with '_' (model_, config_, history_, ...; Sec. III defaults)."""
    target = gb_pin.load_robot("planar5")
    learner = GoalBabbling()
    hyperparameters = set(vars(learner))
    assert learner.fit(target, grid(), MOVEMENTS, seed=0) is learner
    added = set(vars(learner)) - hyperparameters
    assert added and all(name.endswith("_") for name in added)
    for name in ("model_", "config_", "history_", "movements_", "steps_", "noise_"):
        getattr(learner, name)
    assert learner.movements_ == MOVEMENTS
    assert learner.steps_ == MOVEMENTS * 25
    # sigma by Eq. 12 is 0.05 at m = 5; sigma_delta = 0.1 sigma (Sec. III-A).
    assert learner.config_.sigma == pytest.approx(0.05, rel=1e-12)
    assert learner.config_.sigma_delta == pytest.approx(0.005, rel=1e-12)
    X = grid()
    np.testing.assert_array_equal(learner.predict(X), learner.model_.predict(X))
    result = gb_pin.babble("planar5", movements=MOVEMENTS, seed=0)
    np.testing.assert_array_equal(learner.history_.error, result.history.error)
    np.testing.assert_array_equal(learner.predict(X), result.inverse(X))


def test_refit_starts_from_scratch() -> None:
    """A second fit with the same seed reproduces the first: nothing carries over between fits."""
    target = gb_pin.load_robot("planar5")
    learner = GoalBabbling()
    first = learner.fit(target, grid(), MOVEMENTS, seed=3).predict(grid())
    learner.fit(target, grid(), MOVEMENTS, seed=4)
    second = learner.fit(target, grid(), MOVEMENTS, seed=3).predict(grid())
    np.testing.assert_array_equal(first, second)


def test_predict_before_fit_raises() -> None:
    """predict before fit raises InvalidArgumentError (a ValueError) saying to call fit."""
    with pytest.raises(InvalidArgumentError, match="fit"):
        GoalBabbling().predict(grid())
