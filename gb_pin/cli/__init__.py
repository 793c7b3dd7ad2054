"""Command line: ``gb-pin babble | trials | bench | robots``."""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from gb_pin.exceptions import GbPinError, InvalidArgumentError

if TYPE_CHECKING:
    from gb_pin.learn.history import Recording
    from gb_pin.viewer import Viewer


def _babble(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from gb_pin.runs.api import babble, resume, warmup
    from gb_pin.runs.checkpoint import read_checkpoint

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

    from gb_pin.robot.presets import get_preset

    get_preset(args.robot)  # an unknown robot is reported before the kernels compile
    record = _recording(args)
    compile_time = warmup()
    viewer = _start_viewer(args)
    # At full speed the viewer shows at most 30 frames/s anyway: observing every 10th movement
    # keeps the core's per-chunk cost small; with --view-pace every movement is shown.
    observe_every = 1 if args.view_pace is not None else 10
    start = time.perf_counter()
    try:
        if args.resume:
            result = resume(
                args.resume,
                callback=progress,
                checkpoint_every=args.checkpoint_every,
                viewer=viewer,
                observe_every=observe_every,
            )
        else:
            result = babble(
                robot=args.robot,
                movements=args.movements,
                seed=args.seed,
                callback=progress,
                checkpoint=args.checkpoint,
                checkpoint_every=args.checkpoint_every,
                record=record,
                viewer=viewer,
                observe_every=observe_every,
                **{k: getattr(args, k) for k in _LEARNER_OPTIONS},
            )
    finally:
        if bar is not None:
            bar.close()
        if viewer is not None:
            viewer.finish()  # the last state and the learned model; browsers keep showing them
            viewer.close()
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


def _recording(args: argparse.Namespace) -> Recording | None:
    """The Recording asked for by --record-every / --record-movements, or None."""
    if args.record_every is None and args.record_movements is None:
        return None
    from gb_pin.learn.history import Recording
    from gb_pin.viewer import parse_range

    first, last = parse_range(args.record_movements or "0:", "--record-movements")
    return Recording(every=1 if args.record_every is None else args.record_every, first=first, last=last)


def _start_viewer(args: argparse.Namespace) -> Viewer | None:
    """--view: a live viewer on 127.0.0.1 (or a warning and None); waits for a browser to connect."""
    if not args.view:
        return None
    import warnings

    from gb_pin.viewer import ViewerWarning, open_viewer

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ViewerWarning)
        viewer = open_viewer(args.view_port, pace=args.view_pace)
    for w in caught:
        print(f"gb-pin: warning: {w.message}", file=sys.stderr)
    if viewer is None:
        return None
    print(f"viewer           {viewer.url}  (open it in a browser; served on 127.0.0.1 only)", flush=True)
    if args.view_pace is None:
        print("                 (full speed; --view-pace 30 shows every movement, 30 per second)", flush=True)
    if args.view_wait > 0 and not viewer.wait_for_browser(args.view_wait):
        print(f"                 no browser within {args.view_wait:g} s: babbling anyway", flush=True)
    return viewer


def _replay(args: argparse.Namespace) -> int:
    from gb_pin import load_result
    from gb_pin.viewer import export_replay, live_replay, parse_range, serve_until_interrupted

    result = load_result(args.file)
    movements = parse_range(args.movements) if args.movements else None
    if args.html:
        export_replay(result, args.html, movements, args.speed)
        print(f"wrote            {args.html} (self-contained; opens offline in any browser)")
        return 0
    viewer = live_replay(result, movements, args.speed, args.port)
    print(f"viewer           {viewer.url}  (served on 127.0.0.1 only; Ctrl-C to quit)", flush=True)
    serve_until_interrupted(viewer)
    return 0


def _show(args: argparse.Namespace) -> int:
    from gb_pin import load_result
    from gb_pin.viewer import export_model, live_model, serve_until_interrupted

    result = load_result(args.file)
    if args.html:
        export_model(result, args.html, few=args.postures)
        print(f"wrote            {args.html} (self-contained; opens offline in any browser)")
        return 0
    viewer = live_model(result, args.port, few=args.postures)
    print(f"viewer           {viewer.url}  (served on 127.0.0.1 only; Ctrl-C to quit)", flush=True)
    serve_until_interrupted(viewer)
    return 0


def _bench(args: argparse.Namespace) -> int:
    from gb_pin.experiments.bench import format_table, run_benchmark

    robots = [r.strip() for r in args.robots.split(",") if r.strip()]
    rows = run_benchmark(robots, movements=args.movements, repeat=args.repeat)
    print(format_table(rows))
    return 0


