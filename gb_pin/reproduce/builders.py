"""Each figure of the paper from its trials (numbers, CSV, drawing), and the throughput benchmark.

Every builder returns the files it wrote and the numbers that go to ``results.json``
under the figure's name. Figs. 3 and 6 are :func:`gb_pin.reproduce.snapshots.snapshot_figure`.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from typing import Any

from gb_pin.experiments.trials import Condition, TrialSet, run_trials
from gb_pin.reproduce.conditions import FIG4_RATES, JOINTS, LEARNING_RATES, Settings, conditions_for
from gb_pin.reproduce.figures import draw_curves, draw_rows
from gb_pin.reproduce.report import write_curves_csv, write_rows_csv
from gb_pin.reproduce.stats import curve_numbers, row_numbers, speedup

Trials = dict[Condition, TrialSet]


def figure4(data: Trials, st: Settings, formats: Sequence[str]) -> tuple[list[str], Any]:
    """Fig. 4: planar5, eta 0.1 and 0.01, E^X and D^home over movements."""
    files = []
    numbers: dict[str, Any] = {"settings": st.as_dict(), "curves": {}}
    sets = []
    for c in conditions_for("fig4", st.movements):
        ts = data[c]
        eta = c.parameters["learning_rate"]
        sets.append((f"η = {eta:g}", ts))
        numbers["curves"][f"{eta:g}"] = curve_numbers(ts, st.movements)
        files.append(write_curves_csv(os.path.join(st.out, f"fig4_planar5_eta{eta:g}.csv"), ts))
    fast, slow = (numbers["curves"][f"{eta:g}"]["first_median_le_0.04"] for eta in FIG4_RATES)
    numbers["speedup"] = speedup(fast, slow)
    title = f"Fig. 4: planar5, {st.trials} trials, learning rates 0.1 and 0.01"
    files += draw_curves(sets, title, st.out, "fig4", formats)
    return files, numbers


def figure7(data: Trials, st: Settings, formats: Sequence[str]) -> tuple[list[str], Any]:
    """Fig. 7: planar20 vs planar50 (sigma by Eq. 12), E^X and D^home over movements."""
    files = []
    numbers: dict[str, Any] = {"settings": st.as_dict(), "curves": {}}
    sets = []
    for c in conditions_for("fig7", st.movements):
        ts = data[c]
        m = c.robot.removeprefix("planar")
        sets.append((f"m = {m}", ts))
        numbers["curves"][m] = curve_numbers(ts, st.movements)
        files.append(write_curves_csv(os.path.join(st.out, f"fig7_{c.robot}.csv"), ts))
    title = f"Fig. 7: 20 and 50 joints, η = 0.1, {st.trials} trials"
    files += draw_curves(sets, title, st.out, "fig7", formats)
    return files, numbers


def figure5(data: Trials, st: Settings, formats: Sequence[str]) -> tuple[list[str], Any]:
    """Fig. 5: S(Q, 0.1 E_0) (Eq. 11), final E^X and D^home over learning rates."""
    rows = [row_numbers(data[c], st.movements) for c in conditions_for("fig5", st.movements)]
    numbers = {"settings": st.as_dict(), "learning_rates": list(LEARNING_RATES), "rows": rows}
    files = [write_rows_csv(os.path.join(st.out, "fig5.csv"), "learning_rate", LEARNING_RATES, rows)]
    title = f"Fig. 5: planar5, learning rates 0.001-0.5, {st.trials} trials"
    files += draw_rows(LEARNING_RATES, rows, "learning rate η", True, title, st.out, "fig5", formats)
    return files, numbers


def figure8(data: Trials, st: Settings, formats: Sequence[str]) -> tuple[list[str], Any]:
    """Fig. 8: S(Q, 0.1 E_0) (Eq. 11), final E^X and D^home over the number of joints m."""
    rows = [row_numbers(data[c], st.movements) for c in conditions_for("fig8", st.movements)]
    numbers = {"settings": st.as_dict(), "joints": list(JOINTS), "rows": rows}
    files = [write_rows_csv(os.path.join(st.out, "fig8.csv"), "joints", JOINTS, rows)]
    title = f"Fig. 8: 2-50 joints, η = 0.1, σ by Eq. 12, {st.trials} trials"
    files += draw_rows(JOINTS, rows, "joints m", False, title, st.out, "fig8", formats)
    return files, numbers


def throughput(st: Settings, workers: int | None, scheduler: Any) -> tuple[list[str], Any]:
    """Wall time of 100 trials x 1000 movements of planar5 (the issue's benchmark), pool start included."""
    run_trials("planar2", trials=1, movements=1, workers=1)  # compile or load the kernels first
    start = time.perf_counter()
    ts = run_trials("planar5", trials=100, movements=1000, seed=st.seed, workers=workers, scheduler=scheduler)
    wall = time.perf_counter() - start
    return [], {
        "trials": ts.trials,
        "movements": 1000,
        "wall_time": wall,
        "workers": workers if scheduler is None else "dask",
        "cpu_count": os.cpu_count(),
        "steps_per_second": ts.trials * 1000 * 25 / wall,
    }
