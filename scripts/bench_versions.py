r"""Per-step cost of two gb_pin trees, measured alternately in one run (old, new, new, old, ...).

On a noisy machine only an alternating comparison is fair. One long-lived worker process per
tree (each with its own, warm, numba cache) times the compiled loop alone (``BabbleState.run``,
with E^X recorded only at the end, and on the default schedule), and the two workers are asked in
turn, many times, so that drifts of the machine's load hit both alike. Prints the median us/step
per robot and the ratio new/old, and checks that both trees compute the same final E^X. The
clock is the worker thread's CPU time (``--clock wall`` for the wall clock): on a shared machine
the wall clock also counts the time other processes hold the core.

    python scripts/bench_versions.py --old /path/to/old/tree --rounds 15

Continuing a learned run (the cost per step of a large map): ``--learned 10000`` learns 10^4
movements first (not timed, once per worker), then times ``--movements`` more from that state
in every round; ``--until-prototypes 50,100,300,800`` learns until the map has that many
prototypes instead (one row each; at most ``--learn-limit`` movements); ``--goals
uniform,directions`` and ``--radius 0.1,0.05`` (one row each) and ``--preset-learner`` choose the
run. The check is then that both trees end with the same predictions.

    python scripts/bench_versions.py --old ../old --robots panda --preset-learner \
        --goals uniform,directions --learned 10000 --movements 1000

The old tree is any checkout of gb_pin (e.g. ``git worktree add ../old <commit>``): its state class
is ``gb_pin.learn.state.BabbleState`` or, for 0.1, ``gb_pin.babbling.BabbleState``.
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any

WORKER = """
import json, sys, time, warnings
import importlib, inspect
import numpy as np
import gb_pin
warnings.simplefilter("ignore")  # extrapolation warnings of unexplored goals
# The 0.1 layout has gb_pin/babbling.py; import only the module that exists in this tree (an
# editable install elsewhere would otherwise answer for a missing one).
state = importlib.import_module("gb_pin.babbling" if sys.argv[1] == "0.1" else "gb_pin.learn.state")
BabbleState = state.BabbleState
source = inspect.getsourcefile(BabbleState)
targets, learned = {}, {}

def config_of(req, target):
    params = {}
    if req.get("preset_learner"):
        from gb_pin.robot.presets import get_preset
        params.update(get_preset(req["robot"])[0].learner)
    if req.get("radius") is not None:
        params["radius"] = req["radius"]
    return gb_pin.GoalBabbling(**params)._resolve(target.n_joints)

def start(req, target, config, movements, schedule):
    extra = {"goals": req["goals"]} if req.get("goals") else {}
    return BabbleState.start(target, target.targets, movements, config, seed=req["seed"], schedule=schedule,
                             **extra)

def learn(req, target, config):
    # Learn once (seed req["seed"]) until the movement count or the prototype count; keep the arrays.
    key = json.dumps([req[k] for k in ("robot", "goals", "radius", "preset_learner", "seed", "learn")])
    if key not in learned:
        st = start(req, target, config, 10**9, [0])
        kind, value = req["learn"]
        if kind == "movements":
            st.run(value)
        else:  # until K prototypes, or until the movement limit (uniform goals stop growing the map)
            while st.llm.n_prototypes_ < value and st.movements < req["learn_limit"]:
                st.run(st.movements + 20)
        learned[key] = (st.to_arrays(), st.rng_state(), st.movements, st.llm.n_prototypes_)
    return learned[key]

