"""Goal babbling on arms simulated by MuJoCo: URDF IK vs learned inverse vs feedback (docs/SIMULATION.md).

Each run babbles ``--movements`` movements on a :class:`gb_pin.sim.MujocoPlant` (servos of gain kp,
gravity on, a settling rule), then reaches a test grid (3 x 3 x 3 over 3/4 of the goal box's
half-width: not the goal set) three ways, each executed on the simulated arm and measured where
it comes to rest (``plant.true_forward``: no lag, no noise):

- ``urdf``: exact IK on the robot's URDF (``gb_pin.ik.solve(plant.target, X, seed="home", tol=1e-9)``);
- ``learned``: the learned inverse, open loop, g(x*) clipped to the limits;
- ``feedback``: g(x*) then three corrections with the learned Jacobian from 1, 1 and 3 readings
  (``gb_pin.learn.feedback.reach``), the readings asked of the simulated arm.

Writes ``--out``/simulation.json (every run), simulation.md (the tables) and simulation.png (the
figure: reach error over servo stiffness, and over the settling time).

    python scripts/simulation_experiment.py --out docs/figures/simulation --workers 1
    python scripts/simulation_experiment.py --out docs/figures/simulation --bench   # per-ask cost
    python scripts/simulation_experiment.py --out docs/figures/simulation --floor   # no plant: learner alone
    python scripts/simulation_experiment.py --out /tmp/sim --quick      # 1 seed, 300 movements: a smoke test
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import time
from typing import Any

import numpy as np

MOVEMENTS = 3000
# (robot, kp [N m/rad], plant options, seeds): the runs of each table.
ACCEPTANCE = {"so101": (10.0,), "panda": (300.0, 1000.0)}  # 10 seeds each
STIFFNESS = {"so101": (3.0, 10.0, 30.0), "panda": (300.0, 1000.0, 3000.0)}
PERIODS = (0.02, 0.05, 0.1, 0.2, 0.4)  # fixed holds [s] of the settling study (SO-101, kp 10)


def test_grid(plant: Any) -> np.ndarray:
    """3 x 3 x 3 points over 3/4 of the goal box's half-width, around its centre (not the goal set)."""
    goals = plant.targets
    lo, hi = goals.min(axis=0), goals.max(axis=0)
    centre, half = (lo + hi) / 2, 0.75 * (hi - lo) / 2
    axes = [np.linspace(c - h, c + h, 3) for c, h in zip(centre, half, strict=True)]
    return np.array(np.meshgrid(*axes, indexing="ij")).reshape(3, -1).T.copy()


def one_run(job: dict[str, Any]) -> dict[str, Any]:
    """Babble on one plant and measure the three reaches; returns the run's numbers."""
    import gb_pin
    from gb_pin.ik import solve
    from gb_pin.learn.feedback import reach
    from gb_pin.sim import MujocoPlant

    plant = MujocoPlant(job["robot"], **job["plant"])
    X = test_grid(plant)
    home = plant.target.forward(plant.home)
    sag = plant.true_forward(plant.home) - home
    start = time.perf_counter()
    result = gb_pin.babble(
        plant, movements=job["movements"], seed=job["seed"], schedule=[0, job["movements"]]
    )
    wall = time.perf_counter() - start
    asks, steps = plant.asks, plant.steps

    def errors(Q: np.ndarray) -> list[float]:
        return np.linalg.norm(plant.true_forward(Q) - X, axis=1).tolist()

    urdf = solve(plant.target, X, seed="home", tol=1e-9)
    learned = np.clip(result.inverse(X), plant.lower, plant.upper)
    fed = reach(result.model, X, plant.forward, plant.lower, plant.upper, observations=(1, 1, 3))
    return {
        **job,
        "sag": sag.tolist(),
        "urdf": errors(urdf.postures),
        "urdf_solved": bool(np.all(urdf.success)),
        "learned": errors(learned),
        "feedback": errors(fed.postures),
        "wall": wall,
        "asks": asks,
        "steps": steps,
        "error": result.error,
    }


