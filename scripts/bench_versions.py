"""Per-step cost of two gb_pin trees, measured alternately in one run (old, new, old, new, ...).

On a noisy machine only an alternating comparison is fair: each round runs ``gb-pin bench``'s
measurement once per tree in a fresh subprocess (its own numba cache), so that drifts of the
machine's load hit both alike. Reports the median us/step per robot and the ratio new/old.

    python scripts/bench_versions.py --old /path/to/old/tree --rounds 5

The old tree is any checkout of gb_pin (e.g. ``git worktree add ../old v0.1``); its
benchmark module is found at ``gb_pin.experiments.bench`` or, for 0.1, ``gb_pin.bench``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

CHILD = """
import json, sys
try:
    from gb_pin.experiments.bench import run_benchmark
except ImportError:
    from gb_pin.bench import run_benchmark
import gb_pin
rows = run_benchmark(sys.argv[1].split(","), movements=int(sys.argv[2]), repeat=int(sys.argv[3]))
print(json.dumps({"file": gb_pin.__file__,
                  "rows": {r.robot: [r.us_per_step, r.us_per_step_eval, r.error] for r in rows}}))
"""


def measure(tree: Path, robots: str, movements: int, repeat: int) -> dict[str, list[float]]:
    """One benchmark of ``tree`` in a fresh interpreter: robot -> [us/step, us/step with eval, E^X]."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    out = subprocess.run(
        [sys.executable, "-c", CHILD, robots, str(movements), str(repeat)],
        capture_output=True, text=True, env=env, cwd=tree, check=True,
    )  # fmt: skip
    data = json.loads(out.stdout.strip().splitlines()[-1])
    if not data["file"].startswith(str(tree.resolve())):
        raise SystemExit(f"{tree}: imported gb_pin from {data['file']}")
    return data["rows"]


def main(argv: list[str] | None = None) -> int:
    """Alternate the two trees for --rounds rounds and print the medians."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old", type=Path, required=True, help="the tree to compare against")
    parser.add_argument("--new", type=Path, default=Path(__file__).resolve().parents[1])
    parser.add_argument("--robots", default="planar5,planar20,planar50,talos_left_arm,panda")
    parser.add_argument("--movements", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=3, help="best of this many runs per measurement")
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args(argv)
    trees = {"old": args.old.resolve(), "new": args.new.resolve()}
    for tree in trees.values():  # compile (or load) each tree's kernels before timing
        measure(tree, "planar5", 10, 1)
    runs: dict[str, list[dict[str, list[float]]]] = {"old": [], "new": []}
    for r in range(args.rounds):
        for name in ("old", "new") if r % 2 == 0 else ("new", "old"):
            runs[name].append(measure(trees[name], args.robots, args.movements, args.repeat))
    print(f"{args.rounds} alternating rounds, best of {args.repeat} x {args.movements} movements each")
    print(
        "| robot | old us/step | new us/step | new/old | old (eval) | new (eval) | new/old (eval) "
        "| same E^X |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for robot in args.robots.split(","):
        med = {k: [statistics.median(run[robot][i] for run in v) for i in (0, 1)] for k, v in runs.items()}
        same = all(a[robot][2] == b[robot][2] for a, b in zip(runs["old"], runs["new"], strict=True))
        print(
            f"| {robot} | {med['old'][0]:.2f} | {med['new'][0]:.2f} | {med['new'][0] / med['old'][0]:.3f} "
            f"| {med['old'][1]:.2f} | {med['new'][1]:.2f} | {med['new'][1] / med['old'][1]:.3f} | {same} |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
