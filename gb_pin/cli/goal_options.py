"""The goal options of ``babble`` and ``trials``: who chooses the goals, the goal and test sets.

``--goals NAME[:key=value,...]`` picks a goal generator (:mod:`gb_pin.learn.goals`);
``--targets FILE`` and ``--eval-targets FILE`` read point sets from ``.csv`` (one point per
row) or ``.npy`` files (:func:`gb_pin._points.read_points`, in bounds); ``--until-error E`` stops a
run once E^X <= E.
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from gb_pin._points import read_points
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.robot.workspace import WorkspaceRegion, is_workspace_spec


def add_goal_options(parser: argparse.ArgumentParser, *, until: bool = True) -> None:
    """--goals, --targets, --eval-targets (and --until-error if ``until``)."""
    parser.add_argument(
        "--goals",
        default=None,
        help="goal generator: uniform (the paper's, default), directions (no goal set needed), error, "
        "progress, motor (motor babbling), cyclic; parameters as NAME:key=value,... "
        "(e.g. uniform:snap=0.05); docs/GOALS.md",
    )
    parser.add_argument(
        "--targets",
        default=None,
        help="goal set X*: a .csv (one point per row) or .npy file; or a region of the arm's reach, "
        "workspace:fraction=0.5 (goals and test points from half of every joint's range; docs/WORKSPACE.md)",
    )
    parser.add_argument(
        "--eval-targets",
        default=None,
        help="test set where E^X is measured (.csv or .npy); default the goal set",
    )
    if until:
        parser.add_argument(
            "--until-error",
            type=float,
            default=None,
            help="stop once E^X on the test set is at most this [m]",
        )


def goal_values(args: argparse.Namespace, *, as_lists: bool = False) -> dict[str, Any]:
    """The goal options given, as babble() arguments (point sets as lists with ``as_lists``).

    Raises:
        InvalidArgumentError: an unknown generator, bad parameters, an unreadable or malformed file.
    """
    out: dict[str, Any] = {}
    if args.goals is not None:
        from gb_pin.learn.goals import make_goals

        make_goals(args.goals)  # checked here, before any work
        out["goals"] = args.goals
    for option, key in (("--targets", "targets"), ("--eval-targets", "eval_targets")):
        path = getattr(args, key)
        if key == "targets" and is_workspace_spec(path):
            WorkspaceRegion.parse(path)  # checked here, before any work
            out[key] = path
        elif path is not None:
            points = read_points(path, option)
            out[key] = points.tolist() if as_lists else points
    until = getattr(args, "until_error", None)
    if until is not None:
        if not (np.isfinite(until) and until > 0):
            raise InvalidArgumentError(f"--until-error must be a level > 0 [m], got {until!r}")
        out["until_error"] = until
    return out


def check_widths(args: argparse.Namespace, goal_args: dict[str, Any], robot: Any) -> None:
    """Raise unless the points of ``--targets`` / ``--eval-targets`` have the robot's task dimension.

    Checked here, where the file and option are known (the run itself would only say "targets").

    Raises:
        InvalidArgumentError: naming the option, the file, its column count and the robot's.
    """
    given = [
        (o, k) for o, k in (("--targets", "targets"), ("--eval-targets", "eval_targets")) if k in goal_args
    ]
    if not given or robot is None:
        return
    n_task = getattr(robot, "n_task", None)
    if n_task is None and isinstance(robot, str):
        from gb_pin.exceptions import GbPinError
        from gb_pin.robot.presets import load_robot

        try:
            n_task = load_robot(robot).n_task
        except GbPinError:  # not a preset's name (a plant's spec): the run checks it
            return
    if n_task is None:
        return
    for option, key in given:
        if isinstance(goal_args[key], str):  # a workspace region: built on the robot itself
            continue
        width = np.asarray(goal_args[key]).shape[1]
        if width != n_task:
            axes = getattr(robot, "axes", None)
            what = f"task axes {axes}" if isinstance(axes, str) and len(axes) == n_task else "task vector"
            raise InvalidArgumentError(
                f"{option} {getattr(args, key)}: points of {width} coordinates a line; the robot's {what} "
                f"has {n_task}"
            )
