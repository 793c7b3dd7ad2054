"""``gb-pin reproduce``: the paper's figures 3-8, their numbers and results.md."""

from __future__ import annotations

import argparse
import os
from typing import TYPE_CHECKING

from gb_pin.cli.options import (
    ROBOT_HELP,
    add_model_options,
    add_overwrite,
    add_quiet,
    add_trial_seed,
    add_workers,
    comma_list,
    onboarding_lines,
    robot_argument,
)
from gb_pin.exceptions import InvalidArgumentError

if TYPE_CHECKING:
    from gb_pin.cli.options import Subparsers


def add_reproduce(sub: Subparsers) -> None:
    """Register ``reproduce``."""
    sub.add_parser(
        "reproduce",
        help="the paper's figures 3-8, their numbers and results.md; 'goals': see docs/GOALS.md",
        configure=_add_options,
    )


def _add_options(p: argparse.ArgumentParser) -> None:
    """``reproduce``'s figures and options."""
    p.add_argument(
        "figures",
        nargs="+",
        metavar="FIGURE",
        help="fig3, fig4, fig5, fig6, fig7, fig8, throughput or all; or goals: the goal generators of "
        "docs/GOALS.md (E^X on a test grid, 20 trials; cached in OUT/trials; --scheduler, --fresh unused); "
        "or hardware: mis-calibrated arms, URDF IK vs learned vs feedback (docs/HARDWARE.md; --trials "
        "arms per robot, default 20; --robots); or workspace: half of every joint's range "
        "(docs/WORKSPACE.md; --trials seeds, default 10; --robots; --fractions)",
    )
    p.add_argument(
        "--robots", default=None, help="hardware: comma-separated robots (default so101,so100,panda)"
    )
    p.add_argument(
        "--fractions",
        default=None,
        help="workspace: comma-separated fractions of the joint ranges (default 0.25,0.5)",
    )
    p.add_argument("--out", default="reproduction", help="output folder (default ./reproduction)")
    add_overwrite(p, "the figures and tables in --out (its cached trials are reused either way)")
    p.add_argument(
        "--trials", type=int, default=None, help="trials per condition (default 100, the paper's; goals: 20)"
    )
    p.add_argument(
        "--movements",
        type=int,
        default=10_000,
        help="movements per trial; final errors are read there (default 10000; the paper: 1e6-1e7)",
    )
    add_trial_seed(p)
    add_workers(p, "local processes (default: all cores)")
    p.add_argument(
        "--scheduler",
        default=None,
        help="run the trials on this Dask scheduler (tcp://host:8786) or SLURM (slurm:cores=4,memory=8GB)",
    )
    p.add_argument("--fresh", action="store_true", help="ignore the cached trials in OUT/trials")
    p.add_argument(
        "--robot",
        default=None,
        help="goals only: run the study on this robot instead of planar5, planar20, talos_left_arm and "
        "g1_left_arm: " + ROBOT_HELP,
    )
    add_model_options(p)
    add_quiet(p)
    p.set_defaults(func=run)


REPORTS = {"hardware": "hardware.md", "workspace": "workspace.md", "goals": "goals.md"}


def _reports(figures: list[str]) -> list[str]:
    """The files in OUT that say a reproduction of ``figures`` was finished there (report, figures)."""
    if len(figures) == 1 and figures[0] in REPORTS:
        return [REPORTS[figures[0]]]
    from gb_pin.reproduce.conditions import expand

    return [f"{name}.png" for name in expand(figures) if name != "throughput"]


def run(args: argparse.Namespace) -> int:
    """Reproduce the figures asked for and say where they went."""
    import gb_pin.cli.checks as checks
    from gb_pin.reproduce import reproduce

    checks.directory(args.out, "--out")
    for name in _reports(args.figures):  # a finished reproduction is not replaced by accident
        checks.no_clobber(os.path.join(args.out, name), "--out", args.overwrite)
    if args.figures == ["hardware"]:
        from gb_pin.reproduce.hardware import run_hardware

        robots = ("so101", "so100", "panda") if args.robots is None else tuple(comma_list(args.robots))
        files = run_hardware(
            args.out, robots=robots, arms=20 if args.trials is None else args.trials,
            movements=args.movements, workers=args.workers, fresh=args.fresh, progress=not args.quiet,
        )  # fmt: skip
        print(f"wrote {len(files)} files to {args.out} (see hardware.md)")
        return 0
    if args.figures == ["workspace"]:
        from gb_pin.reproduce.workspace import FRACTIONS, run_workspace
        from gb_pin.reproduce.workspace import ROBOTS as WORKSPACE_ROBOTS

        robots = WORKSPACE_ROBOTS if args.robots is None else tuple(comma_list(args.robots))
        try:
            fractions = (
                FRACTIONS if args.fractions is None else tuple(float(v) for v in comma_list(args.fractions))
            )
        except ValueError as exc:
            raise InvalidArgumentError(
                f"--fractions must be numbers in (0, 1], got {args.fractions!r}"
            ) from exc
        files = run_workspace(
            args.out, robots=robots, fractions=fractions, seeds=10 if args.trials is None else args.trials,
            movements=args.movements, workers=args.workers, fresh=args.fresh, progress=not args.quiet,
        )  # fmt: skip
        print(f"wrote {len(files)} files to {args.out} (see workspace.md)")
        return 0
    if args.figures == ["goals"]:
        from gb_pin.reproduce.goals import ROBOTS, goal_study

        trials = 20 if args.trials is None else args.trials
        kw = {
            "movements": args.movements,
            "seed": args.seed,
            "workers": args.workers,
            "progress": not args.quiet,
        }
        robot = robot_argument(args)
        for line in onboarding_lines(robot):
            print(line, flush=True)
        files = goal_study(args.out, trials=trials, robots=ROBOTS if robot is None else [robot], **kw)
        print(f"wrote {len(files)} files to {args.out} (see goals.md)")
        return 0
    if args.robot is not None or args.frame is not None:
        raise InvalidArgumentError(
            "--robot: only with `reproduce goals`; the paper's figures are of its planar arms"
        )
    result = reproduce(
        args.figures,
        out=args.out,
        trials=100 if args.trials is None else args.trials,
        movements=args.movements,
        seed=args.seed,
        workers=args.workers,
        scheduler=args.scheduler,
        progress=not args.quiet,
        fresh=args.fresh,
        log=print,
    )
    print(f"wrote {len(result.files)} files to {args.out} in {result.wall_time:.0f} s (see results.md)")
    return 0
