"""``gb-pin bench``: microseconds per babbling step, per robot."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from gb_pin.cli.options import comma_list

if TYPE_CHECKING:
    from gb_pin.cli.options import Subparsers


def add_bench(sub: Subparsers) -> None:
    """Register ``bench``."""
    sub.add_parser("bench", help="microseconds per babbling step", configure=_add_options)


def _add_options(s: argparse.ArgumentParser) -> None:
    """``bench``'s options."""
    s.add_argument("--robots", default="planar5,planar20,planar50", help="comma-separated presets")
    s.add_argument("--movements", type=int, default=2000, help="movements per run (default 2000)")
    s.add_argument("--repeat", type=int, default=3, help="runs per robot, best is reported (default 3)")
    s.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Time the runs and print the table."""
    from gb_pin.experiments.bench import format_table, run_benchmark

    rows = run_benchmark(comma_list(args.robots), movements=args.movements, repeat=args.repeat)
    print(format_table(rows))
    return 0
