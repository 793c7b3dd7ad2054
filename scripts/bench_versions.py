"""Per-step cost of two gb_pin trees, measured alternately in one run (old, new, new, old, ...).

On a noisy machine only an alternating comparison is fair. One long-lived worker process per
tree (each with its own, warm, numba cache) times the compiled loop alone (``BabbleState.run``,
with E^X recorded only at the end, and on the default schedule), and the two workers are asked in
turn, many times, so that drifts of the machine's load hit both alike. Prints the median us/step
per robot and the ratio new/old, and checks that both trees compute the same final E^X.

    python scripts/bench_versions.py --old /path/to/old/tree --rounds 15

The old tree is any checkout of gb_pin (e.g. ``git worktree add ../old <commit>``): its state class
is ``gb_pin.learn.state.BabbleState`` or, for 0.1, ``gb_pin.babbling.BabbleState``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any

WORKER = """
import json, sys, time
import importlib, inspect
import gb_pin
# The 0.1 layout has gb_pin/babbling.py; import only the module that exists in this tree (an
# editable install elsewhere would otherwise answer for a missing one).
state = importlib.import_module("gb_pin.babbling" if sys.argv[1] == "0.1" else "gb_pin.learn.state")
BabbleState = state.BabbleState
source = inspect.getsourcefile(BabbleState)
targets = {}
for line in sys.stdin:
    robot, movements, seed, evaluate = line.split()
    movements, seed = int(movements), int(seed)
    if robot not in targets:
        targets[robot] = gb_pin.load_robot(robot)
    target = targets[robot]
    config = gb_pin.GoalBabbling()._resolve(target.n_joints)
    schedule = None if evaluate == "1" else [0, movements]
    st = BabbleState.start(target, target.targets, movements, config, seed=seed, schedule=schedule)
    start = time.perf_counter()
    st.run(movements)
    wall = time.perf_counter() - start
    out = {"file": source, "us": 1e6 * wall / st.steps, "error": float(st.errors[-1])}
    print(json.dumps(out), flush=True)
"""


class Worker:
    """A process of one tree answering timing requests."""

    def __init__(self, tree: Path) -> None:
        env = {**os.environ, "PYTHONPATH": str(tree)}
        self.tree = tree
        layout = "0.1" if (tree / "gb_pin" / "babbling.py").exists() else "current"
        self.proc = subprocess.Popen(
            [sys.executable, "-c", WORKER, layout], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
            env=env, cwd=tree,
        )  # fmt: skip

    def time(self, robot: str, movements: int, seed: int, evaluate: bool) -> dict[str, Any]:
        """One timed run of the compiled loop."""
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(f"{robot} {movements} {seed} {int(evaluate)}\n")
        self.proc.stdin.flush()
        out = json.loads(self.proc.stdout.readline())
        if not out["file"].startswith(str(self.tree)):
            raise SystemExit(f"{self.tree}: imported BabbleState from {out['file']}")
        return out

    def close(self) -> None:
        """End the worker."""
        assert self.proc.stdin is not None
        self.proc.stdin.close()
        self.proc.wait(timeout=60)


def main(argv: list[str] | None = None) -> int:
    """Alternate the two trees for --rounds rounds per robot and print the medians."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old", type=Path, required=True, help="the tree to compare against")
    parser.add_argument("--new", type=Path, default=Path(__file__).resolve().parents[1])
    parser.add_argument("--robots", default="planar5,planar20,planar50,talos_left_arm,panda")
    parser.add_argument("--movements", type=int, default=2000)
    parser.add_argument("--rounds", type=int, default=15)
    args = parser.parse_args(argv)
    workers = {"old": Worker(args.old.resolve()), "new": Worker(args.new.resolve())}
    robots = args.robots.split(",")
    for w in workers.values():  # compile or load the kernels, build the robots: not timed
        for robot in robots:
            w.time(robot, 5, 0, True)
    times: dict[tuple[str, str, bool], list[float]] = {}
    same = True
    for r in range(args.rounds):
        for robot in robots:
            for evaluate in (False, True):
                order = ("old", "new") if (r + robots.index(robot)) % 2 == 0 else ("new", "old")
                errors = []
                for name in order:
                    out = workers[name].time(robot, args.movements, r, evaluate)
                    times.setdefault((name, robot, evaluate), []).append(out["us"])
                    errors.append(out["error"])
                same = same and errors[0] == errors[1]
    for w in workers.values():
        w.close()
    print(f"{args.rounds} alternating rounds of {args.movements} movements per robot (compiled loop only)")
    print("| robot | old us/step | new us/step | new/old | old (eval) | new (eval) | new/old (eval) |")
    print("|---|---|---|---|---|---|---|")
    for robot in robots:
        med = {(k, e): statistics.median(times[(k, robot, e)]) for k in ("old", "new") for e in (False, True)}
        print(
            f"| {robot} | {med['old', False]:.2f} | {med['new', False]:.2f} "
            f"| {med['new', False] / med['old', False]:.3f} "
            f"| {med['old', True]:.2f} | {med['new', True]:.2f} "
            f"| {med['new', True] / med['old', True]:.3f} |"
        )
    print(f"same final E^X in every pair: {same}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
