"""Pose, pointing and bimanual goal babbling over seeds: component errors over movements (docs/TASKS.md).

Runs each condition (preset, hyperparameters) over ``--seeds`` seeds in ``--workers``
processes, measuring every ``--every`` movements the mean position error [m] and the mean
orientation / pointing error [deg] per task component over the preset's targets
(:func:`gb_pin.learn.component_metrics.task_errors`), and the cost per step (wall time of the
run over its time steps, compilation excluded). Writes ``--out`` (JSON) and, with
``--figures DIR``, one figure per preset (median and quartiles over seeds).

    python scripts/tasks_experiments.py --seeds 10 --movements 10000 --out tasks.json --figures docs/figures
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import time
from typing import Any

import numpy as np

CONDITIONS: dict[str, dict[str, Any]] = {
    "pose": {"robot": "talos_left_arm_pose"},
    "pose_d0.15": {"robot": "talos_left_arm_pose", "radius": 0.15},
    "pose_s0.1": {"robot": "talos_left_arm_pose", "orientation_scale": 0.1},
    "pose_s0.3": {"robot": "talos_left_arm_pose", "orientation_scale": 0.3},
    "pose_sigma0.1": {"robot": "talos_left_arm_pose", "sigma": 0.1},
    "pointing": {"robot": "talos_left_arm_pointing"},
    "position": {"robot": "talos_left_arm_pose", "position_only": True},
    "bimanual": {"robot": "talos_bimanual"},
    "bimanual_d0.1": {"robot": "talos_bimanual", "radius": 0.1},
    "bimanual_d0.2": {"robot": "talos_bimanual", "radius": 0.2},
}
HYPER = ("learning_rate", "sigma", "radius")


def _target(condition: dict[str, Any]) -> tuple[Any, np.ndarray, dict[str, Any]]:
    """The robot, its targets and its learner defaults for one condition."""
    from gb_pin.robot.presets import get_preset, load_robot
    from gb_pin.robot.target import KinematicTarget

    robot = load_robot(condition["robot"])
    preset, _ = get_preset(condition["robot"])
    learner = dict(preset.learner)
    targets = robot.targets
    assert targets is not None
    if condition.get("position_only"):  # the same positions, orientation ignored
        targets = targets[:, :3].copy()
        robot = KinematicTarget(robot.full_model, robot.frame, robot.joints, robot.home, name="position")
    elif "orientation_scale" in condition:  # same poses, rows rescaled to the new s
        s_old = float(preset.task["orientation_scale"])
        s_new = float(condition["orientation_scale"])
        robot = KinematicTarget(robot.full_model, robot.frame, robot.joints, robot.home, task="pose",
                                orientation_scale=s_new, name="pose")  # fmt: skip
        targets = targets.copy()
        targets[:, 3:] *= s_new / s_old
    return robot, targets, learner


def run_one(args: tuple[str, dict[str, Any], int, int, int]) -> dict[str, Any]:
    """One seed of one condition: component errors every ``every`` movements, cost per step."""
    from gb_pin.learn.component_metrics import task_errors
    from gb_pin.learn.learner import GoalBabbling
    from gb_pin.learn.state import BabbleState

    name, condition, seed, movements, every = args
    robot, targets, learner = _target(condition)
    params = {**learner, **{k: condition[k] for k in HYPER if k in condition}}
    curve: list[tuple[int, list[float]]] = []

    def observe(state: Any) -> None:
        errors = task_errors(state.llm, robot, targets)
        curve.append((state.movements, errors.mean.tolist()))

    GoalBabbling(**params).fit(robot, targets, 2, seed=seed)  # compile outside the timing
    config = GoalBabbling(**params)._resolve(robot.n_joints)
    start = task_errors(BabbleState.start(robot, targets, 1, config, seed=seed).llm, robot, targets)  # r = 0
    t0 = time.perf_counter()
    fitted = GoalBabbling(**params).fit(
        robot, targets, movements, seed=seed, observer=observe, observe_every=every
    )
    wall = time.perf_counter() - t0
    final = task_errors(fitted.model_, robot, targets)
    return {
        "condition": name,
        "seed": seed,
        "kinds": list(final.kinds),
        "units": list(final.units),
        "start": start.mean.tolist(),
        "movements": [0, *(m for m, _ in curve)],
        "curve": [start.mean.tolist(), *(e for _, e in curve)],
        "final_mean": final.mean.tolist(),
        "final_q90": final.quantile(0.9).tolist(),
        "error_x": float(fitted.history_.error[-1]),
        "prototypes": int(fitted.model_.n_prototypes_),
        "steps": int(fitted.steps_),
        "us_per_step": 1e6 * wall / max(1, fitted.steps_),
    }


def summarize(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Medians over seeds per condition."""
    out: dict[str, Any] = {}
    for name in dict.fromkeys(r["condition"] for r in runs):
        rs = [r for r in runs if r["condition"] == name]
        out[name] = {
            "seeds": len(rs),
            "kinds": rs[0]["kinds"],
            "median_final_mean": np.median([r["final_mean"] for r in rs], axis=0).tolist(),
            "median_final_q90": np.median([r["final_q90"] for r in rs], axis=0).tolist(),
            "median_start": np.median([r["start"] for r in rs], axis=0).tolist(),
            "median_prototypes": float(np.median([r["prototypes"] for r in rs])),
            "median_us_per_step": float(np.median([r["us_per_step"] for r in rs])),
        }
    return out


