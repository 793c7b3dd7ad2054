"""RunSpec: one description of a run that babble(), babble_session() and trials take."""

from __future__ import annotations

import numpy as np
import pytest

import gb_pin
from gb_pin.runs.spec import RunSpec


def test_babble_session_and_trials_take_one_spec() -> None:
    """babble(spec) is babble(**arguments); a session of the spec and trials of it run the same run."""
    spec = RunSpec("planar5", movements=60, seed=3, learning_rate=0.3, max_joint_step=0.05, goals="cyclic")
    ref = gb_pin.babble(
        "planar5", movements=60, seed=3, learning_rate=0.3, max_joint_step=0.05, goals="cyclic"
    )
    got = gb_pin.babble(spec)
    np.testing.assert_array_equal(got.history.error, ref.history.error)
    target = gb_pin.load_robot("planar5")
    session = gb_pin.babble_session(spec)
    while not session.done:
        session.tell(target.forward(session.ask()))
    np.testing.assert_array_equal(session.result().history.error, ref.history.error)
    trials = gb_pin.run_trials(
        RunSpec("planar5", movements=40, seed=2, learning_rate=0.3), trials=2, workers=1
    )
    direct = gb_pin.run_trials("planar5", trials=2, movements=40, seed=2, workers=1, learning_rate=0.3)
    np.testing.assert_array_equal(trials.error, direct.error)


def test_a_spec_is_checked_once_and_says_what_trials_cannot_carry() -> None:
    """Bad values, unknown options, fields trials cannot carry: gb_pin's errors; a short repr."""
    with pytest.raises(gb_pin.InvalidArgumentError, match="learning_rate"):
        RunSpec("planar5", learning_rate=-1.0)
    with pytest.raises(gb_pin.InvalidArgumentError, match="closest: sigma"):
        RunSpec.of("planar5", sigm=0.1)
    with pytest.raises(gb_pin.InvalidArgumentError, match="reach_window"):
        RunSpec("planar5", reach_window=0)
    with pytest.raises(gb_pin.InvalidArgumentError, match="changes movement"):
        RunSpec("planar5", changes={2**70: None})
    sensor_spec = RunSpec("planar5", sensor=gb_pin.Sensor(0.001))
    with pytest.raises(gb_pin.InvalidArgumentError, match="sensor"):
        gb_pin.run_trials(sensor_spec, trials=1, workers=1)
    with pytest.raises(gb_pin.InvalidArgumentError, match="not both"):
        gb_pin.babble_session(RunSpec("planar5"), sigma=0.1)
    text = repr(RunSpec("planar5", targets=np.zeros((100, 2)), sigma=0.02))
    assert "sigma=0.02" in text and "(100, 2)" in text and len(text) < 200
