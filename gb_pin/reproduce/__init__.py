"""Reproduce the paper's experiments (Sec. III, Figs. 3-8): trials, figures, numbers and a report.

``gb-pin reproduce all --trials 100 --out docs/figures`` runs every condition the
figures need as one sweep (:func:`gb_pin.run_sweep`, locally or on a Dask cluster),
then writes, for each figure, a PNG and an SVG in the paper's style (median bold,
10 % and 90 % quantiles thin, 25-75 % filled), the numbers as CSV and JSON, and
``results.md``: the table "paper vs gb_pin" and the run lengths each number used.

Run lengths. The paper runs 10^6 (Fig. 8) and 10^7 (Fig. 5) movements per trial for
its final errors; ``movements`` (default 10^4) sets ours. Fig. 5 runs each learning
rate eta < 0.01 for N * 0.01 / eta movements (the budget eta * r of eta = 0.01), so that
the slowest rates reach 10 % of the initial error at all; its final errors are read at ``movements``
for every rate. The raw trials are cached in ``OUT/trials/`` (git-ignored), so that
figures sharing a condition (e.g. planar5 at eta 0.1 in Figs. 4, 5 and 8) run it once.

Matplotlib is needed (``pip install "gb_pin[plots]"``); figures are drawn on
``matplotlib.figure.Figure`` objects with the Agg renderer, never through pyplot's
global state.

Modules: :mod:`~gb_pin.reproduce.conditions` (what each figure runs),
:mod:`~gb_pin.reproduce.paper` (the paper's numbers, from ``paper.toml``),
:mod:`~gb_pin.reproduce.cache` (``OUT/trials/``), :mod:`~gb_pin.reproduce.stats` (the
numbers of a condition), :mod:`~gb_pin.reproduce.figures` (drawing; the only one that
imports matplotlib), :mod:`~gb_pin.reproduce.snapshots` (Figs. 3 and 6),
:mod:`~gb_pin.reproduce.builders` (Figs. 4, 5, 7, 8 and the throughput benchmark),
:mod:`~gb_pin.reproduce.report` (CSV, ``results.json``, ``results.md``) and
:mod:`~gb_pin.reproduce.pipeline` (:func:`reproduce`).
"""

from __future__ import annotations

from gb_pin.reproduce.builders import figure4, figure5, figure7, figure8, throughput
from gb_pin.reproduce.cache import collect
from gb_pin.reproduce.conditions import (
    FIG4_RATES,
    FIG7_ROBOTS,
    FIGURES,
    JOINTS,
    LEARNING_RATES,
    PER_DECADE,
    QUANTILES,
    SNAPSHOTS,
    Settings,
    conditions_for,
    expand,
    fig5_length,
    schedule,
)
from gb_pin.reproduce.figures import COLORS, quantile_band
from gb_pin.reproduce.paper import MEDIAN_LEVEL, PAPER, Claim
from gb_pin.reproduce.pipeline import Reproduction, reproduce
from gb_pin.reproduce.report import paper_table, render_results
from gb_pin.reproduce.snapshots import arm_points, snapshot_figure
from gb_pin.reproduce.stats import curve_numbers, first_median_below, row_numbers, speeds

__all__ = [
    "COLORS",
    "FIG4_RATES",
    "FIG7_ROBOTS",
    "FIGURES",
    "JOINTS",
    "LEARNING_RATES",
    "MEDIAN_LEVEL",
    "PAPER",
    "PER_DECADE",
    "QUANTILES",
    "SNAPSHOTS",
    "Claim",
    "Reproduction",
    "Settings",
    "arm_points",
    "collect",
    "conditions_for",
    "curve_numbers",
    "expand",
    "fig5_length",
    "figure4",
    "figure5",
    "figure7",
    "figure8",
    "first_median_below",
    "paper_table",
    "quantile_band",
    "render_results",
    "reproduce",
    "row_numbers",
    "schedule",
    "snapshot_figure",
    "speeds",
    "throughput",
]
