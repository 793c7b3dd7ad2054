"""Where a Panda region's errors lie (docs/WORKSPACE.md, "The measurement"), from the study's cache.

    python scripts/workspace_where.py docs/figures/workspace/trials

Over the cached runs of the Panda at f = 0.5 (``gb-pin reproduce workspace``), after 10^4 movements:
the median error of the test points more than 135 deg (azimuth about the base's vertical) from
home's direction and of those within 45 deg, the share of the worst tenth beyond 90 deg, and the
worst tenth's median distance from the base axis over all points' (medians over the runs).
"""

from __future__ import annotations

import glob
import json
import os
import sys

import numpy as np


def main() -> None:
    """Print the four figures."""
    cache = sys.argv[1] if len(sys.argv) > 1 else "docs/figures/workspace/trials"
    rows = []
    for path in glob.glob(os.path.join(cache, "panda_f0.5_*_m30000.json")):
        with open(path, encoding="utf-8") as fh:
            rows.append(json.load(fh))
    behind, front, share, radial = [], [], [], []
    for r in rows:
        X = np.array(r["test"])
        e = np.array(r["snapshots"]["10000"]["errors"]) * 1000
        az = np.degrees(np.abs(np.arctan2(X[:, 1], X[:, 0])))
        behind.append(np.median(e[az > 135]))
        front.append(np.median(e[az < 45]))
        d = np.linalg.norm(X[:, :2], axis=1)
        bad = e > np.quantile(e, 0.9)
        share.append(np.mean(az[bad] > 90))
        radial.append(np.median(d[bad]) / np.median(d))
    print(f"{len(rows)} runs: median error beyond 135 deg {np.median(behind):.2f} mm, within 45 deg "
          f"{np.median(front):.2f} mm; worst tenth beyond 90 deg {np.median(share):.0%}, its distance from "
          f"the axis / all points' {np.median(radial):.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
