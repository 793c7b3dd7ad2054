r"""Per-query IK time of two gb_pin trees in the field's protocol, measured alternately in one run.

docs/IK.md's protocol (Panda, 6-D poses of postures drawn uniformly within the limits, a learned
seed, a 5 ms budget with restarts, tolerance 1e-5): one long-lived worker per tree learns the same
map (seeded), then solves the same targets, and the two are asked in turn so that the machine's
load hits both alike. Prints the median over rounds of the mean per-query CPU time and of the
success rate, and checks that both trees give the same postures for a deterministic setting
(restarts without a timeout).

    python scripts/bench_ik_versions.py --old /path/to/old/tree --rounds 9 --samples 2000
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
import json, sys, warnings
import numpy as np
import gb_pin, gb_pin.ik
from gb_pin.experiments.ik_paths import sample_postures
from gb_pin.experiments.ik_protocol import _learn, protocol_target
warnings.simplefilter("ignore")
robot, task, samples = sys.argv[1], sys.argv[2], int(sys.argv[3])
target = protocol_target(robot, task)
model = _learn(target, 3000, np.random.default_rng([0, 1]))
X = target.forward(sample_postures(target, samples, np.random.default_rng(0)))
fixed = gb_pin.ik.solve(target, X[:200], model=model, seed="learned", max_restarts=3, rng=0, tol=1e-5,
                        angle_tol=1e-5)
for line in sys.stdin:
    sol = gb_pin.ik.solve(target, X, model=model, seed="learned", timeout=5e-3, rng=0, tol=1e-5,
                          angle_tol=1e-5, max_iterations=50, backtracks=0, clock="cpu")
    out = {"file": gb_pin.ik.solve.__code__.co_filename, "us": 1e6 * float(np.mean(sol.seconds)),
           "success": float(np.mean(sol.success)), "check": float(np.nansum(fixed.postures))}
    print(json.dumps(out), flush=True)
"""


def worker(tree: Path, args: argparse.Namespace) -> subprocess.Popen[str]:
    """A process of ``tree`` that learns the map and solves the targets at each request."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    return subprocess.Popen(
        [sys.executable, "-c", WORKER, args.robot, args.task, str(args.samples)],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env, cwd=tree,
    )  # fmt: skip


def ask(proc: subprocess.Popen[str], tree: Path) -> dict[str, Any]:
    """One timed solve of all targets."""
    assert proc.stdin is not None and proc.stdout is not None
    proc.stdin.write("go\n")
    proc.stdin.flush()
    line = proc.stdout.readline()
    if not line:
        raise SystemExit(f"{tree}: the worker ended")
    out: dict[str, Any] = json.loads(line)
    if not out["file"].startswith(str(tree)):
        raise SystemExit(f"{tree}: imported gb_pin from {out['file']}")
    return out


def main() -> int:
    """Alternate the trees for --rounds rounds; print medians and the ratio new/old."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old", type=Path, required=True)
    parser.add_argument("--new", type=Path, default=Path(__file__).resolve().parents[1])
    parser.add_argument("--robot", default="panda")
    parser.add_argument("--task", default="pose")
    parser.add_argument("--samples", type=int, default=2000)
    parser.add_argument("--rounds", type=int, default=9)
    args = parser.parse_args()
    trees = {"old": args.old.resolve(), "new": args.new.resolve()}
    procs = {k: worker(t, args) for k, t in trees.items()}
    got: dict[str, list[dict[str, Any]]] = {"old": [], "new": []}
    for r in range(args.rounds):
        for k in ("old", "new") if r % 2 == 0 else ("new", "old"):
            got[k].append(ask(procs[k], trees[k]))
    for p in procs.values():
        assert p.stdin is not None
        p.stdin.close()
        p.wait(timeout=60)
    us = {k: statistics.median(o["us"] for o in v) for k, v in got.items()}
    success = {k: statistics.median(o["success"] for o in v) for k, v in got.items()}
    same = got["old"][0]["check"] == got["new"][0]["check"]
    print(
        f"{args.robot} {args.task}, {args.samples} targets, {args.rounds} rounds (median of per-round means):"
    )
    print(f"  old {us['old']:.1f} us/query, success {100 * success['old']:.2f} %")
    print(f"  new {us['new']:.1f} us/query, success {100 * success['new']:.2f} %")
    print(f"  new/old {us['new'] / us['old']:.3f}; deterministic postures identical: {same}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
