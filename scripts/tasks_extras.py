"""Issue 13 extras: direction sampling and a coarse-to-fine radius on talos_left_arm_pose (10 seeds, 10^4).

Usage: python scripts/tasks_extras.py uniform directions:distance=0.05 c2f
("c2f": 3000 movements with radius 0.15, then 7000 more from that run with radius 0.1). Prints the
median over seeds of the final position [mm] and orientation [deg] errors (history.components).
"""

import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor

import numpy as np

warnings.simplefilter("ignore")


def one(args: tuple[str, int]) -> tuple[str, int, float, float, int, float]:
    """One seed of one condition: (condition, seed, position [m], orientation [deg], K, us/step)."""
    cond, seed = args
    import gb_pin

    t = time.perf_counter()
    if cond == "c2f":
        r1 = gb_pin.babble("talos_left_arm_pose", movements=3000, seed=seed, radius=0.15)
        r = gb_pin.babble("talos_left_arm_pose", movements=7000, init=r1, radius=0.1)
        steps = r1.steps + r.steps
    elif cond == "uniform":
        r = gb_pin.babble("talos_left_arm_pose", movements=10000, seed=seed)
        steps = r.steps
    else:
        r = gb_pin.babble("talos_left_arm_pose", movements=10000, seed=seed, goals=cond)
        steps = r.steps
    wall = time.perf_counter() - t
    c = r.history.components[-1]
    return cond, seed, float(c[0]), float(c[1]), r.n_prototypes, 1e6 * wall / steps


if __name__ == "__main__":
    conds = sys.argv[1:]
    with ProcessPoolExecutor(2) as ex:
        out = list(ex.map(one, [(c, s) for c in conds for s in range(10)]))
    for c in conds:
        rows = np.array([o[2:] for o in out if o[0] == c])
        position, orientation, prototypes, cost = np.median(rows, axis=0)
        print(
            f"{c}: position {1000 * position:.1f} mm, orientation {orientation:.2f} deg, "
            f"prototypes {prototypes:.0f}, {cost:.1f} us/step (10 seeds, 10^4 movements)",
            flush=True,
        )
