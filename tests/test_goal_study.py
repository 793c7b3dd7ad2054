"""The goal-generator study of docs/GOALS.md runs end to end with tiny settings, and its command is wired."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from gb_pin.reproduce.goals import goal_sets, goal_study, schedule


def test_goal_sets_keep_test_grid_apart_from_goal_sets() -> None:
    """The planar test grid G is issue 11's 6 x 6 grid, reachable, and shares no point with X* or O."""
    sets = goal_sets("planar5")
    assert sets["test"].shape == (36, 2) and sets["O"].shape == (81, 2)
    for other in (sets["X*"], sets["O"]):
        d = np.linalg.norm(sets["test"][:, None] - other[None], axis=2)
        assert d.min() > 1e-6


def test_schedule_reads_the_table_counts() -> None:
    """E^X is recorded at 300, 1000, 3000 and 10^4 movements."""
    assert {300, 1000, 3000, 10_000} <= set(schedule(10_000))


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_goal_study_writes_its_files_and_reads_its_cache(tmp_path: os.PathLike[str]) -> None:
    """Two trials of 20 movements on planar5: figure, JSON, CSV and table written; a rerun reads the cache."""
    out = os.fspath(tmp_path)
    files = goal_study(out, trials=2, movements=20, robots=("planar5",), workers=1, log=None)
    assert {os.path.basename(f) for f in files} == {
        "goals_planar5.png",
        "goals.json",
        "goals.csv",
        "goals.md",
    }
    assert all(os.path.getsize(f) > 0 for f in files)
    with open(os.path.join(out, "goals.json"), encoding="utf-8") as fh:
        body = json.load(fh)
    assert "directions" in body["results"]["planar5"]
    cached = sorted(os.listdir(os.path.join(out, "trials")))
    stamp = [os.path.getmtime(os.path.join(out, "trials", f)) for f in cached]
    goal_study(out, trials=2, movements=20, robots=("planar5",), workers=1, log=None)
    assert [os.path.getmtime(os.path.join(out, "trials", f)) for f in cached] == stamp


def test_cli_reproduce_goals_help() -> None:
    """``gb-pin reproduce --help`` names the goals target."""
    res = subprocess.run(
        [sys.executable, "-m", "gb_pin", "reproduce", "--help"], capture_output=True, text=True, check=True
    )
    assert "goals" in res.stdout
