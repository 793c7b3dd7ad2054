"""``gb-pin ik``: exact postures for targets, from a saved run's learned inverse refined on the robot."""

from __future__ import annotations

import argparse
import json
import sys
from typing import TYPE_CHECKING, Any

from gb_pin.cli.options import add_model_options, result_robot

if TYPE_CHECKING:
    from collections.abc import Iterator

    import numpy as np
    from numpy.typing import ArrayLike, NDArray

    from gb_pin.cli.options import Subparsers
    from gb_pin.ik.solution import IKSolution

EXAMPLES = """examples:
  gb-pin babble --robot talos_left_arm --movements 3000 --out run.npz
  gb-pin ik run.npz 0.45 0.3 1.1
  gb-pin ik run.npz --targets points.csv --json
  gb-pin ik pose.npz --pose 0.45 0.3 1.1 0 0 0 1    # a pose task's run: position and quaternion x y z w

points.csv: one target per line, comma-separated coordinates on the run's task axes [m];
blank lines, lines starting with # and a header naming the axes (x,y,z) are skipped.
The exit status is 1 when a target is not reached to --tol."""


def add_ik(sub: Subparsers) -> None:
    """Register ``ik``."""
    sub.add_parser(
        "ik",
        help="postures reaching targets: the learned inverse of a saved run, refined (docs/IK.md)",
        description="Postures reaching targets: the saved run's learned estimate g(x*), refined by "
        "damped least squares on the robot's kinematics within its joint limits.",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
        configure=_add_options,
    )


def _add_options(s: argparse.ArgumentParser) -> None:
    """``ik``'s arguments."""
    s.add_argument("run", help="a result file written by `gb-pin babble ... --out run.npz`")
    s.add_argument("coordinates", nargs="*", help="one target's coordinates on the task axes [m]")
    s.add_argument("--targets", default=None, help="a CSV file of targets, one per line [m]")
    s.add_argument(
        "--seed",
        choices=("learned", "nearest", "home", "middle"),
        default="learned",
        help="start (default learned)",
    )
    s.add_argument("--tol", type=float, default=1e-4, help="position tolerance [m] (default 1e-4)")
    s.add_argument(
        "--angle-tol", type=float, default=1e-4, help="orientation / pointing tolerance [rad] (default 1e-4)"
    )
    s.add_argument("--max-iterations", type=int, default=100, help="steps from one seed (default 100)")
    s.add_argument(
        "--timeout", type=float, default=None,
        help="seconds per target: restart from random postures until solved (default: one attempt)",
    )  # fmt: skip
    s.add_argument("--json", action="store_true", help="print the solutions as JSON")
    s.add_argument(
        "--pose",
        nargs=7,
        default=None,
        metavar=("X", "Y", "Z", "QX", "QY", "QZ", "QW"),
        help="a target hand pose: position [m] and unit quaternion, turned into the run's task vector "
        "(gb_pin.ik.pose_target; --quaternion-order wxyz for QW QX QY QZ)",
    )
    s.add_argument(
        "--quaternion-order", choices=("xyzw", "wxyz"), default="xyzw", help="with --pose (default xyzw)"
    )
    add_model_options(s, robot=True)
    s.set_defaults(func=run)


def read_targets_csv(path: str, axes: str | int) -> NDArray[np.float64]:
    """The targets of a file: one per line, ``len(axes)`` (or ``axes``) comma-separated numbers [m]; or .npy.

    Read in bounds by the point-file reader of babble's ``--targets`` (:func:`gb_pin._points.read_points`).

    Raises:
        InvalidArgumentError: the file cannot be read, is too large, or a line is malformed.
    """
    from gb_pin._points import read_points
    from gb_pin.exceptions import InvalidArgumentError

    points = read_points(path, "--targets", axes=axes if isinstance(axes, str) else None)
    if isinstance(axes, int) and points.shape[1] != axes:  # a task vector without axis names
        raise InvalidArgumentError(
            f"--targets {path!r}: expected {axes} numbers per line (the task vector), got {points.shape[1]}"
        )
    return points


