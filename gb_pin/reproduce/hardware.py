"""``gb-pin reproduce hardware``: learn the arm that is, not its URDF (docs/HARDWARE.md).

Per robot, ``arms`` mis-calibrated bodies (:class:`~gb_pin.robot.plant.Plant`: joint zero offsets
~ N(0, 3 deg), every link translation x (1 + N(0, 3 %)), arm i drawn from seed i), each watched
by a tracker of noise sigma per axis that loses a fraction of its readings. Three ways to reach a
3 x 3 x 3 test grid (the preset's goal box shrunk to 2/3: not the goal set) are measured on the
true body:

- **URDF IK**: exact IK on the model (gb_pin's damped least squares from home, to 1e-9 m), executed
  on the true arm;
- **learned, open loop**: g(x*) of a goal-babbling run that learnt from the tracker's readings,
  after each count of :data:`SNAPSHOTS` movements;
- **feedback**: g(x*), then corrections with the learned Jacobian from 1, 1 and 3 readings of the
  same tracker (:mod:`gb_pin.learn.feedback`): at most 5 readings per target.

Each run is cached in ``OUT/trials/`` (one JSON file per condition), so a rerun only redraws.
Written: ``hardware.json`` (every condition), ``hardware.md`` (tables), ``hardware.csv`` and
``hardware_<robot>.png`` (:mod:`gb_pin.reproduce.hardware_figure`).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Sequence
from functools import partial
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin._files import write_json, write_text
from gb_pin.reproduce.cache import run_cached

SNAPSHOTS = (300, 1000, 3000, 10_000)
NOISES = (0.0, 0.0002, 0.0015, 0.003)  # tracker noise per axis [m]: none, motion capture, cameras
LOSSES = (0.0, 0.1)
OFFSET_DEG, LENGTH_PCT = 3.0, 3.0
OBSERVATIONS = (1, 1, 3)
#: Robots and the sensor conditions each runs: the full grid for the SO-101, the acceptance's for the others.
ROBOTS: dict[str, tuple[tuple[float, float], ...]] = {
    "so101": tuple((n, p) for n in NOISES for p in LOSSES),
    "so100": ((0.0015, 0.1),),
    "panda": ((0.0015, 0.1),),
}


class Condition(NamedTuple):
    """One mis-calibrated arm under one tracker."""

    robot: str
    arm: int
    noise: float
    loss: float

    @property
    def key(self) -> str:
        """The cache file's name: robot, arm, sensor and a hash of every setting that changes numbers."""
        settings = json.dumps([*self, OFFSET_DEG, LENGTH_PCT, SNAPSHOTS, OBSERVATIONS, "v1"])
        digest = hashlib.sha256(settings.encode()).hexdigest()[:12]
        return f"{self.robot}_arm{self.arm}_n{self.noise * 1000:g}mm_l{self.loss:g}_{digest}"


def evaluation_grid(target: Any) -> NDArray[np.float64]:
    """3 x 3 x 3 points over the preset's goal box shrunk to 2/3 around its centre (not goal points)."""
    lo, hi = target.targets.min(axis=0), target.targets.max(axis=0)
    centre, half = (lo + hi) / 2, (hi - lo) / 3
    axes = [np.linspace(centre[i] - half[i], centre[i] + half[i], 3) for i in range(3)]
    return np.array([[a, b, c] for a in axes[0] for b in axes[1] for c in axes[2]])


class _Snapshots:
    """A babble() observer keeping a copy of the learned map at each snapshot count."""

    def __init__(self) -> None:
        self.maps: dict[int, Any] = {}

    def start(self, target: Any, targets: Any) -> None:
        """Nothing to draw."""

    def update(self, state: Any) -> None:
        if state.movements in SNAPSHOTS:
            from gb_pin.learn.llm import LocalLinearMap

            self.maps[state.movements] = LocalLinearMap.from_arrays(
                {k: v.copy() for k, v in state.llm.to_arrays().items()},
                state.config.radius,
                cutoff=state.config.cutoff,
            )


def _spread(errors: NDArray[np.float64]) -> list[float]:
    """(median, 90 %) of per-target errors [m]."""
    return [float(np.median(errors)), float(np.quantile(errors, 0.9))]


