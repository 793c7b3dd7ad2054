"""``gb-pin reproduce goals``: goal generators, measured on a grid that is not the goal set (docs/GOALS.md).

Per robot, every condition of :func:`study_conditions` runs as trials (trial i uses seed + i)
and is measured on a test grid that no generator chooses goals from:

- planar arms (total length 1 m): the oversized goal set O is the 9 x 9 grid over
  [-1.1, 1.1]^2 m (about half out of reach), the test grid G the 6 x 6 grid over
  x in [0.15, 0.7], y in [-0.55, 0.35] m (issue 11);
- humanoid arms: O is a 5 x 5 x 5 grid over the preset grid's box scaled x3 around its
  centre, the test grid the reachable points of a 4 x 4 x 4 grid over the box shrunk to
  0.8 of its half-width (none of them a preset target). The second humanoid arm
  (:data:`ONLY`) runs uniform on X* and direction sampling only.

Trials are cached in ``OUT/trials/`` (one JSON file per condition, named by a hash of the
condition, trials, seed and schedule), so a rerun with the same settings only redraws.
Written: ``goals_<robot>.png`` per robot, ``goals.json``, ``goals.csv`` and ``goals.md``.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin._files import save_or_fallback, write_text
from gb_pin.exceptions import GbPinError, InvalidArgumentError
from gb_pin.experiments.conditions import robot_label
from gb_pin.experiments.journal import TrialJournal, remove_journal
from gb_pin.experiments.trials import Condition, TrialSet, run_sweep
from gb_pin.learn.goals import make_goals
from gb_pin.reproduce.cache import GITIGNORE
from gb_pin.reproduce.conditions import QUANTILES
from gb_pin.reproduce.figures import new_figure, quantile_band, require_matplotlib, save_figure
from gb_pin.reproduce.stats import speeds
from gb_pin.robot.presets import load_robot
from gb_pin.robot.reachability import check_reachable

HUMANOIDS = ("talos_left_arm", "g1_left_arm")
ROBOTS = ("planar5", "planar20", *HUMANOIDS)
READ_AT = (300, 1000, 3000, 10_000)  # movement counts of the tables
PALETTE = ("#1f4e9c", "#7f8c8d", "#e67e22", "#c0392b", "#2e8b57", "#8e44ad", "#d4ac0d", "#16a085", "#34495e")
#: (label, goals, goal set) per condition; goal set "X*" is the preset's targets, "O" the oversized set.
CONDITIONS: tuple[tuple[str, str, str | None], ...] = (
    ("uniform on X*", "uniform", "X*"),
    ("uniform on O", "uniform", "O"),
    ("uniform+snap on O", "uniform:snap=0.05", "O"),
    ("error on O", "error", "O"),
    ("progress on O", "progress", "O"),
    ("directions", "directions", None),
    ("motor", "motor", None),
)
#: Extra conditions per robot: (label, goals, goal set, trials or None for the study's).
EXTRAS: dict[str, tuple[tuple[str, str, str | None, int | None], ...]] = {
    "planar5": (("directions, no snap", "directions:snap=none", None, 5),),
    "planar20": (
        ("motor spread 0.1", "motor:spread=0.1", None, None),
        ("motor spread 0.5", "motor:spread=0.5", None, None),
    ),
}


#: Robots that run only some conditions: the second humanoid arm checks direction sampling (issue 11).
ONLY: dict[str, tuple[str, ...]] = {"g1_left_arm": ("uniform on X*", "directions")}


def _grid(lower: Sequence[float], upper: Sequence[float], counts: Sequence[int]) -> NDArray[np.float64]:
    """A regular grid, the first axis slowest: (prod(counts), len(counts)) [m]."""
    axes = [np.linspace(lo, hi, n) for lo, hi, n in zip(lower, upper, counts, strict=True)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(counts))


def goal_sets(robot: Any) -> dict[str, NDArray[np.float64]]:
    """The preset's targets ``X*``, the oversized goal set ``O`` and the test grid ``test`` of a robot [m].

    ``robot``: a preset name, or a KinematicTarget with targets (e.g. an onboarded URDF or erd model).
    """
    rb = load_robot(robot) if isinstance(robot, str) else robot
    if rb.targets is None:
        raise InvalidArgumentError(f"the goal study needs a robot with a target set; {rb.name!r} has none")
    star = np.asarray(rb.targets, dtype=float)
    if star.shape[1] == 2:  # planar arms of total length 1 m (issue 11's grids)
        big = _grid([-1.1, -1.1], [1.1, 1.1], [9, 9])
        test = _grid([0.15, -0.55], [0.7, 0.35], [6, 6])
    else:
        centre = (star.min(axis=0) + star.max(axis=0)) / 2
        half = (star.max(axis=0) - star.min(axis=0)) / 2
        big = _grid(centre - 3 * half, centre + 3 * half, [5] * star.shape[1])
        test = _grid(centre - 0.8 * half, centre + 0.8 * half, [4] * star.shape[1])
    test = test[check_reachable(rb, test).reachable]
    return {"X*": star, "O": big, "test": np.round(test, 6)}


def schedule(movements: int, per_decade: int = 20) -> tuple[int, ...]:
    """Log-spaced movement counts up to ``movements``, with every count of :data:`READ_AT` below it."""
    count = int(np.ceil(per_decade * np.log10(max(movements, 2)))) + 1
    pts = np.round(np.geomspace(1, movements, count)).astype(int)
    return tuple(int(v) for v in np.unique([*pts, *(r for r in READ_AT if r <= movements), movements]))


def study_conditions(robot: Any, movements: int) -> list[tuple[str, Condition, int | None]]:
    """The labelled conditions of one robot (with the extras' own trial counts, None: the study's)."""
    sets = goal_sets(robot)
    keep = ONLY.get(robot_label(robot))
    extras = list(EXTRAS.get(robot_label(robot), ()))
    rows = [(*c, None) for c in CONDITIONS if keep is None or c[0] in keep] + extras
    out = []
    for label, goals, goal_set, trials in rows:
        params: dict[str, Any] = {"goals": goals, "eval_targets": sets["test"].tolist()}
        if goal_set == "O":
            params["targets"] = sets["O"].tolist()
            params.update(_own_settings(robot))  # the study's settings, not scaled to O (runs/scaling.py)
        cond = Condition(robot=robot, parameters=params, movements=movements, schedule=schedule(movements))
        out.append((label, cond, trials))
    return out


def _own_settings(robot: Any) -> dict[str, float]:
    """The robot's own radius and sigma (its preset's or onboarding's, else the paper's), given explicitly.

    A target array given to ``babble`` scales the settings not given to its extent
    (:mod:`gb_pin.runs.scaling`); the oversized set O measures the goal generators with the robot's
    own settings, as docs/GOALS.md did before that rule.
    """
    from gb_pin.learn.config import BY_NAME, default_sigma
    from gb_pin.runs.setup import resolve_robot

    target, _, defaults = resolve_robot(robot)
    sigma = defaults.get("sigma")
    radius: Any = defaults.get("radius", BY_NAME["radius"].default)
    return {
        "radius": float(radius),
        "sigma": float(default_sigma(target.n_joints) if sigma is None else sigma),
    }


def _cache_file(out: str, label: str, cond: Condition, trials: int, seed: int) -> str:
    # The generator's resolved parameters are part of the key: new defaults are new trials.
    spec = cond.parameters.get("goals")
    resolved = None if spec is None else repr(make_goals(spec))
    robot = cond.to_json().get("robot_source", cond.robot)  # a model robot: its source (its digest)
    key = json.dumps([robot, dict(cond.parameters), resolved, cond.schedule, trials, seed], sort_keys=True)
    slug = "".join(ch if ch.isalnum() else "-" for ch in label)
    name = "".join(ch if ch.isalnum() or ch == "_" else "-" for ch in robot_label(cond.robot))
    return os.path.join(
        out, "trials", f"goals_{name}_{slug}_{hashlib.sha1(key.encode()).hexdigest()[:10]}.json"
    )


def run_condition(
    out: str, label: str, cond: Condition, trials: int, seed: int, workers: int | None, progress: bool
) -> TrialSet:
    """A condition's trials, read from ``OUT/trials/`` if cached there, else run and cached.

    While they run, finished trials are journaled beside the cache file (``.journal.jsonl``; on a
    disk that fills, in the journal's fallbacks, which a rerun reads too): a rerun after Ctrl-C or a
    failed write computes only the others; the journal is removed once the condition's file is
    written.
    """
    path = _cache_file(out, label, cond, trials, seed)
    if os.path.exists(path):
        ts = TrialSet.load(path)
        recorded = tuple(int(v) for v in ts.movements if v > 0)  # the run adds movement 0
        if ts.trials == trials and ts.seed == seed and recorded == cond.schedule:
            return ts
    os.makedirs(os.path.dirname(path), exist_ok=True)
    where = path[: -len(".json")] + ".journal.jsonl"
    journal: str | None = where
    try:
        TrialJournal(where)  # created (or read) now; where it cannot be, the trials run unjournaled
    except GbPinError:
        journal = None
    sweep = run_sweep(
        [cond], trials=trials, seed=seed, workers=workers, progress=progress, checkpoint=journal
    )
    ts = sweep.results[0]
    save_or_fallback(path, ts.save, "the trials")  # computed at length: never lost to a failed write
    if os.path.exists(path) and journal is not None:
        remove_journal(journal)  # and its fallbacks, where a full disk moved it
    return ts


def numbers(ts: TrialSet) -> dict[str, Any]:
    """Quantiles of E^X at :data:`READ_AT`, S(Q, 0.1 E_0), E_0 and the final prototype counts."""
    last = int(ts.movements[-1])
    at = {
        str(r): [float(v) for v in np.quantile(ts.error[:, ts.at(r)], QUANTILES)]
        for r in READ_AT
        if r <= last
    }
    return {
        "trials": ts.trials,
        "initial_error": ts.initial_error,
        "error": at,
        "speed": speeds(ts),
        "prototypes": [float(v) for v in np.quantile(ts.prototypes, QUANTILES)],
    }


def draw(robot: str, sets: Sequence[tuple[str, TrialSet]], test_points: int, out: str) -> list[str]:
    """E^X on the test grid over movements, one quantile band per condition (the paper's style)."""
    fig = new_figure(7.5, 4.8)
    ax = fig.subplots(1, 1)
    for k, (label, ts) in enumerate(sets):
        q = ts.quantiles(QUANTILES, "error")[:, 1:]
        q[[0, 4]] = np.nan  # 10/90 % lines would clutter seven bands: median and 25-75 % only
        quantile_band(ax, ts.movements[1:], q, PALETTE[k % len(PALETTE)], f"{label} ({ts.trials})")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("movements r")
    ax.set_ylabel(f"$E^X_r$ on the test grid ({test_points} points) [m]")
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=7, loc="lower left")
    fig.suptitle(f"{robot}: goal generators (median, 25-75 % over trials)")
    return save_figure(fig, out, f"goals_{robot}", ("png",))


def _fmt(q: Sequence[float] | None) -> str:
    return "-" if q is None else f"{q[2]:.4f} ({q[1]:.4f}-{q[3]:.4f})"


def table(results: dict[str, dict[str, dict[str, Any]]]) -> str:
    """The markdown table: median (25-75 %) E^X at 3000 and 10^4, S(0.5, 0.1 E_0), prototypes."""
    lines = [
        "| robot | condition | trials | E^X at 3000 [m] | E^X at 10^4 [m] | S(0.5, 0.1 E_0) | prototypes |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for robot, rows in results.items():
        for label, n in rows.items():
            s = n["speed"]["0.5"]
            lines.append(
                f"| {robot} | {label} | {n['trials']} | {_fmt(n['error'].get('3000'))} | "
                f"{_fmt(n['error'].get('10000'))} | {'-' if s is None else s} | {n['prototypes'][2]:.0f} |"
            )
    return "\n".join(lines) + "\n"


def goal_study(
    out: str = "reproduction",
    *,
    trials: int = 20,
    movements: int = 10_000,
    seed: int = 0,
    workers: int | None = None,
    robots: Sequence[Any] = ROBOTS,
    progress: bool = False,
    log: Callable[[str], Any] | None = print,
) -> list[str]:
    """Run (or read from ``OUT/trials/``) every goal condition of every robot; write figures and tables.

    Args:
        out: output folder (created; the cache goes to ``OUT/trials/``).
        trials: trials per condition (the extras with their own count excepted).
        movements: movements per trial (E^X is read at 300, 1000, 3000 and 10^4 where <= this).
        seed: seed of trial 0.
        workers: local processes (default all cores).
        robots: preset names, or KinematicTargets with targets (e.g. from a URDF or example-robot-data).
        progress: progress bar.
        log: called with one line per condition (None: silent).

    Returns:
        The paths written.
    """
    require_matplotlib()
    say = log or (lambda _line: None)
    os.makedirs(os.path.join(out, "trials"), exist_ok=True)
    ignore = os.path.join(out, "trials", ".gitignore")
    if not os.path.exists(ignore):
        write_text(ignore, GITIGNORE)
    results: dict[str, dict[str, dict[str, Any]]] = {}
    files: list[str] = []
    for robot in robots:
        name = robot_label(robot)
        sets = []
        for label, cond, own in study_conditions(robot, movements):
            t0 = time.perf_counter()
            ts = run_condition(out, label, cond, own or trials, seed, workers, progress)
            sets.append((label, ts))
            final = np.median(ts.error[:, -1])
            say(f"{name} {label}: median final E^X {final:.4f} m ({time.perf_counter() - t0:.0f} s)")
        results[name] = {label: numbers(ts) for label, ts in sets}
        files += draw(name, sets, len(sets[0][1].parameters["eval_targets"]), out)
    body = {"trials": trials, "movements": movements, "seed": seed, "results": results}
    write_text(os.path.join(out, "goals.json"), json.dumps(body, indent=1) + "\n")
    csv = ["robot,condition,trials,movements," + ",".join(f"q{q:g}" for q in QUANTILES)]
    for robot, rows in results.items():
        for label, n in rows.items():
            csv += [
                f"{robot},{label},{n['trials']},{r}," + ",".join(f"{v:.6g}" for v in q)
                for r, q in n["error"].items()
            ]
    write_text(os.path.join(out, "goals.csv"), "\n".join(csv) + "\n")
    write_text(os.path.join(out, "goals.md"), table(results))
    return files + [os.path.join(out, f) for f in ("goals.json", "goals.csv", "goals.md")]
