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
    add_model_options(s, task=False)  # --task is the IK protocol's
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
    p = s.add_argument_group("the IK protocol (--ik --protocol trac-ik)")
    p.add_argument(
        "--protocol", choices=("trac-ik",), default=None,
        help="TRAC-IK's protocol: FK-sampled targets, 1e-5 m / rad, 5 ms, time per solve; TRAC-IK beside "
        "gb_pin when pytracik is installed (pip install 'gb_pin[bench]')",
    )  # fmt: skip
    p.add_argument("--robot", default="panda", help="panda, ur5, kinova or so101 (default panda)")
    p.add_argument("--task", default="pose", help="pose, position or pointing (default pose)")
    p.add_argument("--samples", type=int, default=10_000, help="targets (default 10000)")
    p.add_argument("--timeout", type=float, default=5e-3, help="seconds per target (default 0.005)")
    p.add_argument("--paths", type=int, default=100, help="Cartesian paths (default 100; 0: none)")
    p.add_argument("--seed", type=int, default=0, help="random seed of the postures (default 0)")
    p.add_argument(
        "--clock", choices=("cpu", "wall"), default="cpu",
        help="time queries (and gb_pin's budget) by the thread's CPU time (default) or wall time",
    )  # fmt: skip
    s.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Time the runs and print the table (or, with --ik, run the IK benchmark)."""
    if args.protocol is not None:
        return _protocol(args)
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


def _protocol(args: argparse.Namespace) -> int:
    """--ik --protocol trac-ik: the field's protocol on one arm and task; the table, optionally the doc."""
    import sys

    import gb_pin.cli.checks as checks
    from gb_pin import _validation as check
    from gb_pin.exceptions import InvalidArgumentError
    from gb_pin.experiments.ik_protocol import (
        BEGIN,
        END,
        check_samples,
        format_report,
        protocol_target,
        run_protocol,
    )
    from gb_pin.experiments.robot_bench import update_document

    if not args.ik:
        raise InvalidArgumentError("--protocol goes with --ik (gb-pin bench --ik --protocol trac-ik)")
    check.positive_int("--samples", args.samples, maximum=10**7)
    check.positive_int("--paths", args.paths, minimum=0, maximum=10**5)
    check.positive_float("--timeout", args.timeout)
    check.generator(args.seed)
    movements = 3000 if args.movements is None else args.movements
    check.movements("--movements", movements, minimum=1)
    # a bad robot or task, or more samples than fit, fails before anything runs
    check_samples(protocol_target(args.robot, args.task), args.samples)
    checks.outputs(args, doc="--doc")
    report = run_protocol(
        args.robot, args.task, args.samples, timeout=args.timeout, movements=movements, paths=args.paths,
        seed=args.seed, clock=args.clock, progress=lambda line: print(line, file=sys.stderr),
    )  # fmt: skip
    text = format_report(report)
    print(text)
    if args.doc is not None:
        update_document(
            args.doc, text, begin=BEGIN.format(args.robot, args.task), end=END.format(args.robot, args.task)
        )
    return 0
