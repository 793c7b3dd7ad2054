"""The human right arm of example-robot-data with targets of its own (issue 30; docs/WORKSPACE.md).

    python scripts/workspace_human_arm.py 3000

27 targets at FK of home + U(-0.45, 0.45) per joint (seed 0); 3 seeds with the settings scaled to
these targets (the default now) and with onboarding's settings for its own 7 cm grid. Prints E^X / E_0.
"""

from __future__ import annotations

import sys

import numpy as np

import gb_pin

JOINTS = ["right_shoulder_Z", "right_shoulder_X", "right_shoulder_Y", "right_elbow_Z", "right_elbow_Y",
          "right_wrist_Z", "right_wrist_X"]  # fmt: skip


def main() -> None:
    """Both settings, seeds 0-2."""
    movements = int(sys.argv[1]) if len(sys.argv) > 1 else 3000
    arm = gb_pin.KinematicTarget.from_example_robot_data(
        "human", "right_hand", joints=JOINTS, home=[0.5, 0.3, 0.3, 1.3, 0.5, 0, 0]
    )
    rng = np.random.default_rng(0)
    X = arm.forward(np.clip(arm.home + rng.uniform(-0.45, 0.45, (27, 7)), arm.lower, arm.upper))
    onboarded = arm.learner_defaults
    print("onboarding's settings", onboarded)
    for label, given in (("scaled to the targets", {}), ("onboarding's", onboarded)):
        for seed in range(3):
            run = gb_pin.babble(
                arm, movements=movements, seed=seed, targets=X, schedule=[0, movements], **given
            )
            share = run.error / run.history.error[0]
            used = f"radius {run.config.radius:.4f}, sigma {run.config.sigma:.4f}, K {run.n_prototypes}"
            print(f"{label:22s} seed {seed}: E^X / E_0 {share:.4f} ({used})")


if __name__ == "__main__":
    main()
