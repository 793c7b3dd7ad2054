"""``gb-pin replay`` and ``gb-pin show``: a saved result in the browser, live or as one offline HTML file."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from gb_pin.cli.options import add_html, add_model_options, add_overwrite, add_port, result_robot

if TYPE_CHECKING:
    from gb_pin.cli.options import Subparsers
    from gb_pin.viewer import Viewer


def add_replay_and_show(sub: Subparsers) -> None:
    """Register ``replay`` and ``show``."""
    sub.add_parser(
        "replay",
        help="replay a recorded run in the browser, or as one offline HTML file",
        configure=_add_replay_options,
    )
    sub.add_parser(
        "show",
        help="draw a saved model: target grid, reached grid f(g(x*)), postures",
        configure=_add_show_options,
    )


def _add_replay_options(v: argparse.ArgumentParser) -> None:
    """``replay``'s file and options."""
    v.add_argument("file", help="a result file with recorded steps (gb-pin babble --record-every ...)")
    add_html(v)
    add_overwrite(v, "--html")
    v.add_argument("--movements", default=None, help="replay movements FIRST:LAST only, e.g. 0:50")
    v.add_argument("--speed", type=float, default=2.0, help="movements per second (default 2)")
    add_port(v)
    add_model_options(v, robot=True)
    v.set_defaults(func=replay)


def _add_show_options(w: argparse.ArgumentParser) -> None:
    """``show``'s file and options."""
    w.add_argument("file", help="a result file (gb-pin babble --out ...)")
    add_html(w)
    add_overwrite(w, "--html")
    w.add_argument("--postures", type=int, default=5, help="postures g(x*) drawn (default 5)")
    add_port(w)
    add_model_options(w, robot=True)
    w.set_defaults(func=show)


def replay(args: argparse.Namespace) -> int:
    """Replay the recorded steps of a result: export --html, or serve until Ctrl-C."""
    import gb_pin.cli.checks as checks
    from gb_pin import load_result
    from gb_pin.viewer import export_replay, live_replay, parse_range

    checks.finite("--speed", args.speed, strict=True)
    checks.fresh_outputs(args, html="--html")
    result = load_result(args.file, target=result_robot(args))  # None: the robot the file records
    movements = parse_range(args.movements) if args.movements else None
    if args.html:
        export_replay(result, args.html, movements, args.speed)
        _wrote(args.html)
        return 0
    _serve(live_replay(result, movements, args.speed, args.port))
    return 0


def show(args: argparse.Namespace) -> int:
    """Draw a result's learned model: export --html, or serve until Ctrl-C."""
    import gb_pin.cli.checks as checks
    from gb_pin import _validation as check
    from gb_pin import load_result
    from gb_pin.viewer import export_model, live_model

    check.positive_int("--postures", args.postures, minimum=0)
    checks.fresh_outputs(args, html="--html")
    result = load_result(args.file, target=result_robot(args))  # None: the robot the file records
    if args.html:
        export_model(result, args.html, few=args.postures)
        _wrote(args.html)
        return 0
    _serve(live_model(result, args.port, few=args.postures))
    return 0


def _wrote(path: str) -> None:
    print(f"wrote            {path} (self-contained; opens offline in any browser)")


def _serve(viewer: Viewer) -> None:
    """Say where the viewer is and serve it until Ctrl-C."""
    from gb_pin.viewer import serve_until_interrupted

    print(f"viewer           {viewer.url}  (served on 127.0.0.1 only; Ctrl-C to quit)", flush=True)
    serve_until_interrupted(viewer)