for line in sys.stdin:
    req = json.loads(line)
    robot, movements = req["robot"], req["movements"]
    if robot not in targets:
        targets[robot] = gb_pin.load_robot(robot)
    target = targets[robot]
    config = config_of(req, target)
    if req.get("learn") is None:
        schedule = None if req["evaluate"] else [0, movements]
        st = start(req, target, config, movements, schedule)
        start_k, before = 1, 0
    else:
        arrays, rng_state, before, start_k = learn(req, target, config)
        st = BabbleState.from_arrays(arrays, config, rng_state, goals=req.get("goals"))
    steps = st.steps
    t0, c0 = time.perf_counter(), time.thread_time()
    st.run(before + movements)
    wall, cpu = time.perf_counter() - t0, time.thread_time() - c0
    if req.get("learn") is None:
        check = float(st.errors[-1])
    else:
        check = float(np.sum(st.llm.predict(st.targets, warn=False)))
    seconds = cpu if req["clock"] == "cpu" else wall
    out = {"file": source, "us": 1e6 * seconds / (st.steps - steps), "check": check,
           "prototypes": [int(start_k), int(st.llm.n_prototypes_)], "learned": int(before)}
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

    def time(self, request: dict[str, Any]) -> dict[str, Any]:
        """One timed run of the compiled loop."""
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(json.dumps(request) + "\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        if not line:
            raise SystemExit(f"{self.tree}: the worker ended (see its error above)")
        out = json.loads(line)
        if not out["file"].startswith(str(self.tree)):
            raise SystemExit(f"{self.tree}: imported BabbleState from {out['file']}")
        return out

    def close(self) -> None:
        """End the worker."""
        assert self.proc.stdin is not None
        self.proc.stdin.close()
        self.proc.wait(timeout=60)


def cases(args: argparse.Namespace) -> list[dict[str, Any]]:
    """One request template per row of the table: robots x goal generators x radii (x prototype counts)."""
    common = {"preset_learner": args.preset_learner, "clock": args.clock, "learn_limit": args.learn_limit}
    goals = args.goals.split(",") if args.goals else [None]
    radii = [float(r) for r in args.radius.split(",")] if args.radius else [None]
    out = []
    for robot, goal, radius in itertools.product(args.robots.split(","), goals, radii):
        case = {"robot": robot, "goals": goal, "radius": radius, **common}
        if args.until_prototypes:
            out += [{**case, "learn": ["prototypes", int(k)]} for k in args.until_prototypes.split(",")]
        elif args.learned:
            out.append({**case, "learn": ["movements", args.learned]})
        else:
            out.append({**case, "learn": None})
    return out


def main(argv: list[str] | None = None) -> int:
    """Alternate the two trees for --rounds rounds per case and print the medians."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old", type=Path, required=True, help="the tree to compare against")
    parser.add_argument("--new", type=Path, default=Path(__file__).resolve().parents[1])
    parser.add_argument("--robots", default="planar5,planar20,planar50,talos_left_arm,panda")
    parser.add_argument("--movements", type=int, default=2000)
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--goals", default=None, help="goal generators, one row each: uniform,directions,...")
    parser.add_argument("--radius", default=None, help="prototype radii d [m], one row each: 0.1,0.05")
    parser.add_argument("--preset-learner", action="store_true", help="use the presets' [learner] defaults")
    parser.add_argument("--learned", type=int, default=0, help="learn this many movements first (not timed)")
    parser.add_argument("--until-prototypes", default="", help="learn until K prototypes first: K1,K2,...")
    parser.add_argument("--learn-limit", type=int, default=100_000, help="--until-prototypes: at most this")
    parser.add_argument(
        "--clock",
        choices=("cpu", "wall"),
        default="cpu",
        help="time the worker's thread CPU time (default: what a quiet machine's wall clock "
        "would show, without the time other processes hold the core) or the wall clock",
    )
    args = parser.parse_args(argv)
    workers = {"old": Worker(args.old.resolve()), "new": Worker(args.new.resolve())}
    todo = cases(args)
    continued = todo[0]["learn"] is not None
    evaluations = (False,) if continued else (False, True)
    for w in workers.values():  # compile or load the kernels, build the robots, learn: not timed
        for case in todo:
            w.time({**case, "movements": 5, "seed": 0, "evaluate": True})
    times: dict[tuple[str, int, bool], list[float]] = {}
    info: dict[int, dict[str, Any]] = {}
    same = True
    for r in range(args.rounds):
        for c, case in enumerate(todo):
            for evaluate in evaluations:
                order = ("old", "new") if (r + c) % 2 == 0 else ("new", "old")
                checks = []
                for name in order:
                    seed = 0 if continued else r  # a continued run always starts from the learned state
                    out = workers[name].time({**case, "movements": args.movements, "seed": seed,
                                              "evaluate": evaluate})  # fmt: skip
                    times.setdefault((name, c, evaluate), []).append(out["us"])
                    checks.append(out["check"])
                    info.setdefault(c, {})[name] = out
                same = same and checks[0] == checks[1]
    for w in workers.values():
        w.close()
    what = "continuing a learned run" if continued else "compiled loop only"
    print(f"{args.rounds} alternating rounds of {args.movements} movements per case ({what}; {args.clock})")
    if continued:
        print(
            "| robot | goals | d [m] | learned movements | prototypes (old) | prototypes (new) | old us/step "
            "| new us/step | new/old |"
        )
        print("|---|---|---|---|---|---|---|---|---|")
    else:
        print("| robot | old us/step | new us/step | new/old | old (eval) | new (eval) | new/old (eval) |")
        print("|---|---|---|---|---|---|---|")
    for c, case in enumerate(todo):
        med = {(k, e): statistics.median(times[(k, c, e)]) for k in ("old", "new") for e in evaluations}
        ratio = med["new", False] / med["old", False]
        if continued:
            o, n = info[c]["old"], info[c]["new"]
            k_old, k_new = ("-".join(map(str, out["prototypes"])) for out in (o, n))
            print(
                f"| {case['robot']} | {case['goals'] or 'uniform'} | {case['radius'] or 'preset'} "
                f"| {n['learned']} | {k_old} | {k_new} "
                f"| {med['old', False]:.2f} | {med['new', False]:.2f} | {ratio:.3f} |"
            )
        else:
            print(
                f"| {case['robot']} | {med['old', False]:.2f} | {med['new', False]:.2f} | {ratio:.3f} "
                f"| {med['old', True]:.2f} | {med['new', True]:.2f} "
                f"| {med['new', True] / med['old', True]:.3f} |"
            )
    print(f"same final {'predictions' if continued else 'E^X'} in every pair: {same}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
