"""Bring your own robot: load a URDF, let it learn its inverse kinematics, use the inverse on new targets.

    python examples/custom_urdf.py                                   # tests/data/small_arm.urdf
    python examples/custom_urdf.py --urdf my_arm.urdf --frame tool --srdf my_arm.srdf

The URDF is read with Pinocchio (kinematics only, no mesh needed). Without --targets the
learner uses the "auto" target set: the largest regular 3 x 3 x 3 grid around the home
effector position whose points are all reachable within the joint limits (found by seeded
posture sampling, so it is the same on every run). After learning, the inverse estimate
g(x*) is asked for new targets inside that grid, and the executed (clipped) postures are
checked with Pinocchio.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import gb_pin
from gb_pin.robot.targets_auto import auto_grid

HERE = Path(__file__).resolve().parent
SMALL_ARM = HERE.parent / "tests" / "data" / "small_arm.urdf"


def main() -> None:
    """Load, babble, report, reach new targets."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--urdf", default=str(SMALL_ARM), help="URDF file (default: the small test arm)")
    parser.add_argument("--srdf", default=None, help="SRDF with reference configurations (optional)")
    parser.add_argument("--frame", default="tool", help="operational frame (default tool)")
    parser.add_argument("--joints", default=None, help="comma-separated joints to move (default: all)")
    parser.add_argument("--movements", type=int, default=2000, help="movements (default 2000)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--radius", type=float, default=None, help="prototype radius d [m] (default 0.1)")
    args = parser.parse_args()

    srdf = args.srdf
    if srdf is None and Path(args.urdf) == SMALL_ARM:
        srdf = str(SMALL_ARM.with_suffix(".srdf"))  # its "ready" posture is the home
    joints = None if args.joints is None else [j.strip() for j in args.joints.split(",")]
    target = gb_pin.KinematicTarget.from_urdf(args.urdf, args.frame, joints, srdf=srdf)
    print(f"{target.name}: joints {', '.join(target.joints)}; home {np.round(target.home, 3).tolist()}")
    print(f"limits {np.round(target.lower, 3).tolist()} .. {np.round(target.upper, 3).tolist()}")

    grid = auto_grid(target)  # what babble() uses for a target without targets
    print(
        f"auto targets: {len(grid.targets)} points, half-width {grid.half_width} m around "
        f"{np.round(grid.center, 3).tolist()} m"
    )
    result = gb_pin.babble(target, movements=args.movements, seed=args.seed, radius=args.radius)
    e0 = result.history.error[0]
    print(
        f"after {result.movements} movements: E^X = {result.error * 1000:.2f} mm "
        f"({result.error / e0:.1%} of E_0 = {e0 * 1000:.1f} mm), {result.n_prototypes} prototypes"
    )

    rng = np.random.default_rng(args.seed + 1)
    X = grid.lower + (grid.upper - grid.lower) * rng.random((10, target.n_task))
    Q = target.clip(result.inverse(X))
    reached = target.forward(Q)  # Pinocchio on the model
    errors = np.linalg.norm(reached - X, axis=1)
    for x, e in zip(X, errors, strict=True):
        print(f"  target {np.round(x, 3).tolist()} m: reached within {e * 1000:.2f} mm")
    print(f"mean error on new targets: {errors.mean() * 1000:.2f} mm")


if __name__ == "__main__":
    main()
