"""The share of a region map's activations a cutoff leaves out (docs/WORKSPACE.md, "The cutoff").

    python scripts/workspace_cutoff_share.py

For the SO-101 and the Panda (f = 0.5, seed 0, 10^4 movements) and c = 2.5, 3, 4: over the 300 test
points, each answered by its part's map, the sum of exp(-(||u_k||^2 - min)) over the prototypes
beyond the cutoff over the whole sum (median, 99 % and maximum), and the prototypes listed (median).
"""

import warnings

import numpy as np

import gb_pin

warnings.simplefilter("ignore")
for robot in ("so101", "panda"):
    run = gb_pin.babble(
        robot, movements=10_000, seed=0, targets="workspace:fraction=0.5", schedule=[0, 10_000]
    )
    X = np.asarray(run.targets)
    maps = getattr(run.model, "maps", [run.model])
    part = run.model.part_of(X) if len(maps) > 1 else np.zeros(len(X), dtype=int)
    for c in (2.5, 3.0, 4.0):
        shares, listed = [], []
        for x, p in zip(X, part, strict=True):
            lm = maps[p]
            sq = ((x - lm.prototypes_) ** 2).sum(axis=1) / lm.radius**2
            b = np.exp(-(sq - sq.min()))
            out = sq > sq.min() + c * c
            shares.append(b[out].sum() / b.sum())
            listed.append(int((~out).sum()))
        print(
            f"{robot} c = {c}: left out median {np.median(shares):.2e}, "
            f"99 % {np.quantile(shares, 0.99):.2e}, max {np.max(shares):.2e}; "
            f"listed median {np.median(listed):.0f}",
            flush=True,
        )