def _targets(args: argparse.Namespace, axes: str | int, name: str) -> ArrayLike:
    from gb_pin._points import finite_number
    from gb_pin.exceptions import InvalidArgumentError

    if args.targets is not None and args.coordinates:
        raise InvalidArgumentError("give the coordinates of one target or --targets FILE, not both")
    if args.targets is not None:
        return read_targets_csv(args.targets, axes)
    count = axes if isinstance(axes, int) else len(axes)
    if len(args.coordinates) != count:
        what = f"task vector of {name}" if isinstance(axes, int) else f"axes {axes!r} of {name}"
        raise InvalidArgumentError(
            f"expected {count} coordinates ({what}), got {len(args.coordinates)}: "
            f"{' '.join(args.coordinates) or 'none'} (or give --targets FILE)"
        )
    return [[finite_number(c, "coordinate") for c in args.coordinates]]


def _pose_target(args: argparse.Namespace, target: Any) -> ArrayLike:
    """--pose X Y Z QX QY QZ QW: the run's task vector of that hand pose (one target)."""
    from gb_pin._points import finite_number
    from gb_pin.exceptions import InvalidArgumentError
    from gb_pin.ik.pose import pose_target

    if args.targets is not None or args.coordinates:
        raise InvalidArgumentError(
            "give --pose, the coordinates of one target or --targets FILE: one of them"
        )
    values = [finite_number(c, "--pose") for c in args.pose]
    return [pose_target(target, values[:3], values[3:], order=args.quaternion_order)]


def _as_json(sol: IKSolution, robot: str, joints: tuple[str, ...], axes: str) -> str:
    head = {"robot": robot, "axes": axes, "joints": list(joints), "tol": sol.tol, "seed": sol.seed}
    return json.dumps({**head, "solutions": sol.records()}, indent=1)


def _as_text(sol: IKSolution, joints: tuple[str, ...]) -> Iterator[str]:
    """The solutions as lines of text (one per target, then the summary), made one at a time."""
    from gb_pin._names import listing

    yield "joints: " + listing(joints, " ")  # names from a URDF: printable
    for r in range(len(sol)):
        target = " ".join(f"{v:.4f}" for v in sol.targets[r])
        posture = " ".join(f"{v:+.4f}" for v in sol.postures[r])
        status = "ok" if sol.success[r] else "NOT REACHED"
        yield (
            f"[{target}] -> q [{posture}]  residual {sol.residuals[r]:.2e} m, "
            f"{int(sol.iterations[r])} iterations, {status}"
        )
    yield sol.summary()


def run(args: argparse.Namespace) -> int:
    """Load the run, solve the targets, print them; 1 when a target is not reached."""
    from gb_pin.runs.result import load_result

    result = load_result(args.run, target=result_robot(args))  # None: the robot the file records
    target = result.target
    if getattr(target, "chain", None) is None:  # a robot given as a function: no Jacobian to refine on
        from gb_pin.exceptions import InvalidArgumentError

        raise InvalidArgumentError(
            f"{args.run}: gb-pin ik refines on the robot's kinematic chain, which {target.name!r} (a robot "
            "given as a function) has none of; its learned postures are result.inverse(X) in Python"
        )
    if args.pose is not None:
        X = _pose_target(args, target)
    else:
        X = _targets(args, target.axes if len(target.axes) == target.n_task else target.n_task, target.name)
    sol = result.solve(
        X, tol=args.tol, max_iterations=args.max_iterations, seed=args.seed, angle_tol=args.angle_tol,
        timeout=args.timeout,
    )  # fmt: skip
    if args.json:
        print(_as_json(sol, target.name, target.joints, target.axes))
    else:
        for line in _as_text(sol, target.joints):  # line by line: 10^6 targets print in bounded memory
            print(line)
    if not sol.success.all():
        print(f"gb-pin: {int((~sol.success).sum())} target(s) not reached to {sol.tol:g} m", file=sys.stderr)
        return 1
    return 0
