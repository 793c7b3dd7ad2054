"""A workspace region learnt in parts: one learner per part, babbled in alternation.

``babble(robot, targets="workspace:fraction=0.5,parts=2")``: the region is split around the first
joint's axis (:mod:`gb_pin.robot.workspace_parts`); each part has its own learner (its own home,
map, exploration noise and random stream) with the region's settings
(:mod:`gb_pin.runs.scaling`). The learners take turns of :data:`TURN` movements each, so that the
movement budget is shared: after r movements of the run learner p has made r // P (+1 for the
first r % P learners). E^X and D^home of the run are those of the parted estimate
(:class:`~gb_pin.learn.parts.PartedMap`: a query answered by the map of its part) on the region's
test points, at the schedule's movement counts of the whole run; at movement 0 those of the
robot's constant home q_home (E_0, as a run of one learner records it).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.config import BabbleConfig
from gb_pin.learn.history import History
from gb_pin.learn.layout import REACHES
from gb_pin.learn.metrics import reach_median
from gb_pin.learn.parts import PartedMap
from gb_pin.learn.state import BabbleState
from gb_pin.robot.workspace import WorkspaceRegion
from gb_pin.robot.workspace_parts import region_parts
from gb_pin.runs import setup
from gb_pin.runs.scaling import scaled_spec
from gb_pin.runs.spec import RunSpec

TURN = 100  # movements a learner makes before the next one takes its turn
CURRICULUM_FIRST = 900  # goals of the curriculum's first stage in a run of one learner (CurriculumGoals)


class _PartBody(NamedTuple):
    """The robot as one part's learner sees it: the robot's kinematics with the part's home."""

    chain: Any
    home: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]


class PartedView(NamedTuple):
    """What a viewer's ``update`` gets from a parted run: the count, the parted estimate, the settings."""

    movements: int
    llm: PartedMap
    config: BabbleConfig
    eval_targets: NDArray[np.float64]


def share(total: int, parts: int, p: int) -> int:
    """Movements learner ``p`` of ``parts`` has made after ``total`` movements of the run."""
    return total // parts + (1 if p < total % parts else 0)


def babble_parted(
    spec: RunSpec,
    region: WorkspaceRegion,
    callback: Callable[[int], Any] | None = None,
    viewer: Any | None = None,
    observe_every: int = 10,
) -> Any:
    """Run ``spec`` (a workspace region of ``region.parts`` parts); returns a BabbleResult.

    Raises:
        InvalidArgumentError: a robot without compiled kinematics, or an option a parted run does
            not have (a checkpoint, ``init``, body changes, a sensor, obstacles, recording, ``until_error``).
    """
    from gb_pin.runs.result import BabbleResult

    unsupported = {
        "init": spec.init, "changes": spec.changes, "sensor": spec.sensor, "record": spec.record,
        "obstacles": spec.obstacles, "until_error": spec.until_error,
    }  # fmt: skip
    given = [k for k, v in unsupported.items() if v] + (["self_collision"] if spec.self_collision else [])
    if given:
        raise InvalidArgumentError(
            f"a workspace region in parts (parts={region.parts}) does not take {', '.join(given)}: "
            "use parts=1 for those"
        )
    target, name, defaults = setup.resolve_robot(spec.robot)
    if getattr(target, "chain", None) is None or getattr(target, "sensor", None) is not None:
        raise InvalidArgumentError(
            f"a workspace region in parts needs a robot with compiled kinematics and no sensor model, got "
            f"{target!r:.100}: use parts=1"
        )
    whole = scaled_spec(spec.replace(targets=dataclasses.replace(region, parts=1).spec()), target, defaults)
    parts = region_parts(target, region)
    P = region.parts
    goals = whole.goals
    if spec.goals is None and region.stages > 1:  # stages at the run's movements of one learner's
        goals = f"curriculum:stages={region.stages},first={max(1, round(CURRICULUM_FIRST / P))}"
    learner = setup.make_learner(defaults, whole.hyperparameters())
    config = learner._resolve(target.n_joints)
    movements = check.movements("movements", spec.movements)
    rng, seed = setup.generator(spec.seed)
    streams = [np.random.default_rng(s) for s in rng.integers(0, 2**63, size=P)]
    lower, upper = np.asarray(target.lower, dtype=float), np.asarray(target.upper, dtype=float)
    states = []
    for p in range(P):
        budget = max(1, share(movements, P, p))
        body = _PartBody(target.chain, parts.homes[p], lower, upper)
        state = BabbleState.start(
            body, parts.goals[p], budget, config, seed=streams[p], schedule=[0, budget], goals=goals,
            max_joint_step=spec.max_joint_step, reach_window=spec.reach_window,
        )  # fmt: skip
        states.append(state)
    test = np.asarray(whole.eval_targets, dtype=float)
    schedule = np.asarray(whole.schedule if whole.schedule is not None else [0, movements], dtype=np.int64)
    schedule = schedule[schedule <= movements]
    observe_every = check.positive_int("observe_every", observe_every)
    setup.check_hooks(callback=callback, viewer=viewer)
    if viewer is not None:
        viewer.start(target, test)
    home = np.asarray(target.home, dtype=float)
    errors, distances, reaches = (np.full(schedule.shape[0], np.nan) for _ in range(3))
    start = time.perf_counter()
    total, k = 0, 0
    if schedule.shape[0] and schedule[0] == 0:  # E_0: the robot's constant home, as one learner records it
        reached = target.forward(np.tile(np.clip(home, lower, upper), (test.shape[0], 1)))
        errors[0], distances[0] = float(np.mean(np.linalg.norm(reached - test, axis=1))), 0.0
        k = 1
    observed = range(observe_every, movements + 1, observe_every) if viewer is not None else ()
    chunks = range(TURN * P, movements + 1, TURN * P) if callback is not None else ()
    stops = sorted({*schedule.tolist(), *observed, *chunks, movements} - {0})
    for stop in stops:
        while total < stop:  # turns of TURN movements each, in order, up to this stop
            nxt = min(stop, (total // (TURN * P) + 1) * TURN * P)
            for p, st in enumerate(states):
                st.run(share(nxt, P, p))
            total = nxt
        model = PartedMap([st.llm for st in states], parts.sectors)
        while k < schedule.shape[0] and schedule[k] <= total:
            Q = model.predict(test, warn=False)
            reached = target.forward(np.clip(Q, lower, upper))
            errors[k] = float(np.mean(np.linalg.norm(reached - test, axis=1)))
            distances[k] = float(np.mean(np.linalg.norm(Q - home, axis=1)))
            rings = [st.reach[: min(int(st.istate[REACHES]), st.reach.shape[0])] for st in states]
            ring = np.concatenate(rings) if rings else np.zeros(0)
            reaches[k] = reach_median(ring, ring.shape[0]) if ring.shape[0] else np.nan
            k += 1
        if viewer is not None and total % observe_every == 0:
            viewer.update(PartedView(total, model, config, test))
        if callback is not None:
            callback(total)
    model = PartedMap([st.llm for st in states], parts.sectors)
    return BabbleResult(
        target=target,  # type: ignore[arg-type]
        targets=test,
        history=History(movements=schedule, error=errors, home_distance=distances, reach=reaches),
        model=model,  # type: ignore[arg-type]
        config=config,
        seed=seed,
        robot=name,
        movements=total,
        steps=sum(st.steps for st in states),
        wall_time=time.perf_counter() - start,
        state=None,
        goals=f"{states[0].goals!r} in {P} parts",
        goal_targets=np.vstack(parts.goals),
        missing=sum(st.missing for st in states),
    )
