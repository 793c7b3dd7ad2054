"""Bootstrap 95 % intervals of the reproduction's headline numbers from the trials gb-pin reproduce cached.

The trials are read from the cache of ``gb-pin reproduce`` (``OUT/trials/*.json``). To make it::

    gb-pin reproduce fig4 fig5 fig7 --out docs/figures --overwrite   # 100 trials x 10^4 movements, ~20 min

A condition missing from the cache is run here instead (and not saved), so small options run out of
the box in seconds::

    python examples/reproduction_intervals.py --movements 300 --trials 5 --resamples 200
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

import gb_pin

Statistic = Callable[[NDArray[np.float64], gb_pin.TrialSet], float | None]


def interval(ts: gb_pin.TrialSet, stat: Statistic, rng: np.random.Generator, n: int) -> tuple[float, float]:
    """2.5 % and 97.5 % percentiles of ``stat`` over ``n`` resamplings of the trials with replacement."""
    values = []
    for _ in range(n):
        v = stat(ts.error[rng.integers(0, ts.trials, ts.trials)], ts)
        values.append(np.nan if v is None else v)
    if np.all(np.isnan(values)):  # never reached in any resampling
        return np.nan, np.nan
    lo, hi = np.nanpercentile(values, [2.5, 97.5])
    return float(lo), float(hi)


def speed(q: float) -> Statistic:
    """S(Q, 0.1 E_0) (Eq. 11) of a resampled error matrix."""
    return lambda err, ts: gb_pin.speed(ts.movements, err, q, 0.1 * ts.initial_error)


def median_at_100(err: NDArray[np.float64], ts: gb_pin.TrialSet) -> float:
    """Median E^X after 100 movements [m]."""
    return float(np.median(err[:, ts.at(100)]))


def first_median_le_004(err: NDArray[np.float64], ts: gb_pin.TrialSet) -> float | None:
    """First recorded movement count with median E^X <= 0.04 m."""
    hit = np.flatnonzero(np.median(err, axis=0) <= 0.04)
    return float(ts.movements[hit[0]]) if hit.size else None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", default="docs/figures", help="the --out folder of gb-pin reproduce")
    parser.add_argument("--movements", type=int, default=10_000, help="its --movements (default 10000)")
    parser.add_argument("--trials", type=int, default=100, help="its --trials (default 100)")
    parser.add_argument("--resamples", type=int, default=2000, help="bootstrap resamples (default 2000)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the resampling")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    loaded: dict[str, gb_pin.TrialSet] = {}

    def trials(robot: str, eta: float) -> gb_pin.TrialSet:
        name = f"{robot}_learning_rate-{eta:g}_n{args.movements}_t{args.trials}_s0.json"
        path = os.path.join(args.out, "trials", name)
        if path in loaded:
            return loaded[path]
        if os.path.exists(path):
            loaded[path] = gb_pin.TrialSet.load(path)
            return loaded[path]
        print(
            f"{path} not cached (see this file's docstring: gb-pin reproduce makes it); "
            f"running {args.trials} trials of {args.movements} movements here",
            file=sys.stderr,
            flush=True,
        )
        loaded[path] = gb_pin.run_trials(
            robot=robot, trials=args.trials, movements=args.movements, learning_rate=eta, progress=False
        )
        return loaded[path]

    rows = [
        ("planar5, eta 0.1: median E^X after 100 movements [m]", trials("planar5", 0.1), median_at_100, 0.04),
        (
            "planar5, eta 0.01: first count with median E^X <= 0.04 m",
            trials("planar5", 0.01),
            first_median_le_004,
            2000,
        ),
        ("planar5, eta 0.5: S(0.5, 0.1 E_0)", trials("planar5", 0.5), speed(0.5), 34),
        ("planar50: S(0.5, 0.1 E_0)", trials("planar50", 0.1), speed(0.5), 128),
        ("planar50: S(0.9, 0.1 E_0)", trials("planar50", 0.1), speed(0.9), 364),
    ]
    print(f"| quantity | paper | gb_pin | 95 % bootstrap interval ({args.resamples} resamples) |")
    print("|---|---|---|---|")
    for label, ts, stat, paper in rows:
        lo, hi = interval(ts, stat, rng, args.resamples)
        print(f"| {label} | {paper:g} | {_number(stat(ts.error, ts))} | [{_number(lo)}, {_number(hi)}] |")


def _number(value: float | None) -> str:
    """A table cell: 4 significant digits, or "not reached" (None, NaN: e.g. too few movements)."""
    return "not reached" if value is None or not np.isfinite(value) else f"{value:.4g}"


if __name__ == "__main__":
    main()
