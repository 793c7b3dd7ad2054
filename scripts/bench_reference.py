"""gb_pin against the closed-form reference (scripts/planar_reference.py), timed alternately in one run.

The two implementations of the same algorithm run the same planar arm, the same hyperparameters
and the same seed, in turn (reference, gb_pin, gb_pin, reference, ...), each timed on its compiled
loop alone with E^X recorded only at the start and the end, so that drifts of a shared machine's
load hit both alike. The clock is the thread's CPU time (a shared machine's wall clock also
counts the time other processes hold the core). Prints, per arm, the median us/step of each and
the ratio gb_pin/reference with its range over the rounds, then what shows they are the same
algorithm: E^X after each of the first movements of one seed (the same random numbers: equal to
rounding until the runs part), and the final E^X and prototype counts over all rounds' seeds
(the same statistics).

    python scripts/bench_reference.py --robots planar5,planar50 --rounds 15 --movements 2000
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from planar_reference import reference_run

import gb_pin
from gb_pin.learn.state import BabbleState


def setting(robot: str) -> tuple[Any, Any, np.ndarray]:
    """(target, config, hyper) of a planar preset, the learner's defaults."""
    target = gb_pin.load_robot(robot)
    config = gb_pin.GoalBabbling()._resolve(target.n_joints)
    hyper = np.array([config.learning_rate, config.sigma, config.sigma_delta, config.radius,
                      config.path_length, config.p_home])  # fmt: skip
    return target, config, hyper


def run_gb_pin(robot: str, movements: int, seed: int, schedule: np.ndarray) -> tuple[float, np.ndarray, int]:
    """(us/step of the compiled loop in thread CPU time, E^X at ``schedule``, prototypes)."""
    target, config, _ = setting(robot)
    st = BabbleState.start(target, target.targets, movements, config, seed=seed, schedule=schedule)
    start = time.thread_time()
    st.run(movements)
    seconds = time.thread_time() - start
    return 1e6 * seconds / st.steps, st.errors.copy(), st.llm.n_prototypes_


def run_reference(
    robot: str, movements: int, seed: int, schedule: np.ndarray
) -> tuple[float, np.ndarray, int]:
    """(us/step of the reference in thread CPU time, E^X at ``schedule``, prototypes)."""
    target, config, hyper = setting(robot)
    errors = np.full(schedule.shape[0], np.nan)
    rng = np.random.default_rng(seed)
    home, targets = np.array(target.home), np.ascontiguousarray(target.targets)
    start = time.thread_time()
    K = reference_run(rng, target.n_joints, targets, home, hyper, movements, schedule, errors)
    seconds = time.thread_time() - start
    return 1e6 * seconds / (movements * config.path_length), errors, int(K)


RUNS = {"reference": run_reference, "gb_pin": run_gb_pin}


def main(argv: list[str] | None = None) -> int:
    """Alternate reference and gb_pin for --rounds rounds per arm; print timings and agreement."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", default="planar5,planar50")
    parser.add_argument("--movements", type=int, default=2000)
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--early", type=int, default=10, help="movements compared one by one (seed 0)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")  # extrapolation warnings of the first movements
    robots = args.robots.split(",")
    ends = np.array([0, args.movements])
    for robot in robots:  # compile or load both, build the robots: not timed
        for run in RUNS.values():
            run(robot, 5, 0, np.array([0, 5]))
    times: dict[tuple[str, str], list[float]] = {}
    finals: dict[tuple[str, str], list[tuple[float, int]]] = {}
    for r in range(args.rounds):
        for c, robot in enumerate(robots):
            order = ("reference", "gb_pin") if (r + c) % 2 == 0 else ("gb_pin", "reference")
            for name in order:
                us, errors, K = RUNS[name](robot, args.movements, r, ends)
                times.setdefault((name, robot), []).append(us)
                finals.setdefault((name, robot), []).append((float(errors[-1]), K))
    print(f"{args.rounds} alternating rounds of {args.movements} movements per arm (compiled loops; CPU)")
    print("| robot | reference us/step | gb_pin us/step | gb_pin/reference (median, range of rounds) |")
    print("|---|---|---|---|")
    for robot in robots:
        ref, gb = times[("reference", robot)], times[("gb_pin", robot)]
        ratios = [g / f for g, f in zip(gb, ref, strict=True)]
        print(
            f"| {robot} | {statistics.median(ref):.2f} | {statistics.median(gb):.2f} "
            f"| {statistics.median(gb) / statistics.median(ref):.3f} ({min(ratios):.2f}-{max(ratios):.2f}) |"
        )
    early = np.arange(args.early + 1)
    print(f"\nsame algorithm: E^X after movements 0..{args.early} (seed 0); over seeds 0..{args.rounds - 1}")
    for robot in robots:
        e_ref = run_reference(robot, args.early, 0, early)[1]
        e_gb = run_gb_pin(robot, args.early, 0, early)[1]
        rel = np.max(np.abs(e_gb - e_ref) / e_ref)
        print(f"{robot}: largest relative difference of E^X over the first {args.early} movements {rel:.1e}")
        for name in RUNS:
            e = np.array([f[0] for f in finals[(name, robot)]])
            k = np.array([f[1] for f in finals[(name, robot)]])
            q1, q2, q3 = np.quantile(e, [0.25, 0.5, 0.75])
            print(
                f"  {name:9s} E^X at {args.movements}: median {q2:.5f} m (quartiles {q1:.5f}-{q3:.5f}), "
                f"prototypes median {np.median(k):.0f} ({k.min()}-{k.max()})"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
