"""Tests of gb_pin.experiments.robot_bench: the results table of docs/ROBOTS.md (on a tiny planar run)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gb_pin import InvalidArgumentError, UnknownRobotError
from gb_pin.exceptions import GbPinError
from gb_pin.experiments.robot_bench import (
    BEGIN,
    END,
    PresetResult,
    benchmark_robot,
    default_robots,
    format_markdown,
    plot_curves,
    run,
    update_document,
)
from gb_pin.experiments.trialset import TrialSet
from gb_pin.robot.presets import robots


def test_default_robots_cover_every_preset() -> None:
    """Every preset is benchmarked; the planar family as planar5 and planar20."""
    names = default_robots()
    assert {"planar5", "planar20"} <= set(names)
    assert {p.name for p in robots() if p.source != "planar"} <= set(names)


def test_benchmark_row_matches_its_trials() -> None:
    """A row's medians and 90 % quantiles are those of its 3 trials at 1000 and the total movements."""
    row, ts = benchmark_robot("planar3", trials=3, movements=1200, workers=1, time_steps=False)
    assert (row.robot, row.dof, row.axes, row.targets, row.trials) == ("planar3", 3, "xy", 25, 3)
    assert row.movements == (1000, 1200)
    for k, count in enumerate((1000, 1200)):
        _, mid, high = sorted(ts.error[:, list(ts.movements).index(count)])
        # Of 3 values the median is the middle one; the 90 % quantile (linear interpolation) lies at
        # position 0.9 * (3 - 1) = 1.8 of the sorted values.
        assert row.median[k] == mid
        assert row.q90[k] == pytest.approx(mid + 0.8 * (high - mid), rel=1e-12)
    assert row.initial_error == ts.error[0, 0] > 0
    assert np.isnan(row.us_per_step)


@pytest.mark.parametrize(("end", "learns"), [(0.05, True), (0.099, True), (0.1, False), (0.5, False)])
def test_a_preset_learns_below_a_tenth_of_its_initial_error(end: float, learns: bool) -> None:
    """`learns` is the issue's criterion: median E^X at the end strictly below 0.10 E_0 (E_0 = 2 m here)."""
    row = PresetResult(
        robot="planar3", dof=3, axes="xy", kind="planar arm", targets=25, trials=3, movements=(1000, 2000),
        initial_error=2.0, median=(1.0, 2.0 * end), q90=(1.5, 1.0), home_distance=0.1, prototypes=10.0,
        us_per_step=1.0, parameters={},
    )  # fmt: skip
    assert row.learns is learns


def test_run_updates_document_figure_and_json(tmp_path: Path) -> None:
    """run() replaces the table between the markers, keeps the prose, writes the figure and JSON."""
    doc = tmp_path / "ROBOTS.md"
    doc.write_text(f"# Robots\n\nprose before\n\n{BEGIN}\nold table\n{END}\n\nprose after\n")
    figure = tmp_path / "curves.png"
    out = tmp_path / "results.json"
    results = run(
        ["planar3"], trials=2, movements=1000, workers=1, progress=False, doc=str(doc), figure=str(figure),
        json_path=str(out),
    )  # fmt: skip
    text = doc.read_text()
    assert "old table" not in text
    assert "prose before" in text and "prose after" in text
    assert "| planar3 | planar arm | 3 | xy | 25 |" in text
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert figure.stat().st_size > 10_000
    data = json.loads(out.read_text())
    assert data["results"][0]["robot"] == "planar3"
    assert results[0].us_per_step > 0
    assert text.count(BEGIN) == 1 and text.count(END) == 1


def test_bad_benchmark_requests() -> None:
    """Unknown presets fail before any trial; fewer than 1000 movements and empty tables are errors."""
    with pytest.raises(UnknownRobotError):
        run(["planar3", "no_such_robot"], trials=1, movements=1000, progress=False)
    with pytest.raises(InvalidArgumentError, match="0"):
        benchmark_robot("planar3", trials=1, movements=0)
    with pytest.raises(InvalidArgumentError):
        format_markdown([])


def test_update_document_needs_markers(tmp_path: Path) -> None:
    """A document without the markers is reported, not silently left unchanged."""
    doc = tmp_path / "plain.md"
    doc.write_text("no markers here\n")
    with pytest.raises(GbPinError, match="markers"):
        update_document(doc, "table")
    with pytest.raises(GbPinError, match="cannot read"):
        update_document(tmp_path / "missing.md", "table")


def test_writes_are_atomic(tmp_path: Path) -> None:
    """The document is replaced whole, and a figure that cannot be written leaves no file behind."""
    pytest.importorskip("matplotlib")
    doc = tmp_path / "ROBOTS.md"
    doc.write_text(f"{BEGIN}\nold\n{END}\n")
    update_document(doc, "new table")
    assert doc.read_text() == f"{BEGIN}\nnew table\n{END}\n"
    ts = TrialSet(
        robot="planar3", seed=0, parameters={}, movements=np.array([0, 10, 100]),
        error=np.array([[1.0, 0.5, 0.1], [1.0, 0.4, 0.2]]), home_distance=np.zeros((2, 3)),
        initial_error=1.0, prototypes=np.array([3, 4]),
    )  # fmt: skip
    with pytest.raises(ValueError, match="nosuchformat"):
        plot_curves([ts], tmp_path / "curves.nosuchformat")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ROBOTS.md"]
    plot_curves([ts], tmp_path / "curves.png")
    assert (tmp_path / "curves.png").read_bytes()[:4] == b"\x89PNG"


def test_short_benchmark_has_one_column_pair(capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin robots --benchmark --movements 500` runs; its table has one E^X pair, not a repeated one."""
    from gb_pin.cli import main

    args = ["robots", "--benchmark", "--robots", "planar3", "--trials", "2", "--movements", "500", "--quiet"]
    assert main(args) == 0
    text = capsys.readouterr().out
    header = next(line for line in text.splitlines() if line.startswith("| preset"))
    assert header.count("E^X 500 median") == 1 and "1000" not in header
    row = next(line for line in text.splitlines() if line.startswith("| planar3"))
    assert row.count("|") == header.count("|")
    assert "--movements 500" in text
