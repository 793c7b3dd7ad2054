"""Sweep the learning rate of a planar arm over independent trials, locally or on a Dask cluster."""

from __future__ import annotations

import argparse
import time

import gb_pin


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--robot", default="planar5", help="preset name (default planar5)")
    parser.add_argument("--learning-rates", default="0.02,0.1,0.5", help="comma-separated learning rates")
    parser.add_argument("--trials", type=int, default=20, help="trials per learning rate (default 20)")
    parser.add_argument("--movements", type=int, default=1000, help="movements per trial (default 1000)")
    parser.add_argument("--scheduler", default=None, help="Dask scheduler address, e.g. tcp://host:8786")
    parser.add_argument("--out", default=None, help="save the whole sweep to this JSON file")
    args = parser.parse_args()

    rates = [float(r) for r in args.learning_rates.split(",")]
    start = time.perf_counter()
    sweep = gb_pin.run_sweep(
        robot=args.robot,
        learning_rate=rates,
        trials=args.trials,
        movements=args.movements,
        scheduler=args.scheduler,
        progress=True,
    )
    wall = time.perf_counter() - start
    print(f"{'condition':<32} {'S(0.5, 0.1 E_0)':>16} {'S(0.9, 0.1 E_0)':>16} {'final median E^X [m]':>21}")
    for condition, trials in sweep:
        level = 0.1 * trials.initial_error
        median = trials.quantiles([0.5])[0, -1]
        s50, s90 = trials.speed(0.5, level), trials.speed(0.9, level)
        print(f"{condition.label:<32} {s50!s:>16} {s90!s:>16} {median:>21.5f}")
    print(f"{len(sweep)} conditions x {args.trials} trials in {wall:.1f} s")
    if args.out:
        sweep.save(args.out)


if __name__ == "__main__":
    main()
