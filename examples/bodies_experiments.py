"""Bodies that change while learning: growth, a tool, shrinking, continuous growth, a humanoid's tool.

Every experiment runs ``--seeds`` seeds of planar5 (grid targets of the preset) or talos_left_arm
and compares, by the median E^X over seeds (with the 25-75 % band):

- *continued*: learn ``BEFORE`` movements, change the body (``babble(changes={BEFORE: body})``),
  go on learning, one history throughout;
- *fresh*: a new learner on the changed body, shifted to start at the change;
- *unchanged*: the body that never changed.

    python examples/bodies_experiments.py --out docs/figures/bodies        # about two minutes

It writes one PNG per experiment and ``numbers.json`` there, and prints the table of docs/BODIES.md.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np

import gb_pin
from gb_pin.robot.bodies import scaled, with_tool

BEFORE, AFTER = 1000, 1000  # movements before and after the change
PROBES = (1, 30, 100, 1000)  # movements after the change at which the table reports E^X


def schedule() -> np.ndarray:
    """Every 10th movement, and every movement for 100 movements after the change."""
    return np.unique(np.r_[np.arange(0, BEFORE + AFTER + 1, 10), np.arange(BEFORE, BEFORE + 101)])


def change_experiment(robot: str, make_body: Any, seeds: int) -> dict[str, Any]:
    """Continued / fresh / unchanged E^X curves (seeds, T) for one body change."""
    base = gb_pin.load_robot(robot)
    body = make_body(base)
    at = schedule()
    fresh_at = at[at >= BEFORE] - BEFORE
    curves: dict[str, list[np.ndarray]] = {"continued": [], "fresh": [], "unchanged": []}
    for seed in range(seeds):
        kw: dict[str, Any] = {"seed": seed, "targets": base.targets}
        curves["continued"].append(
            gb_pin.babble(robot, BEFORE + AFTER, changes={BEFORE: body}, schedule=at, **kw).history.error
        )
        curves["fresh"].append(gb_pin.babble(body, AFTER, schedule=fresh_at, **kw).history.error)
        curves["unchanged"].append(gb_pin.babble(robot, BEFORE + AFTER, schedule=at, **kw).history.error)
    return {
        "movements": at,
        "fresh_movements": fresh_at + BEFORE,
        **{k: np.array(v) for k, v in curves.items()},
    }


def summary(data: dict[str, Any]) -> dict[str, float]:
    """Median E^X [m] at the probes after the change (continued, fresh at the same age, unchanged)."""
    mv, fmv = data["movements"], data["fresh_movements"]
    out: dict[str, float] = {"before": float(np.median(data["continued"][:, mv == BEFORE]))}
    for p in PROBES:
        out[f"continued+{p}"] = float(np.median(data["continued"][:, mv == BEFORE + p]))
        out[f"fresh+{p}"] = float(np.median(data["fresh"][:, fmv == BEFORE + p]))
        out[f"unchanged+{p}"] = float(np.median(data["unchanged"][:, mv == BEFORE + p]))
    return out


def continuous_growth(seeds: int, start: float = 0.7, end: float = 1.0, movements: int = 5000,
                      segment: int = 100) -> dict[str, Any]:  # fmt: skip
    """planar5 growing linearly from ``start`` to ``end`` times 1 m over ``movements``, targets scaled alike.

    Each segment of ``segment`` movements continues the last (``babble(init=...)``) on a body
    a little larger; E^X is measured on the current body and targets. Against it: a learner
    that starts afresh on each size would restart from E^X ~ 0.3 m.
    """
    arm = gb_pin.load_robot("planar5")
    assert arm.targets is not None
    n = movements // segment
    factors = np.linspace(start, end, n)
    errors = np.empty((seeds, n + 1))
    grown_at_end = np.empty(seeds)
    for seed in range(seeds):
        result = None
        for i, f in enumerate(factors):
            body = scaled(arm, f, targets=arm.targets * f)
            kw: dict[str, Any] = {"init": result} if result is not None else {"seed": seed}
            result = gb_pin.babble(body, segment, schedule=[0, segment], **kw)
            if i == 0:
                errors[seed, 0] = result.history.error[0]
            errors[seed, i + 1] = result.error
        grown_at_end[seed] = gb_pin.babble(arm, movements, seed=seed, schedule=[0, movements]).error
    return {"movements": np.arange(n + 1) * segment, "growing": errors, "factors": factors,
            "fixed_final": grown_at_end}  # fmt: skip


def plot_change(data: dict[str, Any], title: str, path: Path) -> None:
    """E^X around the change: median and 25-75 % band of the three learners."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for ax, window in zip(axes, ((0, BEFORE + AFTER), (BEFORE - 20, BEFORE + 100)), strict=True):
        lines = (
            ("unchanged", data["movements"], "0.5"),
            ("fresh", data["fresh_movements"], "C1"),
            ("continued", data["movements"], "C0"),
        )
        for key, mv, color in lines:
            e = data[key]
            keep = (mv >= window[0]) & (mv <= window[1])
            lo, med, hi = np.percentile(e[:, keep], [25, 50, 75], axis=0)
            ax.plot(mv[keep], med, color=color, label=key)
            ax.fill_between(mv[keep], lo, hi, color=color, alpha=0.2)
        ax.axvline(BEFORE, color="k", lw=0.8, ls=":")
        ax.set_yscale("log")
        ax.set_xlabel("movements")
        ax.set_ylabel("E^X [m]")
        ax.grid(alpha=0.3)
    axes[0].set_title(title)
    axes[1].set_title("around the change")
    axes[0].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_growth(data: dict[str, Any], path: Path) -> None:
    """E^X of the continuously growing arm (median, 25-75 %), and the arm's size."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4))
    lo, med, hi = np.percentile(data["growing"], [25, 50, 75], axis=0)
    ax.plot(data["movements"], med, color="C0", label="growing 0.7 m -> 1.0 m")
    ax.fill_between(data["movements"], lo, hi, color="C0", alpha=0.2)
    ax.axhline(np.median(data["fixed_final"]), color="0.5", ls="--", label="1.0 m arm, 5000 movements")
    ax.set_yscale("log")
    ax.set_xlabel("movements")
    ax.set_ylabel("E^X [m] (current body and targets)")
    ax.set_title("planar5 growing while it learns")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


EXPERIMENTS = {
    "growth": ("planar5", lambda arm: scaled(arm, 1.15), "planar5: every link +15 % at movement 1000"),
    "tool": ("planar5", lambda arm: with_tool(arm, 0.1), "planar5: a 0.1 m tool at movement 1000"),
    "shrink": ("planar5", lambda arm: scaled(arm, 0.85), "planar5: every link -15 % at movement 1000"),
    "talos_tool": (
        "talos_left_arm",
        lambda arm: with_tool(arm, 0.1),
        "talos_left_arm: a 0.1 m tool at movement 1000",
    ),
}


def main() -> None:
    """Run the experiments, write the figures and numbers, print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/figures/bodies"))
    parser.add_argument("--seeds", type=int, default=20)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    numbers: dict[str, Any] = {"seeds": args.seeds}
    for name, (robot, make, title) in EXPERIMENTS.items():
        data = change_experiment(robot, make, args.seeds)
        numbers[name] = summary(data)
        plot_change(data, title, args.out / f"{name}.png")
    growth = continuous_growth(args.seeds)
    numbers["continuous_growth"] = {
        "start": float(np.median(growth["growing"][:, 0])),
        "end": float(np.median(growth["growing"][:, -1])),
        "fixed_1m_after_5000": float(np.median(growth["fixed_final"])),
    }
    plot_growth(growth, args.out / "continuous_growth.png")
    numbers["wall_s"] = time.perf_counter() - start
    (args.out / "numbers.json").write_text(json.dumps(numbers, indent=1) + "\n")
    print(
        f"median E^X [m] over {args.seeds} seeds; +k: k movements after the change (fresh: k movements old)"
    )
    head = ["experiment", "before", "continued +1", "+30", "+100", "+1000", "fresh +30", "+100", "+1000"]
    print("| " + " | ".join([*head, "unchanged +1000"]) + " |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name in EXPERIMENTS:
        s = numbers[name]
        row = [s["before"], s["continued+1"], s["continued+30"], s["continued+100"], s["continued+1000"],
               s["fresh+30"], s["fresh+100"], s["fresh+1000"], s["unchanged+1000"]]  # fmt: skip
        print(f"| {name} | " + " | ".join(f"{v:.4f}" for v in row) + " |")
    print(json.dumps(numbers["continuous_growth"]), f"wall {numbers['wall_s']:.0f} s")


if __name__ == "__main__":
    main()
