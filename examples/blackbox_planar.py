"""A planar arm given as a plain Python function learns as the compiled Pinocchio preset does."""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import gb_pin


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--movements", type=int, default=1000)
    args = parser.parse_args()
    arm = gb_pin.load_robot("planar5")

    def forward(q: np.ndarray) -> np.ndarray:
        """The planar5 arm's tip, closed form (five 0.2 m links)."""
        x = y = h = 0.0
        for v in q:
            h += v
            x += 0.2 * math.cos(h)
            y += 0.2 * math.sin(h)
        return np.array([x, y])

    box = gb_pin.FunctionTarget(
        forward, arm.home, lower=arm.lower, upper=arm.upper, targets=arm.targets, name="box"
    )
    n = args.movements
    compiled, black, t_compiled, t_black = [], [], [], []
    for seed in range(args.seeds):
        start = time.perf_counter()
        compiled.append(gb_pin.babble("planar5", n, seed=seed, schedule=[0, n]).error)
        t_compiled.append(time.perf_counter() - start)
        start = time.perf_counter()
        res = gb_pin.babble(box, n, seed=seed, schedule=[0, n])
        black.append(res.error)
        t_black.append(time.perf_counter() - start)
    steps = res.steps
    mc, mb = float(np.median(compiled)), float(np.median(black))
    worst = float(np.max(np.abs(np.subtract(compiled, black))))
    print(
        f"median E^X after {n} movements over {args.seeds} seeds: compiled {mc:.5f} m, Python function "
        f"{mb:.5f} m (ratio {mb / mc:.4f}); largest per-seed difference {worst:.1e} m"
    )
    print(
        f"per step: compiled {1e6 * np.median(t_compiled) / steps:.2f} us, Python function "
        f"{1e6 * np.median(t_black) / steps:.1f} us"
    )


if __name__ == "__main__":
    main()
