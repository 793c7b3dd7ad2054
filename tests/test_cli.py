"""The gb-pin command line: babble, bench, robots, and clean errors for bad input."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import gb_pin
from gb_pin.cli import main


def test_babble_prints_summary_and_saves(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin babble` ends with E^X, D^home, prototypes and wall time, and --out saves a loadable result."""
    out = tmp_path / "run.npz"
    code = main(["babble", "--robot", "planar5", "--movements", "30", "--seed", "3", "--out", str(out)])
    assert code == 0
    text = capsys.readouterr().out
    for word in ("E^X", "D^home", "prototypes", "wall time"):
        assert word in text
    loaded = gb_pin.load_result(out)
    direct = gb_pin.babble("planar5", movements=30, seed=3)
    np.testing.assert_array_equal(loaded.history.error, direct.history.error)
    np.testing.assert_array_equal(loaded.inverse(loaded.targets), direct.inverse(direct.targets))


def test_bench_prints_a_table(capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin bench` runs and prints microseconds per step for each robot (no timing asserted)."""
    assert main(["bench", "--robots", "planar3", "--movements", "4", "--repeat", "1"]) == 0
    text = capsys.readouterr().out
    assert "us/step" in text
    assert "| planar3 | 4 | 100 |" in text


def test_robots_lists_planar(capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin robots` lists the planarN family."""
    assert main(["robots"]) == 0
    assert "planarN" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["babble", "--robot", "plnar5"], "plnar5"),
        (["babble", "--robot", "planar1"], "planar1"),
        (["babble", "--movements", "0"], "movements"),
        (["babble", "--learning-rate", "-1"], "learning_rate"),
        (["babble", "--learning-rate", "nan"], "learning_rate"),
        (["babble", "--radius", "0"], "radius"),
        (["babble", "--sigma", "-0.1"], "sigma"),
    ],
)
def test_bad_input_exits_2_without_traceback(argv, needle) -> None:  # type: ignore[no-untyped-def]
    """A user mistake prints one error line naming the value and exits with status 2."""
    proc = subprocess.run(
        [sys.executable, "-m", "gb_pin.cli", *argv, "--quiet"], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert needle in proc.stderr
