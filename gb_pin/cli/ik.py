"""``gb-pin ik``: exact postures for targets, from a saved run's learned inverse refined on the robot."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import TYPE_CHECKING

from gb_pin.cli.options import add_model_options, result_robot

if TYPE_CHECKING:
    from gb_pin.cli.options import Subparsers
    from gb_pin.ik.solution import IKSolution

EXAMPLES = """examples:
  gb-pin babble --robot talos_left_arm --movements 3000 --out run.npz
  gb-pin ik run.npz 0.45 0.3 1.1
  gb-pin ik run.npz --targets points.csv --json

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
    add_model_options(s, robot=True)
    s.set_defaults(func=run)


def _number(text: str, where: str) -> float:
    from gb_pin.exceptions import InvalidArgumentError

    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InvalidArgumentError(f"{where}: {text.strip()!r} is not a finite number")
    return value


def read_targets_csv(path: str, axes: str | int) -> list[list[float]]:
    """The targets of a CSV file: one per line, ``len(axes)`` (or ``axes``) comma-separated numbers.

    Raises:
        InvalidArgumentError: the file cannot be read, or a line is malformed.
    """
    from gb_pin.exceptions import InvalidArgumentError

    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise InvalidArgumentError(f"--targets: cannot read {path!r} ({exc})") from exc
    if isinstance(axes, int):  # a task vector without axis names: n numbers per line
        axes = "?" * axes
    rows: list[list[float]] = []
    for number, line in enumerate(lines, start=1):
        fields = [f.strip() for f in line.split(",")]
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        if not rows and [f.lower() for f in fields] == list(axes):
            continue  # a header naming the axes
        if len(fields) != len(axes):
            raise InvalidArgumentError(
                f"{path}:{number}: expected {len(axes)} comma-separated coordinates (axes {axes!r}), "
                f"got {line.strip()!r}"
            )
        rows.append([_number(f, f"{path}:{number}") for f in fields])
    if not rows:
        raise InvalidArgumentError(f"{path}: no targets (one per line, {len(axes)} coordinates)")
    return rows


def _targets(args: argparse.Namespace, axes: str | int, name: str) -> list[list[float]]:
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
    return [[_number(c, "coordinate") for c in args.coordinates]]


def _as_json(sol: IKSolution, robot: str, joints: tuple[str, ...], axes: str) -> str:
    head = {"robot": robot, "axes": axes, "joints": list(joints), "tol": sol.tol, "seed": sol.seed}
    return json.dumps({**head, "solutions": sol.records()}, indent=1)


def _as_text(sol: IKSolution, joints: tuple[str, ...]) -> str:
    lines = ["joints: " + " ".join(joints)]
    for r in range(len(sol)):
        target = " ".join(f"{v:.4f}" for v in sol.targets[r])
        posture = " ".join(f"{v:+.4f}" for v in sol.postures[r])
        status = "ok" if sol.success[r] else "NOT REACHED"
        lines.append(
            f"[{target}] -> q [{posture}]  residual {sol.residuals[r]:.2e} m, "
            f"{int(sol.iterations[r])} iterations, {status}"
        )
    lines.append(sol.summary())
    return "\n".join(lines)


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
    X = _targets(args, target.axes if len(target.axes) == target.n_task else target.n_task, target.name)
    sol = result.solve(
        X, tol=args.tol, max_iterations=args.max_iterations, seed=args.seed, angle_tol=args.angle_tol,
        timeout=args.timeout,
    )  # fmt: skip
    if args.json:
        print(_as_json(sol, target.name, target.joints, target.axes))
    else:
        print(_as_text(sol, target.joints))
    if not sol.success.all():
        print(f"gb-pin: {int((~sol.success).sum())} target(s) not reached to {sol.tol:g} m", file=sys.stderr)
        return 1
    return 0