def run_condition(cond: Condition, movements: int) -> dict[str, Any]:
    """Learn one arm under one tracker and measure the three ways to reach on its true body."""
    import gb_pin
    from gb_pin.learn.feedback import reach
    from gb_pin.robot.plant import Plant

    arm = gb_pin.load_robot(cond.robot)
    test = evaluation_grid(arm)
    plant = Plant(cond.robot, offset_std=math.radians(OFFSET_DEG), length_std=LENGTH_PCT / 100,
                  noise=cond.noise, loss=cond.loss, seed=cond.arm)  # fmt: skip
    urdf = gb_pin.ik.solve(arm, test, seed="home", tol=1e-9)
    shots = _Snapshots()
    every = math.gcd(*SNAPSHOTS)
    run = gb_pin.babble(plant, movements=movements, seed=cond.arm, eval_targets=test, viewer=shots,
                        observe_every=every)  # fmt: skip
    out: dict[str, Any] = {
        "condition": cond._asdict(),
        "urdf": _spread(np.linalg.norm(plant.forward(urdf.postures) - test, axis=1)),
        "urdf_converged": float(np.mean(urdf.success)),
        "open": {},
        "feedback": {},
        "reach": {},
        "prototypes": {},
        "missing": run.missing,
        "steps": run.steps,
    }
    for at, model in sorted(shots.maps.items()):
        Q = np.clip(model.predict(test, warn=False), arm.lower, arm.upper)
        out["open"][str(at)] = _spread(np.linalg.norm(plant.forward(Q) - test, axis=1))
        fb = reach(model, test, plant.observe, arm.lower, arm.upper, observations=OBSERVATIONS)
        out["feedback"][str(at)] = [*_spread(np.linalg.norm(plant.forward(fb.postures) - test, axis=1)),
                                    float(fb.readings.mean())]  # fmt: skip
        i = int(np.flatnonzero(run.history.movements == at)[0]) if at in run.history.movements else -1
        out["reach"][str(at)] = float(run.history.reach[i]) if run.history.reach is not None else math.nan
        out["prototypes"][str(at)] = model.n_prototypes_
    return out


def conditions(robots: Sequence[str], arms: int) -> list[Condition]:
    """Every (robot, arm, noise, loss) to run, in order."""
    unknown = [r for r in robots if r not in ROBOTS]
    if unknown:
        from gb_pin.exceptions import InvalidArgumentError

        raise InvalidArgumentError(f"hardware study robots: unknown {unknown}; valid: {', '.join(ROBOTS)}")
    return [Condition(r, a, n, p) for r in robots for (n, p) in ROBOTS[r] for a in range(arms)]


def run_hardware(
    out: str,
    robots: Sequence[str] = tuple(ROBOTS),
    arms: int = 20,
    movements: int = SNAPSHOTS[-1],
    workers: int | None = None,
    fresh: bool = False,
    progress: bool = False,
) -> list[str]:
    """Run (or read from the cache) every condition and write the tables and figures; returns the files.

    Raises:
        InvalidArgumentError: an unknown robot, arms < 1, movements below the last snapshot.
    """
    arms = check.positive_int("arms", arms, 1, 1000)
    check.positive_int("movements", movements, SNAPSHOTS[-1], check.MAX_MOVEMENTS)
    todo = conditions(robots, arms)
    results = run_cached(out, todo, lambda c: c.key + ".json", partial(run_condition, movements=movements),
                         workers, fresh, progress)  # fmt: skip
    from gb_pin.reproduce.hardware_figure import draw_robot, tables

    rows = [results[c] for c in todo]
    files = [os.path.join(out, "hardware.json")]
    write_json(files[0], {"snapshots": list(SNAPSHOTS), "observations": list(OBSERVATIONS), "runs": rows})
    md, csv = tables(rows)
    for name, text in (("hardware.md", md), ("hardware.csv", csv)):
        files.append(os.path.join(out, name))
        write_text(files[-1], text)
    for robot in dict.fromkeys(c.robot for c in todo):
        files += draw_robot([r for r in rows if r["condition"]["robot"] == robot], robot, out)
    return files
