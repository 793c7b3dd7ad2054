"""A planar continuum arm (constant curvature) learnt by goal babbling from its forward function alone.

Three soft segments of 0.33 m each; the posture q is each segment's bending angle [rad] (its
curvature times its length). Segment i bends by q_i along a circular arc, so its tip lies at
(L sin q / q, L (1 - cos q) / q) in the segment's base frame, and the next segment starts
there, turned by q_i. No Pinocchio model exists for such an arm: :class:`gb_pin.FunctionTarget`
takes the forward function, a home posture, limits and targets.

    python examples/continuum_arm.py
    gb-pin babble --robot examples/continuum_arm.py:robot --movements 2000
"""

from __future__ import annotations

import argparse
import itertools
import math
import time

import numpy as np

import gb_pin

LENGTHS = (0.33, 0.33, 0.33)  # [m]
HOME = np.array([0.4, 0.4, 0.4])  # [rad], a gentle curl
LIMIT = 2.0  # [rad] most a segment bends either way


def forward(q: np.ndarray) -> np.ndarray:
    """Tip position (x, y) [m] of the arm at bending angles ``q`` (3,) [rad]."""
    x = y = heading = 0.0
    for length, bend in zip(LENGTHS, q, strict=True):
        if abs(bend) < 1e-9:
            dx, dy = length, 0.0
        else:
            dx, dy = length * math.sin(bend) / bend, length * (1.0 - math.cos(bend)) / bend
        c, s = math.cos(heading), math.sin(heading)
        x += c * dx - s * dy
        y += s * dx + c * dy
        heading += bend
    return np.array([x, y])


def targets() -> np.ndarray:
    """A 3 x 3 x 3 posture grid around home, mapped forward: 27 reachable targets [m]."""
    offsets = (-0.6, 0.0, 0.6)
    return np.array([forward(HOME + np.array(d)) for d in itertools.product(offsets, repeat=3)])


def robot() -> gb_pin.FunctionTarget:
    """The continuum arm as a robot for gb_pin (used by ``--robot examples/continuum_arm.py:robot``)."""
    return gb_pin.FunctionTarget(
        forward, HOME, lower=-LIMIT, upper=LIMIT, targets=targets(), name="continuum3"
    )


def main() -> None:
    """Learn ``--movements`` movements and print E^X and the per-step cost."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--movements", type=int, default=2000, help="movements (default 2000)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    args = parser.parse_args()
    arm = robot()
    start = time.perf_counter()
    result = gb_pin.babble(arm, movements=args.movements, seed=args.seed)
    wall = time.perf_counter() - start
    e = result.history.error
    print(f"continuum arm, {arm.n_joints} segments: E^X {e[0]:.4f} m -> {result.error:.4f} m "
          f"after {result.movements} movements ({result.n_prototypes} prototypes)")  # fmt: skip
    print(f"{1e6 * wall / result.steps:.1f} us per step (forward() in Python, evaluation included)")


if __name__ == "__main__":
    main()
