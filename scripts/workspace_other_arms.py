"""A workspace region on an arm of example-robot-data (docs/WORKSPACE.md, "Other arms"), 3 seeds.

    python scripts/workspace_other_arms.py xarm7 link_eef auto,1

Onboards the arm from its frame alone, prints what ``parts=auto`` chooses for f = 0.5, then for
each ``parts`` value given the median and 90 % reach error [mm] on the region's test points after
10^4 movements, K and E^X / E_0 of seeds 0-2.
"""

import sys
import warnings

import numpy as np

import gb_pin
from gb_pin.robot.workspace import WorkspaceRegion
from gb_pin.robot.workspace_parts import auto_parts

warnings.simplefilter("ignore")
name, frame = sys.argv[1], sys.argv[2]
arm = gb_pin.KinematicTarget.from_example_robot_data(name, frame)
print(name, "auto parts", auto_parts(arm, WorkspaceRegion(0.5)), flush=True)
for parts in sys.argv[3].split(","):
    rows = []
    for seed in range(3):
        r = gb_pin.babble(
            arm,
            movements=10000,
            seed=seed,
            targets=f"workspace:fraction=0.5,parts={parts}",
            schedule=[0, 10000],
        )
        e = r.workspace_errors()
        rows.append((e.median * 1000, e.p90 * 1000, r.n_prototypes, r.error / r.initial_error))
    a = np.array(rows)
    print(
        name,
        "parts",
        parts,
        "med",
        a[:, 0].round(2),
        "p90",
        a[:, 1].round(1),
        "K",
        a[:, 2].astype(int),
        "E/E0",
        a[:, 3].round(4),
        flush=True,
    )
