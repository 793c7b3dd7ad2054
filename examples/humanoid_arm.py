"""A TALOS humanoid arm learns to reach in 3-D by goal babbling, then reaches new targets (Pinocchio checks).

    python examples/humanoid_arm.py                      # talos_left_arm, 3000 movements
    python examples/humanoid_arm.py --view               # watch it in the browser (meshcat, 127.0.0.1)
    python examples/humanoid_arm.py --robot icub_right_arm --movements 10000

The preset loads the full humanoid from example-robot-data and locks every joint but the arm's
(the floating base included) at the SRDF's half_sitting posture. After babbling, the learned
inverse g is asked for postures reaching random points inside the target box; each posture is
clipped to the joint limits (what the robot executes) and checked with Pinocchio's forward
kinematics on the *full* model.
"""

from __future__ import annotations

import argparse

import numpy as np
import pinocchio as pin

import gb_pin
from gb_pin.runs.api import warmup


def main() -> None:
    """Babble, report E^X and D^home, then reach new targets and check them on the full model."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    humanoid = [p.name for p in gb_pin.robots() if p.kind == "humanoid arm"]
    parser.add_argument("--robot", default="talos_left_arm", choices=humanoid, help="a humanoid-arm preset")
    parser.add_argument("--movements", type=int, default=3000, help="movements (default 3000)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--new-targets", type=int, default=20, help="new targets to reach after learning")
    parser.add_argument("--view", action="store_true", help="show the robot learning in a live viewer")
    args = parser.parse_args()

    target = gb_pin.load_robot(args.robot)
    warmup()  # compile (or load) the kernels first, so that the timing below is babbling alone
    viewer = None
    if args.view:
        from gb_pin.viewer import open_viewer

        viewer = open_viewer()  # None, with a warning, if meshcat is missing or no port is free
        if viewer is not None:
            print(f"open {viewer.url} in a browser (waiting up to 30 s)")
            viewer.wait_for_browser(30.0)
    print(f"{args.robot}: {target.n_joints} joints {', '.join(target.joints)}")
    print(f"frame {target.frame!r}, home position {np.round(target.home_position, 3).tolist()} m")
    assert target.targets is not None
    print(
        f"{len(target.targets)} targets in the box {target.targets.min(0).round(3).tolist()} .. "
        f"{target.targets.max(0).round(3).tolist()} m"
    )

    result = gb_pin.babble(
        args.robot, movements=args.movements, seed=args.seed, viewer=viewer, observe_every=10
    )
    if viewer is not None:
        viewer.finish()
    e0 = result.history.error[0]
    us = 1e6 * result.wall_time / result.steps
    print(
        f"after {result.movements} movements: E^X = {result.error:.4f} m (E_0 = {e0:.4f} m, "
        f"{result.error / e0:.1%} of E_0), D^home = {result.home_distance:.3f} rad, "
        f"{result.n_prototypes} prototypes, {us:.1f} us/step"
    )

    # New targets: uniform in the box spanned by the target grid.
    rng = np.random.default_rng(args.seed + 1000)
    lower, upper = target.targets.min(0), target.targets.max(0)
    X = lower + (upper - lower) * rng.random((args.new_targets, 3))
    Q = target.clip(result.inverse(X))
    model = target.full_model
    data = model.createData()
    frame = model.getFrameId(target.frame)
    errors = []
    for q, x in zip(Q, X, strict=True):
        pin.framesForwardKinematics(model, data, target.full_configuration(q))
        errors.append(np.linalg.norm(data.oMf[frame].translation - x))
    mean, worst = 1000 * np.mean(errors), 1000 * np.max(errors)
    print(
        f"{args.new_targets} new targets: mean error {mean:.1f} mm, max {worst:.1f} mm "
        "(Pinocchio, full model, postures clipped to the limits)"
    )
    if viewer is not None:
        from gb_pin.viewer import serve_until_interrupted

        print("Ctrl-C to quit")
        serve_until_interrupted(viewer)


if __name__ == "__main__":
    main()
