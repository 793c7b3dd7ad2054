"""A humanoid arm learns its inverse by goal babbling, then solves exact IK with it (checked by Pinocchio)."""

from __future__ import annotations

import argparse
import time

import numpy as np
import pinocchio as pin

import gb_pin
from gb_pin.runs.api import warmup


def main() -> None:
    """Babble, then solve new targets raw vs refined, time 10^4 queries, and follow a straight path."""
    parser = argparse.ArgumentParser(description=__doc__)
    humanoid = [p.name for p in gb_pin.robots() if p.kind == "humanoid arm"]
    parser.add_argument("--robot", default="talos_left_arm", choices=humanoid, help="a humanoid-arm preset")
    parser.add_argument("--movements", type=int, default=3000, help="movements of babbling (default 3000)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--targets", type=int, default=200, help="new targets to solve (default 200)")
    parser.add_argument("--tol", type=float, default=1e-4, help="IK tolerance [m] (default 1e-4)")
    args = parser.parse_args()

    warmup()
    result = gb_pin.babble(args.robot, movements=args.movements, seed=args.seed)
    target = result.target
    print(
        f"{args.robot}: {target.n_joints} joints; "
        f"after {result.movements} movements E^X = {result.error:.4f} m"
    )

    # Reachable targets: positions of postures within home +/- 0.45 rad (clipped to the limits).
    rng = np.random.default_rng(args.seed + 1)
    Q = target.clip(target.home + rng.uniform(-0.45, 0.45, (args.targets, target.n_joints)))
    X = target.forward(Q)
    raw = np.linalg.norm(target.forward(target.clip(result.inverse(X))) - X, axis=1)
    print(f"raw g(x*): median error {1e3 * np.median(raw):.2f} mm, worst {1e3 * raw.max():.2f} mm")
    for seed in ("learned", "home"):
        sol = result.solve(X, tol=args.tol, seed=seed)
        comfort = np.median(sol.home_distance(target.home))
        print(f"  seed {seed:7s}: {sol.summary()}; median ||q - q_home|| {comfort:.2f} rad")

    # Check the refined postures on the *full* humanoid with Pinocchio.
    sol = result.solve(X, tol=args.tol)
    model, frame = target.full_model, target.full_model.getFrameId(target.frame)
    data = model.createData()
    worst = 0.0
    for q, x in zip(sol.postures, X, strict=True):
        pin.framesForwardKinematics(model, data, target.full_configuration(q))
        worst = max(worst, float(np.linalg.norm(data.oMf[frame].translation - x)))
    inside = np.all((sol.postures >= target.lower) & (sol.postures <= target.upper))
    print(f"full model (Pinocchio): worst error {worst:.2e} m, every posture within the limits: {inside}")

    # Speed: 10^4 queries in one batch.
    many = target.forward(target.clip(target.home + rng.uniform(-0.45, 0.45, (10_000, target.n_joints))))
    start = time.perf_counter()
    result.inverse(many)
    middle = time.perf_counter()
    result.solve(many, tol=args.tol)
    end = time.perf_counter()
    us_raw, us_refined = 100 * (middle - start), 100 * (end - middle)  # s per 10^4 -> us each
    print(f"10^4 queries: raw {us_raw:.2f} us each, refined {us_refined:.2f} us each")

    # A straight hand path of 10 cm, each point seeded by the learned inverse.
    start_x = target.home_position
    path = result.solve_path(start_x, start_x + np.array([0.0, 0.1, 0.0]), steps=50, tol=args.tol)
    print(
        f"10 cm path, 50 points: all solved {path.all_solved}, joint length {path.joint_length:.3f} rad, "
        f"largest joint step {path.max_joint_step:.4f} rad"
    )


if __name__ == "__main__":
    main()