OVERVIEW = (
    ("pose: position", ("pose", "pose_d0.15", "pose_s0.1", "pose_s0.3", "pose_sigma0.1", "position"), 0),
    ("pose: orientation", ("pose", "pose_d0.15", "pose_s0.1", "pose_s0.3", "pose_sigma0.1"), 1),
    ("pointing: position", ("pointing",), 0),
    ("pointing: approach axis", ("pointing",), 1),
    ("bimanual: left hand", ("bimanual", "bimanual_d0.1", "bimanual_d0.2"), 0),
    ("bimanual: right hand", ("bimanual", "bimanual_d0.1", "bimanual_d0.2"), 1),
)
LABELS = {"pose": "s 0.2, d 0.1 (preset)", "pose_d0.15": "d 0.15", "pose_s0.1": "s 0.1", "pose_s0.3": "s 0.3",
          "pose_sigma0.1": "sigma 0.1", "position": "position only", "pointing": "s 0.2, d 0.1 (preset)",
          "bimanual": "d 0.15 (preset)", "bimanual_d0.1": "d 0.1", "bimanual_d0.2": "d 0.2"}  # fmt: skip


def overview(runs: list[dict[str, Any]], path: str) -> None:
    """The three presets and their variants: median (line) and quartiles (band) over seeds, log scales."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 2, figsize=(10, 10))
    for ax, (title, names, c) in zip(axes.ravel(), OVERVIEW, strict=True):
        for name in names:
            rs = [r for r in runs if r["condition"] == name]
            if not rs:
                continue
            mv = np.asarray(rs[0]["movements"])
            unit = rs[0]["units"][c]
            curves = np.asarray([r["curve"] for r in rs])[:, :, c] * (1000.0 if unit == "m" else 1.0)
            q25, q50, q75 = (np.quantile(curves, q, axis=0) for q in (0.25, 0.5, 0.75))
            ax.fill_between(mv[1:], q25[1:], q75[1:], alpha=0.25)
            ax.plot(mv[1:], q50[1:], label=f"{LABELS.get(name, name)} ({len(rs)} seeds)")
            ax.set_ylabel("mm" if unit == "m" else "deg")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(title)
        ax.set_xlabel("movements")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.suptitle("mean error over the targets: median and quartiles over seeds")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def figures(runs: list[dict[str, Any]], directory: str) -> None:
    """The overview, and one figure per condition: median and quartiles of each component's error."""
    import os

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    overview(runs, os.path.join(directory, "tasks_overview.png"))

    for name in dict.fromkeys(r["condition"] for r in runs):
        rs = [r for r in runs if r["condition"] == name]
        mv = np.asarray(rs[0]["movements"])
        curves = np.asarray([r["curve"] for r in rs])  # seeds x T x C
        kinds, units = rs[0]["kinds"], rs[0]["units"]
        fig, axes = plt.subplots(1, len(kinds), figsize=(4.2 * len(kinds), 3.2), squeeze=False)
        for c, ax in enumerate(axes[0]):
            scale = 1000.0 if units[c] == "m" else 1.0
            q25, q50, q75 = (np.quantile(curves[:, :, c], q, axis=0) * scale for q in (0.25, 0.5, 0.75))
            ax.fill_between(mv, q25, q75, alpha=0.3)
            ax.plot(mv, q50)
            ax.set_xscale("symlog", linthresh=100)
            ax.set_xlabel("movements")
            ax.set_ylabel(f"{kinds[c]} {c} error [{'mm' if units[c] == 'm' else 'deg'}]")
            ax.grid(alpha=0.3)
        fig.suptitle(f"{name}: median and quartiles over {len(rs)} seeds")
        fig.tight_layout()
        fig.savefig(os.path.join(directory, f"tasks_{name}.png"), dpi=90)
        plt.close(fig)


def main() -> None:
    """Parse the arguments, run, write the JSON and the figures, print the summary."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--conditions", nargs="*", default=list(CONDITIONS), choices=list(CONDITIONS))
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--movements", type=int, default=10_000)
    parser.add_argument("--every", type=int, default=250)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", default="tasks.json")
    parser.add_argument("--figures", default=None)
    parser.add_argument("--replot", default=None, help="draw the figures of this JSON file, run nothing")
    parser.add_argument(
        "--overwrite", "--force", action="store_true", help="let --out replace an existing file"
    )
    args = parser.parse_args()
    if not args.replot and args.out is not None:
        from gb_pin._files import check_writable
        from gb_pin.cli.checks import no_clobber
        from gb_pin.exceptions import GbPinError

        try:  # before any work: another study's file is never replaced by accident
            check_writable(args.out, "--out")
            no_clobber(args.out, "--out", args.overwrite)
        except GbPinError as exc:
            parser.exit(2, f"tasks_experiments.py: error: {exc}\n")
    if args.replot:
        with open(args.replot, encoding="utf-8") as f:
            figures(json.load(f)["runs"], args.figures or ".")
        return
    jobs = [
        (n, CONDITIONS[n], s, args.movements, args.every) for n in args.conditions for s in range(args.seeds)
    ]
    with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
        runs = pool.map(run_one, jobs, chunksize=1)
    summary = summarize(runs)
    with open(args.out, "w", encoding="utf-8") as f:
        json.dump({"args": vars(args), "summary": summary, "runs": runs}, f)
    if args.figures:
        figures(runs, args.figures)
    for name, s in summary.items():
        print(name, json.dumps({k: v for k, v in s.items() if k != "kinds"}))


if __name__ == "__main__":
    main()
