"""One setting at a time on a workspace region (docs/WORKSPACE.md, "What changed the numbers").

    python scripts/workspace_sweep.py so101 10000 lr0.1,sigma1,r0.06,lr0.5

Each variant learns ``targets="workspace:fraction=0.5"`` with seeds 0-2 and prints each run's median
and 90 % reach error on the region's test points [mm], the prototypes K, and the median over the seeds.
Unlisted settings are the region's defaults (gb_pin/runs/scaling.py); the variants name the learning
rate explicitly, so that the table reproduces whatever the default is.
"""

from __future__ import annotations

import sys

import numpy as np

import gb_pin
from gb_pin.learn.config import default_sigma
from gb_pin.robot.workspace import WorkspaceRegion, extent


def variants(robot: str) -> dict[str, dict[str, object]]:
    """Name -> babble arguments."""
    arm = gb_pin.load_robot(robot)
    L = extent(WorkspaceRegion().final_goals(arm))
    eq12 = default_sigma(arm.n_joints)
    out: dict[str, dict[str, object]] = {
        "lr0.1": {"learning_rate": 0.1},
        "sigma1": {"learning_rate": 0.1, "sigma": eq12},
        "r0.06": {"learning_rate": 0.1, "radius": 0.06 * L},
        "r0.10": {"learning_rate": 0.1, "radius": 0.10 * L},
        "uniform": {"learning_rate": 0.1, "goals": "uniform"},
        "sigma3": {"learning_rate": 0.1, "sigma": 3 * eq12},
    }
    for lr in (0.2, 0.3, 0.5, 0.7, 1.0):
        out[f"lr{lr:g}"] = {"learning_rate": lr}
    out["lr0.5-uniform"] = {"learning_rate": 0.5, "goals": "uniform"}
    out["lr0.5-r0.10"] = {"learning_rate": 0.5, "radius": 0.10 * L}
    return out


def main() -> None:
    """Run the variants named on the command line (all by default)."""
    robot, movements = sys.argv[1], int(sys.argv[2])
    table = variants(robot)
    names = sys.argv[3].split(",") if len(sys.argv) > 3 else list(table)
    for name in names:
        rows = []
        for seed in range(3):
            run = gb_pin.babble(robot, movements=movements, seed=seed, targets="workspace:fraction=0.5",
                                schedule=[0, movements], **table[name])  # type: ignore[arg-type]  # fmt: skip
            e = run.workspace_errors()
            rows.append((1000 * e.median, 1000 * e.p90, run.n_prototypes))
        a = np.array(rows)
        head = f"{robot} {movements} {name:14s} median {np.round(a[:, 0], 2)} 90 % {np.round(a[:, 1], 1)}"
        tail = f"K {a[:, 2].astype(int)} | {np.median(a[:, 0]):.2f} / {np.median(a[:, 1]):.1f}"
        print(head, tail, flush=True)


if __name__ == "__main__":
    main()