def _trials(args: argparse.Namespace) -> int:
    from gb_pin.experiments.trials import run_trials

    babble_args = {k: getattr(args, k) for k in _LEARNER_OPTIONS if getattr(args, k) is not None}
    start = time.perf_counter()
    result = run_trials(
        robot=args.robot,
        trials=args.trials,
        movements=args.movements,
        seed=args.seed,
        workers=args.workers,
        progress=not args.quiet,
        scheduler=args.scheduler,
        checkpoint=args.checkpoint,
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


def _reproduce(args: argparse.Namespace) -> int:
    from gb_pin.reproduce import reproduce

    result = reproduce(
        args.figures,
        out=args.out,
        trials=args.trials,
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


def _robots(args: argparse.Namespace) -> int:
    if args.benchmark:
        from gb_pin.experiments.robot_bench import run

        names = [r.strip() for r in args.robots.split(",") if r.strip()] if args.robots else None
        run(
            names,
            trials=args.trials,
            movements=args.movements,
            seed=args.seed,
            workers=args.workers,
            progress=not args.quiet,
            doc=args.doc,
            figure=args.figure,
            json_path=args.json,
            command="gb-pin robots --benchmark" + (f" --trials {args.trials}" if args.trials != 10 else ""),
        )
        return 0
    from gb_pin.robot.presets import format_presets

    print(format_presets())
    return 0


_LEARNER_OPTIONS = {
    "learning_rate": (float, "eta (default 0.1, or the preset's)"),
    "sigma": (float, "exploration noise [rad] (default Eq. 12, or the preset's)"),
    "sigma_delta": (float, "noise random-walk step [rad] (default 0.1 sigma)"),
    "radius": (float, "prototype radius d [m] (default 0.1, or the preset's)"),
    "path_length": (int, "steps per movement L (default 25)"),
    "p_home": (float, "home-return probability (default 0.1)"),
}


def _add_learner_options(parser: argparse.ArgumentParser) -> None:
    """The learner's hyperparameters as options (None: the robot preset's or the paper's default)."""
    for name, (kind, text) in _LEARNER_OPTIONS.items():
        parser.add_argument("--" + name.replace("_", "-"), type=kind, default=None, help=text)


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
    _add_learner_options(b)
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
    b.add_argument(
        "--record-every", type=int, default=None, help="record every K-th step into the result (for replay)"
    )
    b.add_argument(
        "--record-movements", default=None, help="record movements FIRST:LAST only, e.g. 0:50 (default all)"
    )
    b.add_argument("--view", action="store_true", help="watch it live in a browser (meshcat, 127.0.0.1)")
    b.add_argument("--view-port", type=int, default=None, help="viewer port (default: first free from 7000)")
    b.add_argument(
        "--view-pace", type=float, default=None, help="slow motion: at most this many movements per second"
    )
    b.add_argument(
        "--view-wait", type=float, default=60.0, help="seconds to wait for a browser to connect (default 60)"
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
    _add_learner_options(t)
    t.add_argument(
        "--scheduler",
        default=None,
        help="run the trials on this Dask scheduler, e.g. tcp://host:8786 (needs gb_pin[cluster])",
    )
    t.add_argument("--json", default=None, help="write movements, error, home_distance, initial_error")
    t.add_argument(
        "--checkpoint",
        default=None,
        help="trial journal: finished trials are appended to it and not recomputed when the command is rerun",
    )
    t.add_argument("--quiet", action="store_true", help="no progress bar")
    t.set_defaults(func=_trials)

    p = sub.add_parser("reproduce", help="the paper's figures 3-8, their numbers and results.md")
    p.add_argument(
        "figures", nargs="+", metavar="FIGURE", help="fig3, fig4, fig5, fig6, fig7, fig8, throughput or all"
    )
    p.add_argument("--out", default="reproduction", help="output folder (default ./reproduction)")
    p.add_argument("--trials", type=int, default=100, help="trials per condition (default 100, the paper's)")
    p.add_argument(
        "--movements",
        type=int,
        default=10_000,
        help="movements per trial; final errors are read there (default 10000; the paper: 1e6-1e7)",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of trial 0; trial i uses seed + i")
    p.add_argument("--workers", type=int, default=None, help="local processes (default: all cores)")
    p.add_argument(
        "--scheduler", default=None, help="run the trials on this Dask scheduler (tcp://host:8786)"
    )
    p.add_argument("--fresh", action="store_true", help="ignore the cached trials in OUT/trials")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_reproduce)

    v = sub.add_parser("replay", help="replay a recorded run in the browser, or as one offline HTML file")
    v.add_argument("file", help="a result file with recorded steps (gb-pin babble --record-every ...)")
    v.add_argument("--html", default=None, help="write one self-contained HTML file instead of serving")
    v.add_argument("--movements", default=None, help="replay movements FIRST:LAST only, e.g. 0:50")
    v.add_argument("--speed", type=float, default=2.0, help="movements per second (default 2)")
    v.add_argument("--port", type=int, default=None, help="viewer port (default: first free from 7000)")
    v.set_defaults(func=_replay)

    w = sub.add_parser("show", help="draw a saved model: target grid, reached grid f(g(x*)), postures")
    w.add_argument("file", help="a result file (gb-pin babble --out ...)")
    w.add_argument("--html", default=None, help="write one self-contained HTML file instead of serving")
    w.add_argument("--postures", type=int, default=5, help="postures g(x*) drawn (default 5)")
    w.add_argument("--port", type=int, default=None, help="viewer port (default: first free from 7000)")
    w.set_defaults(func=_show)

    r = sub.add_parser("robots", help="list the robot presets (--benchmark: the table of docs/ROBOTS.md)")
    r.add_argument("--benchmark", action="store_true", help="run trials on every preset and print the table")
    r.add_argument("--robots", default=None, help="comma-separated presets (default: all, planar5, planar20)")
    r.add_argument("--trials", type=int, default=10, help="trials per preset (default 10)")
    r.add_argument("--movements", type=int, default=10000, help="movements per trial (default 10000)")
    r.add_argument("--seed", type=int, default=0, help="seed of trial 0; trial i uses seed + i")
    r.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    r.add_argument("--doc", default=None, help="update the table in this markdown file (docs/ROBOTS.md)")
    r.add_argument("--figure", default=None, help="write the learning curves to this PNG (matplotlib)")
    r.add_argument("--json", default=None, help="write the results and every trial's curve to this file")
    r.add_argument("--quiet", action="store_true", help="no progress output")
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
    except BrokenPipeError:
        # Output piped into e.g. `head`: stop quietly, as Unix tools do.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except KeyboardInterrupt as exc:
        print(f"gb-pin: {exc or 'interrupted'}", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
