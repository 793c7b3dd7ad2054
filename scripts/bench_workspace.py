r"""Per-step cost of workspace-region runs in two gb_pin trees, alternated (old, new, new, old, ...).

    python scripts/bench_workspace.py --old /work/main --rounds 3 --movements 10000
    python scripts/bench_workspace.py --old <tree of the commit the issue was filed at> --old-presets-only

One long-lived worker per tree (its own interpreter and numba cache, warmed by one run first)
times ``babble(robot, movements, targets="workspace:fraction=F", schedule=[0, movements])`` and a
preset's default run (its own targets, ``--preset-movements``) on the worker thread's CPU clock; the
workers are asked in turn so that the machine's load hits both alike. Prints per robot the median
us per step (evaluations at 0 and the end included), the prototypes K (all parts together) and
the parts, for each tree, and the ratio new/old, then each robot's region step over the presets'
steps in each tree. ``--old-presets-only``: the old tree runs the presets only (one from before
regions existed: the presets' cost when issue 30 was filed).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

WORKER = r"""
import json, sys, time, warnings
warnings.simplefilter("ignore")
import gb_pin
for line in sys.stdin:
    req = json.loads(line)
    kw = {"targets": req["targets"]} if req["targets"] else {}
    start = time.thread_time()
    run = gb_pin.babble(req["robot"], movements=req["movements"], seed=req["seed"],
                        schedule=[0, req["movements"]], **kw)
    cpu = time.thread_time() - start
    print(json.dumps({"us": 1e6 * cpu / run.steps, "K": run.n_prototypes,
                      "parts": getattr(run.model, "n_parts", 1)}), flush=True)
"""


def main() -> None:
    """Alternate the two trees' workers over the robots and rounds; print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old", required=True, help="the other tree (with its .venv)")
    parser.add_argument("--new", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    parser.add_argument("--robots", default="so101,panda,talos_left_arm")
    parser.add_argument("--fraction", type=float, default=0.5)
    parser.add_argument("--movements", type=int, default=10_000)
    parser.add_argument("--preset-movements", type=int, default=3000)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument(
        "--old-presets-only",
        action="store_true",
        help="the old tree runs the presets only (a tree from before workspace regions existed)",
    )
    args = parser.parse_args()
    trees = {"old": args.old, "new": args.new}
    workers = {}
    for name, tree in trees.items():
        python = os.path.join(tree, ".venv", "bin", "python")
        env = {**os.environ, "PYTHONPATH": tree}
        pipe = subprocess.PIPE
        workers[name] = subprocess.Popen(
            [python, "-c", WORKER], stdin=pipe, stdout=pipe, text=True, cwd=tree, env=env
        )

    def ask(name: str, robot: str, targets: str | None, movements: int, seed: int) -> dict[str, float]:
        w = workers[name]
        assert w.stdin is not None and w.stdout is not None
        w.stdin.write(
            json.dumps({"robot": robot, "targets": targets, "movements": movements, "seed": seed}) + "\n"
        )
        w.stdin.flush()
        return json.loads(w.stdout.readline())

    robots = args.robots.split(",")
    region = f"workspace:fraction={args.fraction!r}"
    cases = [(r, region, args.movements) for r in robots] + [(r, None, args.preset_movements) for r in robots]

    def runs(name: str, targets: str | None) -> bool:
        return not (name == "old" and args.old_presets_only and targets is not None)

    for name in trees:  # warm-up: compile or load every kernel once
        for robot, targets, _ in cases:
            if runs(name, targets):
                ask(name, robot, targets, 200, 0)
    results: dict[tuple[str, str, str], list[dict[str, float]]] = {}
    for rnd in range(args.rounds):
        order = ("old", "new") if rnd % 2 == 0 else ("new", "old")
        for robot, targets, movements in cases:
            for name in order:
                if runs(name, targets):
                    key = (robot, targets or "preset", name)
                    results.setdefault(key, []).append(ask(name, robot, targets, movements, rnd))
    print(f"load average {os.getloadavg()[0]:.1f}; us per step (thread CPU), median of {args.rounds} rounds")
    print("robot | run | old us (K, parts) | new us (K, parts) | new/old")
    median: dict[tuple[str, str, str], float] = {}
    for robot, targets, _ in cases:
        kind = targets or "preset"
        cells = []
        for name in trees:
            rows = results.get((robot, kind, name))
            if not rows:
                cells.append("-")
                continue
            median[(robot, kind, name)] = us = statistics.median(r["us"] for r in rows)
            K = statistics.median(r["K"] for r in rows)
            cells.append(f"{us:.2f} ({K:.0f}, {rows[0]['parts']})")
        pair = [median.get((robot, kind, name)) for name in trees]
        ratio = f"{pair[1] / pair[0]:.2f}" if None not in pair else "-"
        print(f"{robot} | {kind} | {cells[0]} | {cells[1]} | {ratio}")
    print("robot | new region / new preset | new region / old preset")
    for robot in robots:
        region_us = median[(robot, region, "new")]
        print(
            f"{robot} | {region_us / median[(robot, 'preset', 'new')]:.2f} | "
            f"{region_us / median[(robot, 'preset', 'old')]:.2f}"
        )
    for w in workers.values():
        assert w.stdin is not None
        w.stdin.close()
        w.wait()


if __name__ == "__main__":
    sys.exit(main())
