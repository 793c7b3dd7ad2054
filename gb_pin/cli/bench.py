"""``gb-pin bench``: microseconds per babbling step, per robot; ``--ik``: the IK benchmark (docs/IK.md)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from gb_pin.cli.options import add_model_options, comma_list, robot_list

if TYPE_CHECKING:
    from gb_pin.cli.options import Subparsers


ROBOTS_DEFAULT = "planar5,planar20,planar50"


def add_bench(sub: Subparsers) -> None:
    """Register ``bench``."""
    sub.add_parser("bench", help="microseconds per babbling step", configure=_add_options)


def _add_options(s: argparse.ArgumentParser) -> None:
    """``bench``'s options."""
    s.add_argument(
        "--robots",
        default=None,
        help="comma-separated robots (default planar5,20,50; --ik: all presets): presets, MODULE:NAME, "
        "or a URDF file or erd:NAME with --frame (and the other model options)",
    )
    add_model_options(s)
    s.add_argument("--movements", type=int, default=None, help="movements per run (default 2000; --ik 3000)")
    s.add_argument("--repeat", type=int, default=3, help="runs per robot, best is reported (default 3)")
    s.add_argument(
        "--ik",
        action="store_true",
        help="the IK benchmark instead (docs/IK.md): every preset, 3000 movements unless --movements given",
    )
    s.add_argument(
        "--doc", default=None, help="with --ik: update the tables in this markdown file (docs/IK.md)"
    )
    s.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Time the runs and print the table (or, with --ik, run the IK benchmark)."""
    if args.ik:
        return _ik(args)
    from gb_pin import _validation as check
    from gb_pin.experiments.bench import format_table, run_benchmark

    movements = 2000 if args.movements is None else args.movements
    check.positive_int("--repeat", args.repeat)
    check.movements("--movements", movements, minimum=1)
    robots = robot_list(args, comma_list(args.robots or ROBOTS_DEFAULT))
    rows = run_benchmark(robots, movements=movements, repeat=args.repeat)
    print(format_table(rows))
    return 0


def _ik(args: argparse.Namespace) -> int:
    """--ik: learned vs home vs random seeds on every preset; the tables, and optionally the doc."""
    import sys

    import gb_pin.cli.checks as checks
    from gb_pin import _validation as check
    from gb_pin.experiments.ik_bench import ROBOTS
    from gb_pin.experiments.ik_bench import run as run_ik

    robots = ROBOTS if args.robots is None else tuple(comma_list(args.robots))
    movements = 3000 if args.movements is None else args.movements
    check.movements("--movements", movements, minimum=1)
    checks.outputs(args, doc="--doc")
    print(run_ik(robots, movements, doc=args.doc, progress=lambda line: print(line, file=sys.stderr)))
    return 0
