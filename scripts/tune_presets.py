"""How the presets' homes and learner defaults were chosen: the measurements behind docs/ROBOTS.md.

    python scripts/tune_presets.py --out tune.md       # every spatial preset
    python scripts/tune_presets.py --robots romeo_right_arm --seeds 10

Each preset's rows are printed as soon as they are measured, and ``--out`` rewrites the three tables
after every preset, so an interrupted run keeps what it measured; a preset that fails is reported
and skipped. Stacked tasks (pose, pointing, two hands) learn their own task vector; their
"relative" coordinates row is left out (only position axes can be shifted).

For each spatial preset it prints two markdown tables:

1. homes: the model's reference posture (half_sitting, or the SRDF's only configuration, or
   neutral) against the preset's home: where the hand is, the half-width of the largest
   reachable 3 x 3 x 3 grid around it ("auto"), and E^X / E_0 after 1000 and 3000 movements
   (median and worst over the seeds) learning the preset's targets with its learner defaults;
2. learner defaults: on the preset's home and targets, the paper's defaults (radius 0.1 m,
   sigma by Eq. 12) and the preset's, then the preset's radius and sigma halved and
   doubled one at a time;
3. task coordinates: world coordinates (what gb_pin uses) against coordinates relative to
   the home effector position (the chain and the targets shifted), same seeds.
"""

from __future__ import annotations

import argparse
import dataclasses
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np

import gb_pin
from gb_pin import KinematicTarget
from gb_pin.learn.config import default_sigma
from gb_pin.robot.presets import get_preset
from gb_pin.robot.targets_auto import auto_grid

MOVEMENTS = (1000, 3000)


def reference_target(name: str) -> KinematicTarget:
    """The preset's robot, frame and joints with the model's reference posture as home."""
    preset, _ = get_preset(name)
    return KinematicTarget.from_example_robot_data(
        preset.robot, preset.frame, list(preset.joints), None, preset.axes, label=name, onboard=False,
        **preset.task,
    )  # fmt: skip


@dataclasses.dataclass(frozen=True)
class Shifted:
    """A robot whose task coordinates are relative to ``origin`` (the chain's root joints moved)."""

    chain: Any
    home: Any
    lower: Any
    upper: Any


def shifted(target: KinematicTarget, origin: np.ndarray) -> Shifted:
    """``target`` with x measured from ``origin`` (only its task axes)."""
    chain = target.chain
    translations = chain.translations.copy()
    offset = np.zeros(3)
    offset[chain.task_axes] = origin
    for i in range(chain.n_joints):
        if chain.parents[i] < 0:
            translations[i] -= offset
    return Shifted(
        dataclasses.replace(chain, translations=translations), target.home, target.lower, target.upper
    )


def run_one(job: tuple[str, str, dict[str, Any], int]) -> tuple[float, float, float, int]:
    """(E_0, E^X at 1000, E^X at 3000, prototypes) of one seeded run.

    ``mode``: "reference" (the reference posture as home, the preset's targets), "preset", or
    "relative" (the preset in coordinates relative to its home effector position).
    """
    name, mode, params, seed = job
    preset_target = gb_pin.load_robot(name)
    assert preset_target.targets is not None
    X = preset_target.targets
    target = reference_target(name) if mode == "reference" else preset_target
    if mode == "relative":
        origin = target.home_position
        learner = gb_pin.GoalBabbling(**params)
        learner.fit(shifted(target, origin), X - origin, MOVEMENTS[-1], seed=seed, schedule=[0, *MOVEMENTS])
        e = learner.history_.error
        return float(e[0]), float(e[1]), float(e[2]), learner.model_.n_prototypes_
    result = gb_pin.babble(
        target, movements=MOVEMENTS[-1], seed=seed, targets=X, schedule=[0, *MOVEMENTS], **params
    )
    e = result.history.error
    return float(e[0]), float(e[1]), float(e[2]), result.n_prototypes


def measure(
    pool: ProcessPoolExecutor, name: str, mode: str, params: dict[str, Any], seeds: int
) -> tuple[float, float, float, float, float]:
    """E_0, median E^X/E_0 at 1000 and 3000, worst at 3000, median prototypes."""
    out = np.array(list(pool.map(run_one, [(name, mode, params, s) for s in range(seeds)])))
    ratio = out[:, 1:3] / out[:, [0]]
    return (
        float(out[0, 0]),
        float(np.median(ratio[:, 0])),
        float(np.median(ratio[:, 1])),
        float(ratio[:, 1].max()),
        float(np.median(out[:, 3])),
    )


