"""Check the generated collision matrices (issue 34) against 10^4 fresh sampled postures.

No checked pair touches at home, and every pair that touches in a sampled posture is checked.

    python scripts/check_collision_matrix.py --samples 10000 --check 10000
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from gb_pin.robot.presets import load_robot
from gb_pin.safety.checker import DEFAULT_CLEARANCE
from gb_pin.safety.geometry import robot_geometry
from gb_pin.safety.matrix import ADJACENT, ENABLED, cached_matrix, pair_contacts, sample_postures


def main() -> None:
    """Print the table (markdown)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="+", default=["so101", "so100", "panda", "ur5"])
    parser.add_argument("--samples", type=int, default=10_000, help="postures generating the matrix (seed 0)")
    parser.add_argument("--check", type=int, default=10_000, help="fresh postures checking it (seed 1)")
    args = parser.parse_args()
    print("| robot | shapes | pairs checked | adjacent | at home | always | never | generated [s] "
          "| pairs touching at home | pairs touching in the check | of those not checked |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for robot in args.robots:
        target = load_robot(robot)
        geometry = robot_geometry(target)
        start = time.perf_counter()
        matrix = cached_matrix(target, geometry, DEFAULT_CLEARANCE, args.samples, 0)
        took = time.perf_counter() - start
        k = len(geometry.body)
        enabled = [(i, j) for i in range(k) for j in range(i + 1, k) if matrix.reason[i, j] == ENABLED]
        at_home = int(pair_contacts(target, geometry, enabled, target.home[None, :]).sum())
        candidates = [(i, j) for i in range(k) for j in range(i + 1, k) if matrix.reason[i, j] != ADJACENT]
        postures = sample_postures(target.lower, target.upper, args.check, 1)
        hits = pair_contacts(target, geometry, candidates, postures)
        touching = [candidates[p] for p in np.nonzero(hits)[0]]
        missed = [p for p in touching if matrix.reason[p] != ENABLED]
        c = matrix.counts()
        named = [(matrix.names[i], matrix.names[j]) for i, j in missed]
        cells = [
            *[robot, k, *c.values()][:7],
            f"{took:.1f}",
            at_home,
            len(touching),
            f"{len(missed)} {named}",
        ]
        print("| " + " | ".join(str(v) for v in cells) + " |", flush=True)


if __name__ == "__main__":
    main()
