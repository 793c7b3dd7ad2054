"""Bring your own robot: load a URDF, let it learn its inverse kinematics, use the inverse on new targets.

    python examples/custom_urdf.py                                   # tests/data/small_arm.urdf
    python examples/custom_urdf.py --urdf my_arm.urdf --frame tool --srdf my_arm.srdf --home ready

The URDF is read with Pinocchio (kinematics only, no mesh needed). What is not given is chosen
by measurement (onboarding, docs/ROBOTS.md): the joints that move the frame, a home away from
the joint limits and singularities, the goal grid (half of the largest reachable 3 x 3 x 3 grid
around the home, found by seeded posture sampling: the same on every run) and the prototype
radius. After learning, the inverse estimate g(x*) is asked for new targets inside that grid,
and the executed (clipped) postures are checked with Pinocchio.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import gb_pin

HERE = Path(__file__).resolve().parent
SMALL_ARM = HERE.parent / "tests" / "data" / "small_arm.urdf"


def main() -> None:
    """Load, babble, report, reach new targets."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--urdf", default=str(SMALL_ARM), help="URDF file (default: the small test arm)")
    parser.add_argument("--srdf", default=None, help="SRDF with reference configurations (optional)")
    parser.add_argument("--frame", default="tool", help="operational frame (default tool)")
    parser.add_argument("--joints", default=None, help="comma-separated joints to move (default: chosen)")
    parser.add_argument("--home", default=None, help="a named posture of the SRDF (default: chosen)")
    parser.add_argument("--movements", type=int, default=2000, help="movements (default 2000)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--radius", type=float, default=None, help="prototype radius d [m] (default: chosen)")
    args = parser.parse_args()

    srdf = args.srdf
    if srdf is None and Path(args.urdf) == SMALL_ARM:
        srdf = str(SMALL_ARM.with_suffix(".srdf"))  # its "ready" posture: --home ready
    joints = None if args.joints is None else [j.strip() for j in args.joints.split(",")]
    target = gb_pin.KinematicTarget.from_urdf(args.urdf, args.frame, joints, args.home, srdf=srdf)
    print(f"{target.name}: joints {', '.join(target.joints)}; home {np.round(target.home, 3).tolist()}")
    print(f"limits {np.round(target.lower, 3).tolist()} .. {np.round(target.upper, 3).tolist()}")
    if target.onboarding is not None:  # what was chosen by measurement, and why
        for line in target.onboarding.lines(target.joints, target.home, len(target.targets)):
            print(f"chosen: {line}")
    assert target.targets is not None  # the goal grid onboarding chose
    lower, upper = target.targets.min(axis=0), target.targets.max(axis=0)
    result = gb_pin.babble(target, movements=args.movements, seed=args.seed, radius=args.radius)
    e0 = result.history.error[0]
    print(
        f"after {result.movements} movements: E^X = {result.error * 1000:.2f} mm "
        f"({result.error / e0:.1%} of E_0 = {e0 * 1000:.1f} mm), {result.n_prototypes} prototypes"
    )

    rng = np.random.default_rng(args.seed + 1)
    X = lower + (upper - lower) * rng.random((10, target.n_task))
    Q = target.clip(result.inverse(X))
    reached = target.forward(Q)  # Pinocchio on the model
    errors = np.linalg.norm(reached - X, axis=1)
    for x, e in zip(X, errors, strict=True):
        print(f"  target {np.round(x, 3).tolist()} m: reached within {e * 1000:.2f} mm")
    print(f"mean error on new targets: {errors.mean() * 1000:.2f} mm")


if __name__ == "__main__":
    main()