def jobs(seeds: int, movements: int) -> list[dict[str, Any]]:
    """Every run of the study: acceptance (``seeds`` seeds), stiffness and settling (3 seeds)."""
    out: list[dict[str, Any]] = []

    def add(study: str, robot: str, plant: dict[str, Any], n: int) -> None:
        out.extend({"study": study, "robot": robot, "plant": plant, "seed": s, "movements": movements}
                   for s in range(n))  # fmt: skip

    few = min(seeds, 3)
    for robot, gains in ACCEPTANCE.items():
        for kp in gains:
            add("acceptance", robot, {"kp": kp}, seeds)
    for robot, gains in STIFFNESS.items():
        for kp in gains:
            if kp not in ACCEPTANCE[robot]:
                add("stiffness", robot, {"kp": kp}, few)
    for period in PERIODS:
        add("settling", "so101", {"kp": 10.0, "period": period}, few)
    return out


def summary(runs: list[dict[str, Any]]) -> str:
    """The tables of docs/SIMULATION.md (Markdown): medians over the test grid, then over seeds."""
    lines = []

    def row(label: str, group: list[dict[str, Any]]) -> str:
        med = {k: [float(np.median(r[k])) for r in group] for k in ("urdf", "learned", "feedback")}
        sag = np.array(group[0]["sag"]) * 1e3
        ask = 1e6 * float(np.median([r["wall"] / r["asks"] for r in group]))
        steps = float(np.median([r["steps"] / r["asks"] for r in group]))

        def mm(v: list[float]) -> str:
            return f"{1e3 * np.median(v):.2f} ({1e3 * min(v):.2f}-{1e3 * max(v):.2f})"

        ratio = np.median(med["urdf"]) / np.median(med["learned"])
        cells = [label, str(len(group)), f"({sag[0]:.1f}, {sag[1]:.1f}, {sag[2]:.1f})", mm(med["urdf"]),
                 mm(med["learned"]), mm(med["feedback"]), f"{ratio:.1f}", f"{steps:.0f}",
                 f"{ask:.0f}"]  # fmt: skip
        return "| " + " | ".join(cells) + " |"

    names = ["plant", "seeds", "sag at home [mm]", "URDF IK [mm]", "learned [mm]", "feedback [mm]",
             "URDF / learned", "steps per ask", "us per ask"]  # fmt: skip
    header = "| " + " | ".join(names) + " |\n" + "|---" * len(names) + "|"
    for study in ("acceptance", "stiffness", "settling"):
        group = [
            r for r in runs if r["study"] == study or (study == "stiffness" and r["study"] == "acceptance")
        ]
        if not group:
            continue
        lines += [f"\n### {study}\n", header]
        keys = sorted({(r["robot"], json.dumps(r["plant"], sort_keys=True)) for r in group})
        for robot, plant in keys:
            members = [
                r for r in group if r["robot"] == robot and json.dumps(r["plant"], sort_keys=True) == plant
            ]
            label = f"{robot} " + ", ".join(f"{k} {v:g}" for k, v in json.loads(plant).items())
            lines.append(row(label, members))
    return "\n".join(lines) + "\n"


