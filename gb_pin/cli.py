"""Command line: ``gb-pin babble | trials | bench | robots``."""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence

import numpy as np

from gb_pin.exceptions import GbPinError, InvalidArgumentError


def _babble(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from gb_pin.api import babble, resume, warmup
    from gb_pin.checkpoint import read_checkpoint

    if args.resume:
        # The robot and the run's length come from the checkpoint.
        state, info = read_checkpoint(args.resume)
        if info.robot is None:
            raise InvalidArgumentError(
                f"{args.resume}: a run of a custom robot resumes from Python (gb_pin.resume)"
            )
        args.robot, args.movements, args.seed = info.robot, info.movements, info.seed
    bar = None
    done = state.movements if args.resume else 0

    def progress(r: int) -> None:
        # Created on the first report, so that argument errors are not preceded by a bar.
        nonlocal bar, done
        if bar is None:
            bar = tqdm(
                total=args.movements,
                initial=done,
                unit="mv",
                desc=f"babbling {args.robot}",
                disable=args.quiet,
            )
        bar.update(r - done)
        done = r

    from gb_pin.robots import get_preset

    get_preset(args.robot)  # an unknown robot is reported before the kernels compile
    compile_time = warmup()
    start = time.perf_counter()
    try:
        if args.resume:
            result = resume(args.resume, callback=progress, checkpoint_every=args.checkpoint_every)
        else:
            result = babble(
                robot=args.robot,
                movements=args.movements,
                seed=args.seed,
                learning_rate=args.learning_rate,
                sigma=args.sigma,
                sigma_delta=args.sigma_delta,
                radius=args.radius,
                path_length=args.path_length,
                p_home=args.p_home,
                callback=progress,
                checkpoint=args.checkpoint,
                checkpoint_every=args.checkpoint_every,
            )
    finally:
        if bar is not None:
            bar.close()
    wall = time.perf_counter() - start
    h = result.history
    e0 = h.error[0]
    print(f"robot            {args.robot} ({result.target.n_joints} joints, task axes {result.target.axes})")
    print(f"movements        {result.movements} ({result.steps} steps), seed {args.seed}")
    print(f"E^X              {result.error:.5f} m   (E_0 = {e0:.4f} m, {result.error / e0:.1%} of E_0)")
    print(f"D^home           {result.home_distance:.4f} rad")
    print(f"prototypes       {result.n_prototypes}")
    print(
        f"wall time        {wall:.2f} s ({1e6 * result.wall_time / result.steps:.2f} us/step, "
        f"evaluation included; plus {compile_time:.2f} s to compile or load the kernels)"
    )
    if args.out:
        result.save(args.out)
        print(f"saved            {args.out}")
    return 0


def _bench(args: argparse.Namespace) -> int:
    from gb_pin.bench import format_table, run_benchmark

    robots = [r.strip() for r in args.robots.split(",") if r.strip()]
    rows = run_benchmark(robots, movements=args.movements, repeat=args.repeat)
    print(format_table(rows))
    return 0


def _trials(args: argparse.Namespace) -> int:
    from gb_pin.trials import run_trials

    babble_args = {
        k: v
        for k, v in (
            ("learning_rate", args.learning_rate),
            ("sigma", args.sigma),
            ("sigma_delta", args.sigma_delta),
            ("radius", args.radius),
        )
        if v is not None
    }
    start = time.perf_counter()
    result = run_trials(
        robot=args.robot,
        trials=args.trials,
        movements=args.movements,
        seed=args.seed,
        workers=args.workers,
        progress=not args.quiet,
        **babble_args,
    )
    wall = time.perf_counter() - start
    e0 = result.initial_error
    q10, q50, q90 = result.quantiles((0.1, 0.5, 0.9))[:, -1]
    print(f"robot            {args.robot}, {result.trials} trials x {args.movements} movements")
    print(f"E_0              {e0:.4f} m")
    print(f"final E^X        median {q50:.5f} m (10 % {q10:.5f}, 90 % {q90:.5f})")
    print(f"final D^home     median {np.median(result.home_distance[:, -1]):.4f} rad")
    for q in (0.1, 0.25, 0.5, 0.75, 0.9):
        print(f"{f'S({q}, 0.1 E_0)':<17}{result.speed(q, 0.1 * e0)}")
    print(f"wall time        {wall:.2f} s")
    if args.json:
        result.save(args.json)
        print(f"saved            {args.json}")
    return 0


def _robots(args: argparse.Namespace) -> int:
    from gb_pin.robots import robots

    print(f"{'name':<12} {'task axes':<10} {'frame':<8} {'source':<8} {'targets':>7}  description")
    for p in robots():
        print(f"{p.pattern:<12} {p.axes:<10} {p.frame:<8} {p.source:<8} {len(p.targets):>7}  {p.description}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The ``gb-pin`` argument parser."""
    parser = argparse.ArgumentParser(
        prog="gb-pin",
        description="Online Goal Babbling (Rolf, Steil & Gienger 2011) on Pinocchio robots.",
    )
    sub = parser.add_subparsers(dest="command", required=True)

    b = sub.add_parser("babble", help="learn an inverse model by goal babbling")
    b.add_argument(
        "--robot", default="planar20", help="preset name, e.g. planar5, planar20 (default planar20)"
    )
    b.add_argument(
        "--movements",
        type=int,
        default=1000,
        help="movements, home returns included (default 1000)",
    )
    b.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    b.add_argument("--learning-rate", type=float, default=None, help="eta (default 0.1)")
    b.add_argument("--sigma", type=float, default=None, help="exploration noise [rad] (default Eq. 12)")
    b.add_argument(
        "--sigma-delta", type=float, default=None, help="noise random-walk step (default 0.1 sigma)"
    )
    b.add_argument("--radius", type=float, default=None, help="prototype radius d [m] (default 0.1)")
    b.add_argument("--path-length", type=int, default=None, help="steps per movement L (default 25)")
    b.add_argument("--p-home", type=float, default=None, help="home-return probability (default 0.1)")
    b.add_argument("--out", default=None, help="save the result to this .npz file")
    b.add_argument(
        "--checkpoint", default=None, help="write the run's complete state to this file as it goes (atomic)"
    )
    b.add_argument("--checkpoint-every", type=int, default=None, help="movements between checkpoints")
    b.add_argument(
        "--resume",
        default=None,
        help="continue the run of this checkpoint (bit-identical to an uninterrupted run)",
    )
    b.add_argument("--quiet", action="store_true", help="no progress bar")
    b.set_defaults(func=_babble)

    s = sub.add_parser("bench", help="microseconds per babbling step")
    s.add_argument("--robots", default="planar5,planar20,planar50", help="comma-separated presets")
    s.add_argument("--movements", type=int, default=2000, help="movements per run (default 2000)")
    s.add_argument("--repeat", type=int, default=3, help="runs per robot, best is reported (default 3)")
    s.set_defaults(func=_bench)

    t = sub.add_parser("trials", help="independent trials in parallel, with S(Q, e) and quantiles")
    t.add_argument("--robot", default="planar5", help="preset name (default planar5)")
    t.add_argument("--trials", type=int, default=100, help="number of trials (default 100)")
    t.add_argument("--movements", type=int, default=300, help="movements per trial (default 300)")
    t.add_argument("--seed", type=int, default=0, help="seed of trial 0; trial i uses seed + i")
    t.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    t.add_argument("--learning-rate", type=float, default=None, help="eta (default 0.1)")
    t.add_argument("--sigma", type=float, default=None, help="exploration noise [rad] (default Eq. 12)")
    t.add_argument("--sigma-delta", type=float, default=None, help="noise random-walk step")
    t.add_argument("--radius", type=float, default=None, help="prototype radius d [m]")
    t.add_argument("--json", default=None, help="write movements, error, home_distance, initial_error")
    t.add_argument("--quiet", action="store_true", help="no progress bar")
    t.set_defaults(func=_trials)

    r = sub.add_parser("robots", help="list the robot presets")
    r.set_defaults(func=_robots)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``gb-pin``: user mistakes print one line and exit with status 2."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except GbPinError as exc:
        print(f"gb-pin: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        print(f"gb-pin: {exc or 'interrupted'}", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
