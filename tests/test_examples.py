"""Examples that a newcomer runs first work out of the box with small options."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

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