def figure(runs: list[dict[str, Any]], path: str) -> None:
    """Reach error over servo stiffness (SO-101, Panda) and over the settling time (SO-101, kp 10)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, NullFormatter

    colours = {"urdf": "tab:red", "learned": "tab:blue", "feedback": "tab:green"}
    names = {"urdf": "exact IK on the URDF", "learned": "learned inverse (open loop)",
             "feedback": "learned + 3 feedback corrections"}  # fmt: skip

    def medians(group: list[dict[str, Any]], key: str) -> list[float]:
        return [1e3 * float(np.median(r[key])) for r in group]  # per seed: median over the test grid [mm]

    def axis(ax: Any, ticks: list[float], xlabel: str, title: str) -> None:
        ax.set(xscale="log", yscale="log", xlabel=xlabel, ylabel="median reach error [mm]", title=title)
        ax.set_xticks(ticks, [f"{t:g}" for t in ticks])
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.grid(True, which="both", alpha=0.3)

    fig, axes = plt.subplots(1, 3, figsize=(14, 4.8), constrained_layout=True)
    for ax, robot in zip(axes[:2], ("so101", "panda"), strict=True):
        group = [r for r in runs if r["robot"] == robot and r["study"] in ("acceptance", "stiffness")]
        gains = sorted({r["plant"]["kp"] for r in group})
        for key, colour in colours.items():
            per = [medians([r for r in group if r["plant"]["kp"] == kp], key) for kp in gains]
            ax.plot(gains, [np.median(p) for p in per], "o-", color=colour, label=names[key])
            ax.fill_between(gains, [min(p) for p in per], [max(p) for p in per], color=colour, alpha=0.2)
        axis(ax, gains, "servo gain kp [N m/rad]", f"{robot}: stiffness (settle until at rest)")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncol=3, fontsize=9)
    ax = axes[2]
    group = [r for r in runs if r["study"] == "settling"]
    periods = sorted({r["plant"]["period"] for r in group})
    rest = [r for r in runs if r["study"] == "acceptance" and r["robot"] == "so101"]
    held = float(np.median([r["steps"] / r["asks"] for r in rest])) * 0.002 if rest else None
    for key, colour in colours.items():
        per = [medians([r for r in group if r["plant"]["period"] == p], key) for p in periods]
        ax.plot(periods, [np.median(p) for p in per], "o-", color=colour)
        if held is not None:
            ax.plot([held], [np.median(medians(rest, key))], "*", ms=15, color=colour, mec="black", mew=0.5)
    ax.plot([], [], "*", ms=12, color="grey", mec="black", mew=0.5, label="settle until at rest (default)")
    ax.plot([], [], "o-", color="grey", label="fixed hold per ask")
    ax.legend(loc="upper right", fontsize=8)
    axis(ax, periods, "hold per ask [s]", "so101, kp 10: readings taken too early")
    fig.suptitle("Simulated in MuJoCo, 3000 movements: median reach error on a test grid "
                 "(line: median over seeds, band: their range)", fontsize=11)  # fmt: skip
    fig.savefig(path, dpi=120)


def bench(rounds: int = 5, movements: int = 200) -> str:
    """Per-ask cost of the plant alone: a babbling run's asks replayed on a fresh plant, ``rounds`` times.

    Returns a Markdown table: us per ask (median and range over rounds), MuJoCo steps per ask, us per step.
    """
    import gb_pin
    from gb_pin.sim import MujocoPlant

    lines = ["| plant | us per ask | steps per ask | us per step |", "|---|---|---|---|"]
    for robot, options in [("so101", {"kp": 10.0}), ("panda", {"kp": 1000.0}),
                           ("so101", {"kp": 10.0, "period": 0.02})]:  # fmt: skip
        plant = MujocoPlant(robot, **options)
        session = gb_pin.babble_session(plant, movements=movements, seed=0, schedule=[0, movements])
        asked = []
        while not session.done:
            q = session.ask()
            asked.append(q)
            session.tell(plant.forward(q))
        times, steps = [], 0
        for _ in range(rounds):
            fresh = MujocoPlant(robot, **options)
            start = time.perf_counter()
            for q in asked:
                fresh.forward(q)
            times.append((time.perf_counter() - start) / len(asked))
            steps = fresh.steps
        per_ask = 1e6 * np.array(times)
        label = f"{robot} " + ", ".join(f"{k} {v:g}" for k, v in options.items())
        per_step = np.median(per_ask) * len(asked) / steps
        lines.append(f"| {label} | {np.median(per_ask):.0f} ({per_ask.min():.0f}-{per_ask.max():.0f}) | "
                     f"{steps / len(asked):.0f} | {per_step:.2f} |")  # fmt: skip
    return "\n".join(lines) + "\n"


def floor(seeds: int = 10, movements: int = MOVEMENTS) -> str:
    """The learned inverse on the kinematic robots themselves (no plant): the learner's own accuracy.

    Returns a Markdown table: the median reach error on the same test grid, median and range over seeds.
    """
    import gb_pin

    lines = ["| robot (kinematic) | seeds | learned [mm] |", "|---|---|---|"]
    for robot in ACCEPTANCE:
        target = gb_pin.load_robot(robot)
        X = test_grid(target)
        per = []
        for seed in range(seeds):
            result = gb_pin.babble(robot, movements=movements, seed=seed, schedule=[0, movements])
            Q = np.clip(result.inverse(X), target.lower, target.upper)
            per.append(1e3 * float(np.median(np.linalg.norm(target.forward(Q) - X, axis=1))))
        lines.append(f"| {robot} | {seeds} | {np.median(per):.2f} ({min(per):.2f}-{max(per):.2f}) |")
    return "\n".join(lines) + "\n"


def _key(run: dict[str, Any]) -> str:
    return json.dumps(
        [run["study"], run["robot"], run["plant"], run["seed"], run["movements"]], sort_keys=True
    )


def main() -> None:
    """Run the study (or ``--quick``), write the JSON, the tables and the figure."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--seeds", type=int, default=10, help="seeds of the acceptance runs (others: 3)")
    parser.add_argument("--movements", type=int, default=MOVEMENTS)
    parser.add_argument("--workers", type=int, default=1, help="processes (the 2-core machine is shared)")
    parser.add_argument("--quick", action="store_true", help="1 seed, 300 movements (smoke test)")
    parser.add_argument("--figure-only", action="store_true", help="redraw from the JSON of --out")
    parser.add_argument("--bench", action="store_true", help="time the plant per ask (simulation_bench.md)")
    parser.add_argument("--floor", action="store_true", help="the learner, no plant (simulation_floor.md)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    if args.bench or args.floor:
        table, name = (bench(), "simulation_bench.md") if args.bench else (floor(), "simulation_floor.md")
        with open(os.path.join(args.out, name), "w") as fh:
            fh.write(table)
        print(table)
        return
    store = os.path.join(args.out, "simulation.json")
    if args.figure_only:
        with open(store) as fh:
            runs = json.load(fh)["runs"]
    else:
        todo = jobs(1, 300) if args.quick else jobs(args.seeds, args.movements)
        journal = os.path.join(args.out, "simulation.jsonl")  # finished runs, kept if the study stops
        runs = []
        if os.path.exists(journal):
            with open(journal) as fh:
                runs = [json.loads(line) for line in fh if line.strip()]
        done = {_key(r) for r in runs}
        todo = [job for job in todo if _key(job) not in done]
        start = time.perf_counter()
        with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
            for i, run in enumerate(pool.imap_unordered(one_run, todo), 1):
                runs.append(run)
                with open(journal, "a") as fh:
                    fh.write(json.dumps(run) + "\n")
                learned, urdf = 1e3 * np.median(run["learned"]), 1e3 * np.median(run["urdf"])
                print(f"{i}/{len(todo)} {run['study']} {run['robot']} {run['plant']} seed {run['seed']}: "
                      f"learned {learned:.2f} mm, URDF {urdf:.2f} mm, {run['wall']:.0f} s",
                      flush=True)  # fmt: skip
        with open(store, "w") as fh:
            json.dump({"runs": runs, "wall": time.perf_counter() - start}, fh)
    with open(os.path.join(args.out, "simulation.md"), "w") as fh:
        fh.write(summary(runs))
    figure(runs, os.path.join(args.out, "simulation.png"))
    print(summary(runs))


if __name__ == "__main__":
    main()
