"""``gb-pin reproduce workspace``: learning half of every joint's range (docs/WORKSPACE.md).

Per robot and fraction f, ``seeds`` runs learn the region ``targets="workspace:fraction=f"``
(:mod:`gb_pin.robot.workspace`: goals from seed 0, 300 test points from seed 1, the curriculum
and the settings scaled to the region, :mod:`gb_pin.runs.scaling`); after each count of
:data:`SNAPSHOTS` movements the learned map's reach error on every test point is measured (the
model's forward kinematics of the clipped g(x*)): median, 90 % and the share within 1 cm and 2 mm.

Each run is cached in ``OUT/trials/`` (one JSON file per run, the errors of every test point
included), so a rerun only redraws. Written: ``workspace.json``, ``workspace.md`` (the table),
``workspace_<robot>.png`` (:mod:`gb_pin.reproduce.workspace_figure`).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
from collections.abc import Sequence
from functools import partial
from typing import Any, NamedTuple

import numpy as np

from gb_pin import _validation as check
from gb_pin._files import write_json, write_text
from gb_pin.reproduce.cache import run_cached

SNAPSHOTS = (3000, 10_000, 30_000)
ROBOTS = ("so101", "panda", "talos_left_arm")
FRACTIONS = (0.25, 0.5)


class Condition(NamedTuple):
    """One run: a robot, a region fraction, a seed."""

    robot: str
    fraction: float
    seed: int
    goals: str | None = None  # None: the region's default (the curriculum)

    @property
    def key(self) -> str:
        """The cache file's name: robot, fraction, seed and a hash of every setting that changes numbers."""
        # v2: rate 0.5; v3: parts=auto; v4, v5: cutoff 4, 3; v6: the noise walk by redundant joints
        settings = json.dumps([*self, SNAPSHOTS, "v6"])
        digest = hashlib.sha256(settings.encode()).hexdigest()[:12]
        return f"{self.robot.replace(':', '_')}_f{self.fraction:g}_s{self.seed}_{digest}"


class _Snapshots:
    """A babble() observer keeping a copy of the learned map at each snapshot count."""

    def __init__(self, at: Sequence[int]) -> None:
        self.at = set(at)
        self.maps: dict[int, Any] = {}

    def start(self, target: Any, targets: Any) -> None:
        """Nothing to draw."""

    def update(self, state: Any) -> None:
        if state.movements in self.at:
            from gb_pin.learn.llm import LocalLinearMap

            if hasattr(state.llm, "copy"):  # a region in parts: its PartedMap
                self.maps[state.movements] = state.llm.copy()
                return
            self.maps[state.movements] = LocalLinearMap.from_arrays(
                {k: v.copy() for k, v in state.llm.to_arrays().items()},
                state.config.radius,
                cutoff=state.config.cutoff,
            )


def run_condition(cond: Condition, movements: int) -> dict[str, Any]:
    """Learn one region with one seed; the test points' errors at every snapshot count."""
    import gb_pin
    from gb_pin.learn.reach_errors import ReachErrors
    from gb_pin.robot.workspace import WorkspaceRegion, extent

    at = [s for s in SNAPSHOTS if s <= movements]
    shots = _Snapshots(at)
    every = math.gcd(*at)
    start = time.process_time()
    run = gb_pin.babble(cond.robot, movements=movements, seed=cond.seed, goals=cond.goals,
                        targets=f"workspace:fraction={cond.fraction!r}", schedule=[0, *at], viewer=shots,
                        observe_every=every)  # fmt: skip
    cpu = time.process_time() - start
    arm, test = run.target, run.targets
    out: dict[str, Any] = {
        "condition": cond._asdict(),
        "radius": run.config.radius,
        "sigma": run.config.sigma,
        "goals": run.goals,
        "parts": getattr(run.model, "n_parts", 1),
        "extent": extent(WorkspaceRegion(cond.fraction).final_goals(arm)),
        "cpu_seconds": cpu,
        "steps": run.steps,
        "test": test.tolist(),
        "home_position": arm.forward(arm.home).tolist(),
        "snapshots": {},
    }
    for count, model in sorted(shots.maps.items()):
        Q = np.clip(model.predict(test, warn=False), arm.lower, arm.upper)
        e = ReachErrors.of(np.linalg.norm(arm.forward(Q) - test, axis=1))
        out["snapshots"][str(count)] = {
            "median": e.median, "p90": e.p90, "mean": e.mean, "coverage": list(e.coverage),
            "prototypes": model.n_prototypes_, "errors": [round(float(v), 7) for v in e.errors],
        }  # fmt: skip
    return out


def conditions(robots: Sequence[str], fractions: Sequence[float], seeds: int) -> list[Condition]:
    """Every (robot, fraction, seed) to run, in order."""
    from gb_pin.robot.presets import get_preset

    for robot in robots:
        get_preset(robot)  # an unknown preset fails here, before any work
    for f in fractions:
        if not 0.0 < f <= 1.0:
            from gb_pin.exceptions import InvalidArgumentError

            raise InvalidArgumentError(f"workspace study fractions must be in (0, 1], got {f!r}")
    return [Condition(r, float(f), s) for r in robots for f in fractions for s in range(seeds)]


def run_workspace(
    out: str,
    robots: Sequence[str] = ROBOTS,
    fractions: Sequence[float] = FRACTIONS,
    seeds: int = 10,
    movements: int = SNAPSHOTS[-1],
    workers: int | None = None,
    fresh: bool = False,
    progress: bool = False,
) -> list[str]:
    """Run (or read from the cache) every condition and write the table and figures; returns the files.

    Raises:
        InvalidArgumentError: an unknown robot, a bad fraction, seeds < 1, movements below the first snapshot.
    """
    seeds = check.positive_int("seeds", seeds, 1, 1000)
    check.positive_int("movements", movements, SNAPSHOTS[0], check.MAX_MOVEMENTS)
    todo = conditions(robots, fractions, seeds)
    results = run_cached(out, todo, lambda c: f"{c.key}_m{movements}.json",
                         partial(run_condition, movements=movements), workers, fresh, progress)  # fmt: skip
    from gb_pin.reproduce.workspace_figure import draw_robot, table

    rows = [results[c] for c in todo]
    files = [os.path.join(out, "workspace.json")]
    write_json(files[0], {"snapshots": list(SNAPSHOTS), "runs": [_without_points(r) for r in rows]})
    files.append(os.path.join(out, "workspace.md"))
    write_text(files[-1], table(rows))
    for robot in dict.fromkeys(c.robot for c in todo):
        files += draw_robot([r for r in rows if r["condition"]["robot"] == robot], robot, out)
    return files


def _without_points(row: dict[str, Any]) -> dict[str, Any]:
    """A run's summary without its per-point arrays (those stay in the cache)."""
    out = {k: v for k, v in row.items() if k not in ("test", "home_position")}
    out["snapshots"] = {k: {a: b for a, b in v.items() if a != "errors"} for k, v in row["snapshots"].items()}
    return out
