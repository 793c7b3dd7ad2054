"""The IK benchmark's baseline: the same damped least squares with Pinocchio calls per iteration, in Python.

    python scripts/ik_pinocchio_baseline.py [--robots talos_left_arm,panda]

Home seed, lambda 1e-3 m, full steps clipped to the limits, tol 1e-4 m, at most 100 steps, on the
200 near targets of docs/IK.md (postures within home +/- 0.45 rad, seed 0), against gb_pin.ik's
compiled solver (home and learned seeds) on the same targets, after 3000 movements of babbling.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import pinocchio as pin

import gb_pin
from gb_pin.experiments.ik_bench import posture_targets


def pinocchio_dls(target: gb_pin.KinematicTarget, X: np.ndarray) -> tuple[int, float]:
    """(targets solved, median iterations) of the DLS loop written with Pinocchio calls."""
    model, data, frame, axes = (
        target.model,
        target.model.createData(),
        target.frame_id,
        target.chain.task_axes,
    )
    columns = [model.joints[model.getJointId(j)].idx_v for j in target.joints]
    world = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    solved, iterations = 0, []
    for x in X:
        q = target.home.copy()
        for k in range(101):
            config = target.to_pinocchio(q)
            pin.framesForwardKinematics(model, data, config)
            e = x - data.oMf[frame].translation[axes]
            if np.linalg.norm(e) <= 1e-4:
                solved += 1
                break
            if k == 100:
                break
            J = pin.computeFrameJacobian(model, data, config, frame, world)[:3][axes][:, columns]
            q = np.clip(
                q + J.T @ np.linalg.solve(J @ J.T + 1e-6 * np.eye(len(axes)), e), target.lower, target.upper
            )
        iterations.append(k)
    return solved, float(np.median(iterations))


def main() -> None:
    """Print one line per robot: Pinocchio loop vs compiled solver, solved / median iterations / us."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", default="talos_left_arm,panda", help="comma-separated presets")
    args = parser.parse_args()
    for name in args.robots.split(","):
        result = gb_pin.babble(name, movements=3000, seed=0)
        X = posture_targets(result.target, 0.45, 200, np.random.default_rng(0))
        result.solve(X)  # compile or load the kernels first
        start = time.perf_counter()
        solved, median = pinocchio_dls(result.target, X)
        us_pin = 1e6 * (time.perf_counter() - start) / len(X)
        line = (
            f"{name}: Pinocchio loop (home seed) {solved}/200, median {median:g} steps, {us_pin:.0f} us/query"
        )
        for seed in ("home", "learned"):
            start = time.perf_counter()
            sol = result.solve(X, seed=seed)
            us = 1e6 * (time.perf_counter() - start) / len(X)
            median = float(np.median(sol.iterations))
            line += f"; gb_pin.ik ({seed}) {int(sol.success.sum())}/200, median {median:g}, {us:.1f} us"
        print(line)


if __name__ == "__main__":
    main()
