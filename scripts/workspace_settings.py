"""One learner setting of a workspace region against others, over seeds (docs/WORKSPACE.md).

    python scripts/workspace_settings.py panda 10000 10 '{}' '{"cutoff": 4.0}' '{"sdr": 0.1}'

Each variant (a JSON object of ``babble`` keywords; ``targets`` defaults to
``workspace:fraction=0.5``; ``sdr``: sigma_delta as a share of the run's sigma) runs
``gb_pin.babble(ROBOT, movements=M, seed=s, targets=..., **variant)`` for seeds 0..N-1 and prints
the median over the seeds of each run's median and 90 % reach error on the region's test points
[mm], the median prototype count, then each seed's median.
"""

import json
import sys
import warnings

import numpy as np

import gb_pin

warnings.simplefilter("ignore")
robot, movements, seeds = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
for spec in sys.argv[4:]:
    kw = json.loads(spec)
    targets = kw.pop("targets", "workspace:fraction=0.5")
    if "sdr" in kw:
        share = kw.pop("sdr")
        sigma = gb_pin.babble(robot, movements=1, seed=0, targets=targets, **kw).config.sigma
        kw["sigma_delta"] = share * sigma
    medians, p90s, counts = [], [], []
    for seed in range(seeds):
        run = gb_pin.babble(
            robot, movements=movements, seed=seed, targets=targets, schedule=[0, movements], **kw
        )
        errors = run.workspace_errors()
        medians.append(1e3 * errors.median)
        p90s.append(1e3 * errors.p90)
        counts.append(run.n_prototypes)
    print(
        f"{robot} {movements} {spec} {targets}: median {np.median(medians):.3f} 90 % {np.median(p90s):.2f} "
        f"K {np.median(counts):.0f} |",
        " ".join(f"{m:.2f}" for m in medians),
        flush=True,
    )
