"""Property-based tests (hypothesis) over the public API's arguments.

No input may crash with anything but the package's own error, and valid inputs never
give non-finite results.
"""

from __future__ import annotations

import contextlib
import math
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gb_pin

FAST = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])

anything = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**6), max_value=10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=5),
    st.lists(st.floats(allow_nan=True), max_size=3),
)


def _babble_or_own_error(**kwargs: Any) -> gb_pin.BabbleResult | None:
    try:
        return gb_pin.babble(**kwargs)
    except gb_pin.GbPinError:
        return None


# path_length is bounded: one movement runs path_length steps, so a draw of 10^6 would run
# 2 * 10^6 steps (seconds) while testing nothing that 10^3 does not.
bounded_path_length = st.one_of(
    st.integers(min_value=-(10**6), max_value=1000),
    anything.filter(lambda v: not isinstance(v, int) or v <= 1000),
)


@FAST
@given(
    name=st.sampled_from(
        ["learning_rate", "sigma", "sigma_delta", "radius", "path_length", "p_home", "seed"]
    ),
    data=st.data(),
)
def test_babble_any_parameter_value_is_ok_or_own_error(name: str, data: st.DataObject) -> None:
    """babble with any value of one parameter either runs or raises a GbPinError naming it."""
    value = data.draw(bounded_path_length if name == "path_length" else anything)
    try:
        result = gb_pin.babble(robot="planar3", movements=2, **{name: value})
    except gb_pin.GbPinError as exc:
        assert name in str(exc), f"the error for {name}={value!r} does not name it: {exc}"
        return
    assert np.all(np.isfinite(result.history.error))
    assert np.all(np.isfinite(result.model.offsets_))
    if name != "seed" and value is not None:
        assert float(getattr(result.config, name)) == float(value)


@FAST
@given(robot=st.one_of(st.text(max_size=12), st.integers(), st.none()), movements=anything)
def test_babble_any_robot_and_movements_is_ok_or_own_error(robot: Any, movements: Any) -> None:
    """Any robot name or movement count runs or raises a GbPinError (ValueError for arguments)."""
    if isinstance(movements, int) and not isinstance(movements, bool) and movements > 3:
        movements = 3
    try:
        res = gb_pin.babble(robot=robot, movements=movements)
    except gb_pin.InvalidArgumentError as exc:
        message = str(exc)
        assert "robot" in message or "movements" in message, message
        return
    assert isinstance(robot, str) and res.robot == robot
    assert res.movements == movements and res.history.movements[-1] == movements


@FAST
@given(
    learning_rate=st.floats(min_value=1e-4, max_value=1.0),
    sigma=st.floats(min_value=0.0, max_value=0.3),
    radius=st.floats(min_value=0.02, max_value=1.0),
    p_home=st.floats(min_value=0.0, max_value=0.99),
    path_length=st.integers(min_value=1, max_value=30),
    m=st.integers(min_value=2, max_value=12),
    seed=st.integers(min_value=0, max_value=2**63),
)
def test_valid_parameters_give_finite_results(
    learning_rate: float, sigma: float, radius: float, p_home: float, path_length: int, m: int, seed: int
) -> None:
    """Valid parameters (the paper's ranges and beyond) never give non-finite results."""
    res = gb_pin.babble(
        robot=f"planar{m}", movements=5, seed=seed, learning_rate=learning_rate, sigma=sigma,
        radius=radius, p_home=p_home, path_length=path_length,
    )  # fmt: skip
    assert np.all(np.isfinite(res.history.error)) and np.all(np.isfinite(res.history.home_distance))
    assert np.all(np.isfinite(res.inverse(res.targets)))
    assert res.steps == 5 * path_length


@FAST
@given(
    targets=st.one_of(
        anything,
        st.lists(
            st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=0, max_size=4), max_size=4
        ),
    )
)
def test_any_targets_are_ok_or_own_error(targets: Any) -> None:
    """Any targets value runs (finite (N, 2) points) or raises a GbPinError.

    Targets far out of reach (e.g. 1e7 m) may make the run diverge: DivergenceError, not a crash.
    """
    try:
        res = gb_pin.babble(robot="planar3", movements=2, targets=targets)
    except gb_pin.GbPinError:
        return
    if targets is None:  # the robot's own target set
        np.testing.assert_array_equal(res.targets, gb_pin.load_robot("planar3").targets)
        return
    arr = np.asarray(targets, dtype=float)
    assert arr.ndim == 2 and arr.shape[1] == 2 and np.all(np.isfinite(arr))
    assert np.all(np.isfinite(res.history.error))


@FAST
@given(X=st.one_of(anything, st.lists(st.lists(st.floats(allow_nan=True), max_size=3), max_size=3)))
def test_inverse_of_anything_is_ok_or_own_error(X: Any) -> None:
    """result.inverse of any input gives finite postures or raises InvalidArgumentError."""
    res = _RESULT
    try:
        q = res.inverse(X)
    except gb_pin.InvalidArgumentError:
        return
    assert np.all(np.isfinite(q))


_RESULT = gb_pin.babble("planar3", movements=5, seed=0)


@FAST
@given(
    q=st.one_of(anything, st.lists(st.floats(allow_nan=False, allow_infinity=False, width=32), max_size=4))
)
def test_forward_of_anything_is_ok_or_own_error(q: Any) -> None:
    """target.forward of any input gives a position or raises InvalidArgumentError."""
    try:
        x = _RESULT.target.forward(q)
    except gb_pin.InvalidArgumentError:
        return
    assert x.shape[-1] == 2


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.binary(max_size=400), cut=st.floats(min_value=0.0, max_value=1.0))
def test_load_result_of_any_bytes_is_own_error(tmp_path: Path, data: bytes, cut: float) -> None:
    """Random bytes, or a real result file cut anywhere, load or raise ResultFileError, nothing else."""
    path = tmp_path / "random.npz"
    path.write_bytes(data)
    with contextlib.suppress(gb_pin.ResultFileError):
        gb_pin.load_result(path)
    real = tmp_path / "real.npz"
    _RESULT.save(real)
    blob = real.read_bytes()
    real.write_bytes(blob[: math.floor(cut * len(blob))])
    try:
        loaded = gb_pin.load_result(real)
    except gb_pin.ResultFileError:
        return
    np.testing.assert_array_equal(loaded.history.error, _RESULT.history.error)
