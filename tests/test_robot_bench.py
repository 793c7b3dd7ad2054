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
    benchmark_robot,
    default_robots,
    format_markdown,
    run,
    update_document,
)
from gb_pin.robot.presets import robots


def test_default_robots_cover_every_preset() -> None:
    """Every preset is benchmarked; the planar family as planar5 and planar20."""
    names = default_robots()
    assert {"planar5", "planar20"} <= set(names)
    assert {p.name for p in robots() if p.source != "planar"} <= set(names)


def test_benchmark_row_matches_its_trials() -> None:
    """A row's medians and quantiles are those of its TrialSet at 1000 and the total movements."""
    row, ts = benchmark_robot("planar3", trials=3, movements=1200, workers=1, time_steps=False)
    assert (row.robot, row.dof, row.axes, row.targets, row.trials) == ("planar3", 3, "xy", 25, 3)
    assert row.movements == (1000, 1200)
    end = ts.error[:, -1]
    assert row.median[1] == pytest.approx(float(np.median(end)))
    assert row.q90[1] == pytest.approx(float(np.quantile(end, 0.9)))
    assert row.initial_error == pytest.approx(ts.initial_error)
    assert row.learns == (row.median[1] < 0.1 * row.initial_error)
    assert np.isnan(row.us_per_step)


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
    with pytest.raises(InvalidArgumentError, match="1000"):
        benchmark_robot("planar3", trials=1, movements=500)
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
