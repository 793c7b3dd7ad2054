"""Bootstrap the inverse kinematics of a 20-joint planar arm and use it on new targets."""

from __future__ import annotations

import argparse

import numpy as np

import gb_pin


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--movements", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    result = gb_pin.babble(robot="planar20", movements=args.movements, seed=args.seed, learning_rate=0.1)
    h = result.history
    for r in (0, 10, 100, args.movements):
        if r <= args.movements:
            e, d = h.at(r)
            print(f"after {r:>5} movements: E^X = {e:.4f} m, D^home = {d:.3f} rad")

    # Use the learned inverse model: targets between the grid points.
    rng = np.random.default_rng(args.seed)
    new_targets = rng.uniform([0.35, -0.35], [0.75, 0.35], size=(5, 2))
    postures = result.inverse(new_targets)
    reached = result.target.forward(postures)  # Pinocchio's forward kinematics
    for x_star, x in zip(new_targets, reached, strict=True):
        print(
            f"target {x_star.round(3)} -> reached {x.round(3)}, "
            f"error {np.linalg.norm(x - x_star) * 1000:.1f} mm"
        )


if __name__ == "__main__":
    main()
