"""``gb-pin robots``: the robot presets, or (--benchmark) the table of docs/ROBOTS.md."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from gb_pin.cli.options import add_overwrite, add_quiet, add_trial_seed, add_workers, comma_list

if TYPE_CHECKING:
    from gb_pin.cli.options import Subparsers

DEFAULT_TRIALS = 10
DEFAULT_MOVEMENTS = 10000


def add_robots(sub: Subparsers) -> None:
    """Register ``robots``."""
    sub.add_parser(
        "robots",
        help="list the robot presets (--benchmark: the table of docs/ROBOTS.md)",
        configure=_add_options,
    )


def _add_options(r: argparse.ArgumentParser) -> None:
    """``robots``'s options, those of --benchmark."""
    r.add_argument("--benchmark", action="store_true", help="run trials on every preset and print the table")
    r.add_argument(
        "--erd",
        action="store_true",
        help="every arm of example-robot-data from its frame alone (joints, home, grid, radius chosen), "
        "5 trials of 3000 movements each unless --trials/--movements: the table of docs/ROBOTS.md",
    )
    r.add_argument(
        "--frames",
        default=None,
        metavar="ROBOT",
        help="list the joints and frames of ROBOT (a preset, erd:NAME, a URDF file, MODULE:NAME): "
        "what --frame and --joints may name",
    )
    r.add_argument("--arms", default=None, help="with --erd: NAME:FRAME,... (default: every arm)")
    r.add_argument("--robots", default=None, help="comma-separated presets (default: all, planar5, planar20)")
    r.add_argument(
        "--trials", type=int, default=DEFAULT_TRIALS, help=f"trials per preset (default {DEFAULT_TRIALS})"
    )
    r.add_argument(
        "--movements",
        type=int,
        default=DEFAULT_MOVEMENTS,
        help=f"movements per trial (default {DEFAULT_MOVEMENTS}; the table's columns: 1000 and this)",
    )
    add_trial_seed(r)
    add_workers(r)
    r.add_argument("--doc", default=None, help="update the table in this markdown file (docs/ROBOTS.md)")
    r.add_argument("--figure", default=None, help="write the learning curves to this PNG (matplotlib)")
    r.add_argument("--json", default=None, help="write the results and every trial's curve to this file")
    add_overwrite(r, "--json or --figure")
    add_quiet(r, "no progress output")
    r.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Print the presets, or run the benchmark."""
    if args.frames is not None:
        return _frames(args.frames)
    if args.erd:
        return _erd(args)
    if args.benchmark:
        return _benchmark(args)
    from gb_pin.robot.presets import format_presets

    print(format_presets())
    return 0


def _frames(spec: str) -> int:
    """--frames ROBOT: the joints and frames of any robot gb_pin loads."""
    from gb_pin.cli.options import is_model_spec
    from gb_pin.exceptions import InvalidArgumentError
    from gb_pin.robot.frames import format_frames
    from gb_pin.robot.spec import is_robot_spec

    moved: tuple[str, ...] = ()
    frame = None
    if is_model_spec(spec):
        from gb_pin.robot.models import load_example_robot, load_urdf_model

        model = load_example_robot(spec[4:])[0] if spec.startswith("erd:") else load_urdf_model(spec)
    else:
        if is_robot_spec(spec):
            from gb_pin.robot.spec import load_robot_spec

            target = load_robot_spec(spec)
        else:
            from gb_pin.robot.presets import load_robot

            target = load_robot(spec)  # an unknown preset: the closest names
        if not hasattr(target, "full_model"):
            raise InvalidArgumentError(
                f"--frames {spec}: {type(target).__name__} has no Pinocchio model "
                "(a robot given as a function)"
            )
        model = target.full_model
        moved, frame = tuple(getattr(target, "joints", None) or ()), getattr(target, "frame", None)
    print(format_frames(model, spec, moved, frame))
    return 0


def _benchmark(args: argparse.Namespace) -> int:
    """--benchmark: trials on every preset; the table, and optionally the doc, figure and JSON."""
    import gb_pin.cli.checks as checks
    from gb_pin.experiments.robot_bench import run as run_benchmark

    checks.outputs(args, doc="--doc")  # a page whose table is updated in place
    checks.fresh_outputs(args, json="--json", figure="--figure")

    # The command recorded with the table: how to regenerate it.
    command = "gb-pin robots --benchmark"
    if args.trials != DEFAULT_TRIALS:
        command += f" --trials {args.trials}"
    if args.movements != DEFAULT_MOVEMENTS:
        command += f" --movements {args.movements}"
    run_benchmark(
        comma_list(args.robots) if args.robots else None,
        trials=args.trials,
        movements=args.movements,
        seed=args.seed,
        workers=args.workers,
        progress=not args.quiet,
        doc=args.doc,
        figure=args.figure,
        json_path=args.json,
        command=command,
    )
    return 0


ERD_TRIALS = 5
ERD_MOVEMENTS = 3000


def _erd(args: argparse.Namespace) -> int:
    """--erd: every arm of example-robot-data onboarded from its frame; the table, and optionally the doc."""
    import gb_pin.cli.checks as checks
    from gb_pin.experiments.arm_bench import parse_arms
    from gb_pin.experiments.arm_bench import run as run_arms

    checks.outputs(args, doc="--doc")
    trials = ERD_TRIALS if args.trials == DEFAULT_TRIALS else args.trials
    movements = ERD_MOVEMENTS if args.movements == DEFAULT_MOVEMENTS else args.movements
    command = "gb-pin robots --erd"
    if trials != ERD_TRIALS:
        command += f" --trials {trials}"
    if movements != ERD_MOVEMENTS:
        command += f" --movements {movements}"
    run_arms(
        parse_arms(args.arms) if args.arms else None,
        seeds=trials,
        movements=movements,
        workers=args.workers,
        progress=not args.quiet,
        doc=args.doc,
        command=command,
    )
    return 0
