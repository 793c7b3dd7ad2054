"""``gb-pin plot``: the learning curves (E^X, D^home over movements) of a result file or of trials."""

from __future__ import annotations

import argparse
import os
from typing import TYPE_CHECKING

from gb_pin.cli.options import add_model_options, add_overwrite, result_robot

if TYPE_CHECKING:
    from gb_pin.cli.options import Subparsers


def add_plot(sub: Subparsers) -> None:
    """Register ``plot``."""
    sub.add_parser(
        "plot",
        help="draw E^X and D^home over movements of a run (.npz) or of trials (.json)",
        description=(
            "Draw the learning curves in the paper's style (log axes): one run's E^X and D^home, "
            "or the median and quartiles of trials written by `gb-pin trials --json`. Needs "
            "matplotlib: pip install 'gb_pin[plots]'."
        ),
        configure=_add_options,
    )


def _add_options(p: argparse.ArgumentParser) -> None:
    """``plot``'s options."""
    p.add_argument("file", help="a result file (gb-pin babble --out run.npz) or trials (trials.json)")
    p.add_argument(
        "-o", "--out", default=None, help="the figure (.png, .svg or .pdf; default: FILE with .png)"
    )
    add_overwrite(p, "--out")
    add_model_options(p, robot=True)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Draw the figure and print where it went."""
    out = args.out or os.path.splitext(args.file)[0] + ".png"
    if os.path.abspath(out) == os.path.abspath(args.file):
        from gb_pin.exceptions import InvalidArgumentError

        raise InvalidArgumentError(f"--out {out!r} would overwrite the input file")
    from gb_pin.cli.checks import no_clobber

    no_clobber(out, "--out", args.overwrite)  # FILE.png by default: a second plot asks for --overwrite
    if args.file.lower().endswith(".json"):
        from gb_pin.experiments.trialset import TrialSet

        TrialSet.load(args.file).plot(out)
    elif args.robot is not None or args.frame is not None:  # a robot given: the result is checked with it
        from gb_pin.runs.result import BabbleResult

        BabbleResult.load(args.file, target=result_robot(args)).plot(out)
    else:  # curves need no robot: a run of any robot plots, whether or not the file can rebuild it
        from gb_pin.runs.plot import plot_history
        from gb_pin.runs.results_file import read_curves

        plot_history(*read_curves(args.file), path=out)
    print(f"wrote {out}")
    return 0
