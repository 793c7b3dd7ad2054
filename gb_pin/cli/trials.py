"""``gb-pin trials``: independent trials in parallel, with S(Q, e) and the quantiles of E^X."""

from __future__ import annotations

import argparse
import sys
import time
from typing import TYPE_CHECKING

from gb_pin.cli.goal_options import add_goal_options, check_widths, goal_values
from gb_pin.cli.options import (
    add_learner_options,
    add_overwrite,
    add_quiet,
    add_robot_options,
    add_trial_seed,
    add_workers,
    learner_values,
    onboarding_lines,
    robot_argument,
)

if TYPE_CHECKING:
    from gb_pin.cli.options import Subparsers
    from gb_pin.experiments.trials import TrialSet


def add_trials(sub: Subparsers) -> None:
    """Register ``trials``."""
    sub.add_parser(
        "trials", help="independent trials in parallel, with S(Q, e) and quantiles", configure=_add_options
    )


def _add_options(t: argparse.ArgumentParser) -> None:
    """``trials``'s options: the trials, the learner, where they run, output."""
    add_robot_options(t, default="planar5")
    t.add_argument("--trials", type=int, default=100, help="number of trials (default 100)")
    t.add_argument("--movements", type=int, default=300, help="movements per trial (default 300)")
    add_trial_seed(t)
    add_workers(t)
    add_learner_options(t)
    add_goal_options(t, until=False)
    t.add_argument(
        "--scheduler",
        default=None,
        help=(
            "run the trials on this Dask scheduler, e.g. tcp://host:8786 (needs gb_pin[cluster]), or on "
            "SLURM, e.g. slurm:cores=4,memory=8GB,jobs=10 (needs gb_pin[slurm]; docs/CLUSTERS.md)"
        ),
    )
    t.add_argument("--json", default=None, help="write movements, error, home_distance, initial_error")
    add_overwrite(t, "--json")
    t.add_argument(
        "--checkpoint",
        default=None,
        help="trial journal: finished trials are appended to it and not recomputed when the command is rerun",
    )
    add_quiet(t)
    t.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the trials, print their summary and write --json if asked."""
    import gb_pin.cli.checks as checks
    from gb_pin import _validation as check
    from gb_pin.experiments.trials import run_trials

    check.positive_int("--trials", args.trials)
    check.movements("--movements", args.movements, minimum=1)
    checks.outputs(args, checkpoint="--checkpoint")  # a journal: rerunning the command goes on with it
    checks.fresh_outputs(args, json="--json")
    goal_args = goal_values(args, as_lists=True)
    given = goal_args.get("targets")  # a workspace region is not the model's goal set
    robot = robot_argument(
        args, "planar5", None if isinstance(given, str) else given
    )  # each worker builds it again
    check_widths(args, goal_args, robot)
    for line in onboarding_lines(robot):
        print(line, flush=True)
    start = time.perf_counter()
    result = run_trials(
        robot=robot,
        trials=args.trials,
        movements=args.movements,
        seed=args.seed,
        workers=args.workers,
        progress=not args.quiet,
        scheduler=args.scheduler,
        checkpoint=args.checkpoint,
        **learner_values(args, given_only=True),
        **goal_args,
    )
    _print_summary(args, result, time.perf_counter() - start)
    if args.json is not None:
        from gb_pin._files import write_or_fallback

        where = write_or_fallback(args.json, result.save)  # a failed write never loses the trials
        if where != args.json:
            print(f"gb-pin: warning: could not write {args.json}; saved to {where} instead", file=sys.stderr)
        print(f"saved            {where}")
    return 0


def _print_summary(args: argparse.Namespace, result: TrialSet, wall: float) -> None:
    """E_0, the final E^X and D^home over the trials, S(Q, 0.1 E_0) and the wall time."""
    import numpy as np

    e0 = result.initial_error
    q10, q50, q90 = result.quantiles((0.1, 0.5, 0.9))[:, -1]
    print(f"robot            {args.robot}, {result.trials} trials x {args.movements} movements")
    print(f"E_0              {e0:.4f} m")
    print(f"final E^X        median {q50:.5f} m (10 % {q10:.5f}, 90 % {q90:.5f})")
    print(f"final D^home     median {np.median(result.home_distance[:, -1]):.4f} rad")
    for q in (0.1, 0.25, 0.5, 0.75, 0.9):
        print(f"{f'S({q}, 0.1 E_0)':<17}{result.speed(q, 0.1 * e0)}")
    print(f"wall time        {wall:.2f} s")
