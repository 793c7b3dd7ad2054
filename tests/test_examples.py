"""Examples that a newcomer runs first work out of the box with small options."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_reproduction_intervals_runs_without_the_cache(tmp_path: Path) -> None:
    """Without gb-pin reproduce's cache the example runs the trials itself; unreached counts print as such."""
    args = ["--movements", "300", "--trials", "4", "--resamples", "50", "--out", str(tmp_path)]
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / "reproduction_intervals.py"), *args],
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("\n| ") >= 5
    assert "not reached" in done.stdout  # eta 0.01 does not reach 0.04 m in 300 movements
    assert "gb-pin reproduce" in done.stderr and "Warning" not in done.stderr


@pytest.mark.parametrize("example", sorted(p.name for p in EXAMPLES.glob("*.py")))
def test_every_example_answers_help_without_running(example: str) -> None:
    """``python examples/X.py --help`` prints a usage and exits 0 at once, for every example.

    An example that ignores --help runs its whole experiment instead (two did: continuum_arm.py
    learnt 2000 movements, simulator_ask_tell.py started its simulator process); 60 s is far more
    than an argparse usage takes even with numba and pinocchio imported, far less than a run.
    """
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / example), "--help"],
        capture_output=True, text=True, timeout=60, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.startswith("usage: "), done.stdout[:200]
    assert "E^X" not in done.stdout  # a usage, not the results of a run
