"""Independent trials: seeds, parallel equality, S(Q, e), quantiles, JSON round trip."""

from __future__ import annotations

import json

import numpy as np
import pytest

import gb_pin
from gb_pin.cli import main


def test_trial_i_uses_seed_plus_i() -> None:
    """Trial i of run_trials equals babble with seed + i."""
    ts = gb_pin.run_trials("planar3", trials=3, movements=20, seed=5, workers=1)
    for i in range(3):
        single = gb_pin.babble("planar3", movements=20, seed=5 + i)
        np.testing.assert_array_equal(ts.error[i], single.history.error)
        np.testing.assert_array_equal(ts.home_distance[i], single.history.home_distance)
    assert ts.initial_error == ts.error[0, 0]
    assert np.all(ts.error[:, 0] == ts.initial_error)


def test_parallel_equals_serial() -> None:
    """Two worker processes give bit-identical results to one process."""
    serial = gb_pin.run_trials("planar5", trials=4, movements=15, seed=0, workers=1, learning_rate=0.3)
    parallel = gb_pin.run_trials("planar5", trials=4, movements=15, seed=0, workers=2, learning_rate=0.3)
    np.testing.assert_array_equal(serial.error, parallel.error)
    np.testing.assert_array_equal(serial.home_distance, parallel.home_distance)
    np.testing.assert_array_equal(serial.prototypes, parallel.prototypes)


def test_speed_and_quantiles_follow_their_definitions() -> None:
    """speed() is Eq. 11 over the trials; quantiles() are numpy quantiles over trials."""
    ts = gb_pin.run_trials("planar5", trials=6, movements=60, seed=1, workers=1)
    level = 0.1 * ts.initial_error
    s = ts.speed(0.5, level)
    frac = np.mean(ts.error <= level, axis=0)
    if s is None:
        assert np.all(frac < 0.5)
    else:
        idx = int(np.flatnonzero(ts.movements == s)[0])
        assert frac[idx] >= 0.5
        assert np.all(frac[:idx] < 0.5)
    q = ts.quantiles((0.25, 0.5))
    np.testing.assert_array_equal(q[1], np.median(ts.error, axis=0))
    assert q.shape == (2, ts.movements.shape[0])
    assert ts.speed(1.0, -1.0) is None


def test_save_load_round_trip(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """A saved TrialSet loads back identical (JSON, no pickle)."""
    ts = gb_pin.run_trials("planar3", trials=2, movements=10, seed=0, workers=1, radius=0.15)
    path = tmp_path / "t.json"
    ts.save(path)
    back = gb_pin.TrialSet.load(path)
    np.testing.assert_array_equal(back.error, ts.error)
    np.testing.assert_array_equal(back.movements, ts.movements)
    assert back.parameters == {"radius": 0.15}
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(gb_pin.ResultFileError, match=r"bad\.json"):
        gb_pin.TrialSet.load(tmp_path / "bad.json")
    (tmp_path / "foreign.json").write_text(json.dumps({"a": 1}))
    with pytest.raises(gb_pin.ResultFileError, match="not a gb_pin trials file"):
        gb_pin.TrialSet.load(tmp_path / "foreign.json")


def test_cli_trials_json_has_the_documented_keys(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin trials --json` writes movements, error, home_distance and initial_error."""
    out = tmp_path / "out.json"
    argv = ["trials", "--robot", "planar3", "--trials", "2", "--movements", "10", "--workers", "1"]
    code = main([*argv, "--learning-rate", "0.5", "--json", str(out), "--quiet"])
    assert code == 0
    raw = json.loads(out.read_text())
    for key in ("movements", "error", "home_distance", "initial_error"):
        assert key in raw
    assert len(raw["error"]) == 2
    assert "S(0.5, 0.1 E_0)" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"trials": 0}, "trials"),
        ({"movements": -1}, "movements"),
        ({"seed": -2}, "seed"),
        ({"workers": 0}, "workers"),
        ({"learning_rate": -0.1}, "learning_rate"),
        ({"bogus": 1}, "bogus"),
        ({"robot": "planar1"}, "planar1"),
    ],
)
def test_bad_arguments_name_the_parameter(kwargs, name) -> None:  # type: ignore[no-untyped-def]
    """Bad run_trials arguments raise the package's ValueError naming the parameter."""
    args = {"robot": "planar3", "trials": 2, "movements": 5, "workers": 1, **kwargs}
    with pytest.raises(gb_pin.InvalidArgumentError, match=name):
        gb_pin.run_trials(**args)
