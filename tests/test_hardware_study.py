"""gb-pin reproduce hardware (gb_pin.reproduce.hardware): one condition end to end, tables and figure."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import gb_pin
from gb_pin.cli import main
from gb_pin.reproduce.hardware import SNAPSHOTS, Condition, conditions, run_hardware


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_one_arm_runs_caches_and_draws(tmp_path: Path) -> None:
    """A tiny study (1 SO-101, one tracker) writes table, csv, json and figure; a rerun reads the cache."""
    pytest.importorskip("matplotlib")
    import gb_pin.reproduce.hardware as hw

    original = hw.ROBOTS
    hw.ROBOTS = {"so101": ((0.0015, 0.1),)}
    try:
        files = run_hardware(str(tmp_path), robots=("so101",), arms=1, workers=1)
        again = run_hardware(str(tmp_path), robots=("so101",), arms=1, workers=1)  # from the cache
    finally:
        hw.ROBOTS = original
    assert files == again and {Path(f).name for f in files} == {
        "hardware.json", "hardware.md", "hardware.csv", "hardware_so101.png"}  # fmt: skip
    run = json.loads((tmp_path / "hardware.json").read_text())["runs"][0]
    assert set(run["open"]) == {str(s) for s in SNAPSHOTS}
    urdf, learned = run["urdf"][0], run["open"]["10000"][0]
    assert learned < 0.003 < 0.005 < urdf  # docs/HARDWARE.md: 0.5 mm against 19 mm
    assert "| so101 | 1.5 mm | 10% | 1 |" in (tmp_path / "hardware.md").read_text()


def test_study_arguments_are_checked(capsys) -> None:  # type: ignore[no-untyped-def]
    """Unknown robots, no arms: gb_pin's errors; the CLI says them in one line."""
    with pytest.raises(gb_pin.InvalidArgumentError, match="unknown"):
        conditions(["so102"], 2)
    assert len(conditions(["so101"], 2)) == 2 * 8 and Condition("so101", 0, 0.0, 0.0).key.startswith(
        "so101_arm0"
    )
    assert main(["reproduce", "hardware", "--robots", "so102", "--out", "/tmp"]) == 2
    assert "so102" in capsys.readouterr().err
