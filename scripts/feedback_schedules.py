"""How many readings feedback reaching should average, by tracker noise (docs/HARDWARE.md).

    python scripts/feedback_schedules.py                 # 6 arms, about a minute on 2 cores
    python scripts/feedback_schedules.py --arms 10 --noise 0.0015,0.0002

Mis-calibrated SO-101s (3 deg, 3 %) learn 3000 movements through a tracker of the given noise that
loses 10 % of its readings; then each observation schedule (readings averaged before each correction)
and gain reaches the 27-point test grid of ``gb-pin reproduce hardware``. Printed: the median over the
arms of each arm's median error on the true body [mm], and the readings used per target.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

import gb_pin
from gb_pin.learn.feedback import reach
from gb_pin.reproduce.hardware import evaluation_grid

SCHEDULES = ((1, 1, 3), (1, 2, 2), (3,), (5,), (10,), (4, 16), (2, 8, 32))


def main() -> None:
    """Print one markdown table per noise level."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--arms", type=int, default=6)
    p.add_argument("--noise", default="0.0002,0.0015", help="tracker noise per axis [m], comma-separated")
    p.add_argument("--movements", type=int, default=3000)
    args = p.parse_args()
    arm = gb_pin.load_robot("so101")
    test = evaluation_grid(arm)
    for noise in (float(v) for v in args.noise.split(",")):
        rows: dict[str, list[float]] = {}
        for seed in range(args.arms):
            plant = gb_pin.Plant("so101", offset_std=math.radians(3), length_std=0.03, noise=noise, loss=0.1,
                                 seed=seed)  # fmt: skip
            run = gb_pin.babble(plant, movements=args.movements, seed=seed, eval_targets=test)
            Q = np.clip(run.inverse(test), arm.lower, arm.upper)
            rows.setdefault("open loop (0 readings)", []).append(
                float(np.median(np.linalg.norm(plant.forward(Q) - test, axis=1)))
            )
            for obs in SCHEDULES:
                for gain in (1.0, 0.5):
                    out = reach(
                        run.model, test, plant.observe, arm.lower, arm.upper, observations=obs, gain=gain
                    )
                    key = f"{obs} gain {gain:g} ({sum(obs)} readings)"
                    rows.setdefault(key, []).append(
                        float(np.median(np.linalg.norm(plant.forward(out.postures) - test, axis=1)))
                    )
        head = f"tracker noise {1000 * noise:g} mm per axis, 10 % lost"
        print(f"\n{head}, {args.arms} arms, {args.movements} movements")
        print("| readings before each correction | median error [mm] | arms' range [mm] |")
        print("|---|---|---|")
        for key, values in rows.items():
            v = 1000 * np.array(values)
            print(f"| {key} | {np.median(v):.2f} | {v.min():.2f}-{v.max():.2f} |")


if __name__ == "__main__":
    main()