def main(argv: Sequence[str] | None = None) -> None:
    """Print the three tables for the chosen presets, row by row as they are measured."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    spatial = [p.name for p in gb_pin.robots() if p.source == "example-robot-data"]
    parser.add_argument("--robots", default=",".join(spatial), help="comma-separated presets")
    parser.add_argument("--seeds", type=int, default=5, help="seeds per measurement (default 5)")
    parser.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    parser.add_argument(
        "--out", default=None, help="rewrite the tables in this markdown file after each preset"
    )
    parser.add_argument(
        "--overwrite", "--force", action="store_true", help="let --out replace an existing file"
    )
    args = parser.parse_args(argv)
    names = [n.strip() for n in args.robots.split(",") if n.strip()]
    if args.out is not None:
        from gb_pin._files import check_writable
        from gb_pin.cli.checks import no_clobber
        from gb_pin.exceptions import GbPinError

        try:  # before any work
            check_writable(args.out, "--out")
            no_clobber(args.out, "--out", args.overwrite)
        except GbPinError as exc:
            parser.exit(2, f"tune_presets.py: error: {exc}\n")

    tables = {
        "homes": [
            "| preset | home | hand position [m] | auto half-width [m] | E_0 | E^X/E_0 1000 "
            "| E^X/E_0 3000 | worst 3000 | E^X 3000 |",
            "|---|---|---|---|---|---|---|---|---|",
        ],
        "defaults": [
            "| preset | learner parameters | E_0 | E^X/E_0 1000 | E^X/E_0 3000 | worst 3000 | prototypes |",
            "|---|---|---|---|---|---|---|",
        ],
        "coordinates": [
            "| preset | task coordinates | E_0 | E^X/E_0 1000 | E^X/E_0 3000 | worst 3000 | prototypes |",
            "|---|---|---|---|---|---|---|",
        ],
    }

    def row(table: str, line: str) -> None:
        tables[table].append(line)
        print(f"{table}: {line}", flush=True)

    failed = []
    with ProcessPoolExecutor(args.workers) as pool:
        for name in names:
            try:
                _tune(pool, name, args.seeds, row)
            except Exception as exc:  # one preset's failure must not lose the others' rows
                failed.append(name)
                print(f"{name}: failed ({type(exc).__name__}: {exc}); going on", flush=True)
            else:
                print(f"{name} done", flush=True)
            if args.out is not None:
                _write(args.out, tables)
    print()
    print("\n\n".join("\n".join(t) for t in tables.values()))
    if failed:
        print(f"\nfailed: {', '.join(failed)}")
    print("E_0 and E^X are in the task vector's units: [m] for positions, a stacked task's rotations scaled.")


def _write(path: str, tables: dict[str, list[str]]) -> None:
    """The tables so far, written atomically."""
    import os

    tmp = f"{path}.tmp"
    with open(tmp, "w") as fh:
        fh.write("\n\n".join("\n".join(t) for t in tables.values()) + "\n")
    os.replace(tmp, path)


def _tune(pool: ProcessPoolExecutor, name: str, seeds: int, row: Any) -> None:
    """One preset's rows of the three tables."""
    preset, _ = get_preset(name)
    mine = gb_pin.load_robot(name)
    ref = reference_target(name)
    for label, target, is_ref in (("reference", ref, True), ("preset", mine, False)):
        try:
            half = auto_grid(target).half_width
        except (gb_pin.InvalidArgumentError, ValueError):
            half = float("nan")
        hand = np.round(target.home_position, 3).tolist()
        mode = "reference" if is_ref else "preset"
        e0, r1, r3, worst, _ = measure(pool, name, mode, dict(preset.learner), seeds)
        cells = f"{e0:.3f} | {r1:.3f} | {r3:.3f} | {worst:.3f} | {r3 * e0:.4f}"
        row("homes", f"| {name} | {label} | {hand} | {half:.3f} | {cells} |")
    radius = float(preset.learner.get("radius", 0.1))
    sigma = float(preset.learner.get("sigma", default_sigma(mine.n_joints)))
    variants: list[tuple[str, dict[str, Any]]] = [
        ("paper: radius 0.1, sigma Eq. 12", {"radius": 0.1, "sigma": None}),
        (f"preset: radius {radius:g}, sigma {sigma:.3g}", {}),
        (f"radius {radius / 2:g}", {"radius": radius / 2}),
        (f"radius {radius * 2:g}", {"radius": radius * 2}),
        (f"sigma {sigma / 2:.3g}", {"sigma": sigma / 2}),
        (f"sigma {sigma * 2:.3g}", {"sigma": sigma * 2}),
    ]
    for label, change in variants:
        params = {**preset.learner, **change}
        params = {k: v for k, v in params.items() if v is not None}
        e0, r1, r3, worst, k = measure(pool, name, "preset", params, seeds)
        row("defaults", f"| {name} | {label} | {e0:.3f} | {r1:.3f} | {r3:.3f} | {worst:.3f} | {k:.0f} |")
    modes = [("world", "preset")]
    if mine.task is None:  # a stacked task's rotations cannot be shifted
        modes.append(("relative to the home position", "relative"))
    for label, mode in modes:
        e0, r1, r3, worst, k = measure(pool, name, mode, dict(preset.learner), seeds)
        row("coordinates", f"| {name} | {label} | {e0:.3f} | {r1:.3f} | {r3:.3f} | {worst:.3f} | {k:.0f} |")


if __name__ == "__main__":
    main()
