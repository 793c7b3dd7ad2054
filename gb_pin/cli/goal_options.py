"""The goal options of ``babble`` and ``trials``: who chooses the goals, the goal and test sets.

``--goals NAME[:key=value,...]`` picks a goal generator (:mod:`gb_pin.learn.goals`);
``--targets FILE`` and ``--eval-targets FILE`` read point sets from ``.csv`` (one point per
row) or ``.npy`` files; ``--until-error E`` stops a run once E^X <= E.
"""

from __future__ import annotations

import argparse
import os
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import InvalidArgumentError

MAX_POINTS = 10**6  # the largest point set a file may hold
MAX_FILE_BYTES = 256 * 2**20


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
        "--targets", default=None, help="goal set X*: a .csv (one point per row) or .npy file"
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
        if path is not None:
            points = read_points(path, option)
            out[key] = points.tolist() if as_lists else points
    until = getattr(args, "until_error", None)
    if until is not None:
        if not (np.isfinite(until) and until > 0):
            raise InvalidArgumentError(f"--until-error must be a level > 0 [m], got {until!r}")
        out["until_error"] = until
    return out


def read_points(path: str | os.PathLike[str], what: str = "points") -> NDArray[np.float64]:
    """An (N, n) point set from a ``.csv`` (comma-separated, ``#`` comments) or ``.npy`` file.

    Raises:
        InvalidArgumentError: missing, too large, not numeric, not 2-D or not finite.
    """
    name = os.fspath(path)
    try:
        size = os.path.getsize(name)
    except OSError as exc:
        raise InvalidArgumentError(f"{what} {name!r}: cannot read it ({exc.strerror})") from exc
    if size > MAX_FILE_BYTES:
        raise InvalidArgumentError(f"{what} {name!r}: {size} bytes, at most {MAX_FILE_BYTES} accepted")
    try:
        if name.lower().endswith(".npy"):
            arr = np.load(name, allow_pickle=False)
        elif name.lower().endswith((".csv", ".txt")):
            arr = np.loadtxt(name, delimiter=",", ndmin=2, dtype=np.float64)
        else:
            raise InvalidArgumentError(f"{what} {name!r}: expected a .csv or .npy file")
    except InvalidArgumentError:
        raise
    except (OSError, ValueError, EOFError) as exc:
        raise InvalidArgumentError(
            f"{what} {name!r}: not a numeric point set ({type(exc).__name__})"
        ) from exc
    if arr.dtype.kind not in "fiu" or arr.ndim != 2 or not 0 < arr.shape[0] <= MAX_POINTS or arr.shape[1] < 1:
        raise InvalidArgumentError(
            f"{what} {name!r}: expected (N, n) numbers with 1 <= N <= {MAX_POINTS}, "
            f"got {arr.dtype} {arr.shape}"
        )
    out = np.ascontiguousarray(arr, dtype=np.float64)
    if not np.all(np.isfinite(out)):
        raise InvalidArgumentError(f"{what} {name!r}: holds NaN or infinite values")
    return out
