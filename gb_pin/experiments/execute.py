"""Running trials: plan the tasks, run them on local cores or a Dask cluster, assemble the trial sets.

Trial i of a condition uses seed ``seed + i``, so a set of trials gives the same
numbers whatever runs it: one process, a local process pool, or a Dask cluster
(:mod:`gb_pin.experiments.distributed`). A task carries only the robot's preset name (or
MODULE:NAME, or the robot source of a URDF or example-robot-data model: a small JSON object,
:mod:`gb_pin.runs.robot_source`), the parameters, the seed and the movement counts to record,
never a model: every worker builds its robot from that (once per process).
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError, ResultFileError
from gb_pin.experiments.conditions import (
    MAX_CONDITIONS,
    Condition,
    Sweep,
    check_parameters,
    conditions_grid,
    robot_label,
)
from gb_pin.experiments.journal import TrialJournal, TrialOutput, TrialTask
from gb_pin.experiments.pool import max_workers, run_pool
from gb_pin.experiments.trialset import TrialSet
from gb_pin.learn.metrics import evaluation_schedule
from gb_pin.robot.presets import get_preset
from gb_pin.runs.api import babble
from gb_pin.runs.spec import RunSpec
from gb_pin.sim.spec import is_plant_spec


def run_one_trial(
    robot: str | dict[str, Any],
    movements: int,
    seed: int,
    schedule: NDArray[np.int64],
    kwargs: dict[str, Any],
) -> TrialOutput:
    """One trial, as a worker runs it: (E^X, D^home at ``schedule``, prototypes, E^X per component or None).

    Module-level and fed only plain values, so that a process pool or a Dask worker
    receives the robot's name (or robot source), never a model.
    """
    target = worker_robot(robot)
    result = babble(robot=target, movements=movements, seed=seed, schedule=schedule, **kwargs)
    h = result.history
    return h.error, h.home_distance, result.n_prototypes, h.components


_REBUILT: dict[str, Any] = {}  # robot source -> robot, once per worker process


def task_robot(robot: Any) -> str | dict[str, Any]:
    """What a trial task carries for ``robot``: a name as is, a URDF or erd model as its robot source.

    Raises:
        InvalidArgumentError: a robot that workers cannot rebuild (built in Python from a pin.Model
            or a function: give it as MODULE:NAME).
    """
    if isinstance(robot, str):
        return robot
    from gb_pin.robot.target import KinematicTarget
    from gb_pin.runs.robot_source import describe

    source = describe(robot, None)
    if source is not None and source["kind"] == "module":
        return str(source["spec"])
    if source is None or not isinstance(robot, KinematicTarget):
        raise InvalidArgumentError(
            "robot must be a preset name, MODULE:NAME or a KinematicTarget loaded from a URDF or "
            f"example-robot-data for trials (each worker builds it again), got {robot!r}"
        )
    return source


def worker_robot(robot: str | dict[str, Any]) -> Any:
    """The robot a task names: a name as is, a robot source rebuilt (once per process) and checked."""
    if isinstance(robot, str):
        return robot
    key = json.dumps(robot, sort_keys=True)
    if key not in _REBUILT:
        from gb_pin.runs.robot_source import rebuild

        _REBUILT[key] = rebuild("trial", robot)
    return _REBUILT[key]


def run_trial_batch(tasks: list[TrialTask]) -> list[TrialOutput]:
    """Several trials in one Dask task (short trials batched): each is :func:`run_one_trial`."""
    return [run_one_trial(*task) for task in tasks]


MAX_TRIALS = 10**5
"""The most trials of one call (all conditions together): 10^5 trials of 0.1 s are 3 hours of one core;
a larger study is several calls (each with its journal)."""

# Dask costs about 1 ms per task: trials are batched so that a task runs about 0.1 s.
# A trial's cost is movements * (joints + 5) (_plan); planar20 at the default path length runs
# 1000 movements, cost 25 000, in about 0.25 s (9.8 us/step, evaluation included): 1e-5 s per unit.
SECONDS_PER_COST = 1e-5
BATCH_SECONDS = 0.1
BATCH_COST = BATCH_SECONDS / SECONDS_PER_COST


def batch_trials(order: Sequence[int], costs: Sequence[float], min_cost: float) -> list[list[int]]:
    """Consecutive runs of ``order`` (longest first) whose summed cost reaches ``min_cost``.

    A trial of at least ``min_cost`` is a task of its own; shorter ones are gathered until the batch
    reaches it (the last batch may be short). ``min_cost <= 0`` gives one trial per task.
    """
    batches: list[list[int]] = []
    batch: list[int] = []
    total = 0.0
    for i in order:
        batch.append(i)
        total += costs[i]
        if total >= min_cost:
            batches.append(batch)
            batch, total = [], 0.0
    if batch:
        batches.append(batch)
    return batches


def resolve_schedule(schedule: ArrayLike | None, movements: int) -> NDArray[np.int64]:
    """The movement counts to record: sorted, unique, with 0; default :func:`evaluation_schedule`.

    Raises:
        InvalidArgumentError: not a 1-D sequence of whole movement counts in [0, movements].
    """
    if schedule is None:
        return evaluation_schedule(movements)
    try:
        raw = np.asarray(schedule)
        if raw.ndim != 1 or (raw.size and not np.all(np.equal(np.mod(raw, 1), 0))):
            raise ValueError
        at = np.unique(np.concatenate([[0], raw.astype(np.int64)]))
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(
            f"schedule must be a 1-D sequence of movement counts, got {schedule!r}"
        ) from exc
    # Movement 0 is always recorded: it gives E_0.
    if at[0] < 0 or at[-1] > movements:
        raise InvalidArgumentError(
            f"schedule must hold movement counts in [0, {movements}], got {schedule!r}"
        )
    return at


@dataclass(frozen=True)
class _Plan:
    condition: Condition
    robot: str | dict[str, Any]  # what the tasks carry (task_robot)
    movements: int
    schedule: NDArray[np.int64]
    parameters: dict[str, Any]
    cost: float  # estimated work of one trial, to start the longest first


def _plan(condition: Condition, movements: int, seed: int) -> _Plan:
    """Validate a condition with a one-movement run here, before any worker starts."""
    if not isinstance(condition, Condition):
        raise InvalidArgumentError(f"conditions must be gb_pin.Condition objects, got {condition!r}")
    robot = task_robot(condition.robot)
    if isinstance(robot, str) and ":" not in robot and not is_plant_spec(robot):  # the probe run checks
        get_preset(robot)  # MODULE:NAME robots and plants (ROBOT@mujoco)
    parameters = dict(condition.parameters)
    check_parameters(parameters)
    length = (
        movements if condition.movements is None else check.positive_int("movements", condition.movements)
    )
    at = resolve_schedule(condition.schedule, length)
    probe = babble(robot=condition.robot, movements=1, seed=seed, schedule=[0, 1], **parameters)
    return _Plan(condition, robot, length, at, parameters, float(length) * (probe.target.n_joints + 5))


def _execute(
    tasks: list[TrialTask],
    costs: list[float],
    workers: int | None,
    scheduler: Any,
    progress: bool,
    desc: str,
    journal: TrialJournal | None = None,
) -> list[TrialOutput]:
    """Run the tasks (longest first, those in ``journal`` not again); outputs in task order."""
    results: list[TrialOutput | None] = [None] * len(tasks)
    if journal is not None:
        for i, task in enumerate(tasks):
            out = journal.done.get(TrialJournal.key(task))
            if out is not None and out[0].shape == (len(task[3]),):  # a line of another length: recomputed
                results[i] = out
    bar = None
    if progress:
        from tqdm import tqdm

        finished = sum(r is not None for r in results)
        bar = tqdm(total=len(tasks), initial=finished, unit="trial", desc=desc)

    def done(i: int, out: TrialOutput) -> None:
        results[i] = out
        if journal is not None:
            journal.record(tasks[i], out)
        if bar is not None:
            bar.update(1)

    todo = [i for i in range(len(tasks)) if results[i] is None]
    order = sorted(todo, key=lambda i: -costs[i])
    try:
        if scheduler is not None:
            from gb_pin.experiments.distributed import map_tasks

            batches = batch_trials(order, costs, BATCH_COST)
            sub = [([tasks[i] for i in batch],) for batch in batches]

            def done_batch(k: int, outs: list[TrialOutput]) -> None:
                for i, out in zip(batches[k], outs, strict=True):
                    done(i, out)

            priorities = [sum(costs[i] for i in batch) for batch in batches]
            map_tasks(run_trial_batch, sub, scheduler, done_batch, priorities=priorities)
        elif not todo:
            pass
        elif workers == 1 or len(todo) == 1:
            for i in order:
                done(i, run_one_trial(*tasks[i]))
        else:
            run_pool(run_one_trial, tasks, order, min(workers or 1, len(todo)), done)
    except KeyboardInterrupt as exc:
        raise KeyboardInterrupt(_interrupted(results, journal, str(exc))) from None
    finally:
        if bar is not None:
            bar.close()
    return [r for r in results if r is not None]


def _interrupted(results: list[TrialOutput | None], journal: TrialJournal | None, reason: str) -> str:
    """The one line that says how far the trials got when Ctrl-C stopped them."""
    finished, total = sum(r is not None for r in results), len(results)
    head = reason if reason and not reason.isdigit() else "interrupted"
    if journal is not None and journal.writing is not None:
        return (
            f"{head}: {finished} of {total} trials finished, journaled in {journal.writing}; "
            "run the same command again to compute only the others"
        )
    # (no command-line option named: this runs under gb-pin trials, sweep, reproduce and from Python)
    return f"{head}: {finished} of {total} trials finished, not journaled (a rerun computes them again)"


def _check_executor(workers: int | None, scheduler: Any) -> int | None:
    if isinstance(scheduler, str):
        from gb_pin.experiments.distributed import check_address
        from gb_pin.experiments.slurm import is_slurm_spec, parse_slurm_spec

        # a malformed address or SLURM spec is refused before any work
        if is_slurm_spec(scheduler):
            parse_slurm_spec(scheduler)
        else:
            check_address(scheduler)
    if scheduler is not None:
        if workers is not None:
            raise InvalidArgumentError(
                f"workers={workers!r} cannot be combined with a Dask scheduler: the cluster's workers run "
                "the trials (leave workers=None)"
            )
        return None
    if workers is None:
        workers = os.cpu_count() or 1
    return check.positive_int("workers", workers, maximum=max_workers())


def _assemble(plan: _Plan, seed: int, outputs: Sequence[TrialOutput]) -> TrialSet:
    if len({None if o[3] is None else o[3].shape for o in outputs}) > 1:
        raise ResultFileError(
            f"{plan.condition.label}: the trial journal holds trials whose E^X per task component has "
            "another shape than the others' (a tampered line?): remove those lines to recompute them"
        )
    error = np.array([o[0] for o in outputs])
    return TrialSet(
        robot=robot_label(plan.condition.robot),
        seed=seed,
        parameters=plan.parameters,
        movements=plan.schedule,
        error=error,
        home_distance=np.array([o[1] for o in outputs]),
        # E_0 is the same for every trial (the estimate starts constant at q_home).
        initial_error=float(error[0, 0]),
        prototypes=np.array([o[2] for o in outputs], dtype=np.int64),
        components=None if any(o[3] is None for o in outputs) else np.array([o[3] for o in outputs]),
    )


def run_sweep(
    conditions: Sequence[Condition] | None = None,
    *,
    trials: int = 100,
    movements: int = 300,
    seed: int = 0,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    checkpoint: str | os.PathLike[str] | None = None,
    **grid: Any,
) -> Sweep:
    """Run independent trials for several conditions, all trials sharing one pool of workers.

    Give either ``conditions`` or a grid: ``robot`` and any babble argument as a value or
    a list of values, e.g. ``run_sweep(robot="planar5", learning_rate=[0.01, 0.1])`` or
    ``run_sweep(robot=["planar20", "planar50"])``; the grid is the Cartesian product,
    the first argument varying slowest.

    Args:
        conditions: the conditions to run.
        trials: trials per condition; trial i uses ``seed + i`` in every condition.
        movements: movements per trial (a condition's own ``movements`` overrides it).
        seed: seed of trial 0.
        workers: local processes; None = all local cores, 1 = in this process.
        scheduler: a Dask scheduler address (``"tcp://host:8786"``), a
            ``dask.distributed.Client``, a cluster object (``LocalCluster``, ``SLURMCluster``) or a
            SLURM spec (``"slurm:cores=4,memory=8GB,jobs=10"``, needs ``gb_pin[slurm]``): run the
            trials on that cluster instead, short trials several to a task (see
            :mod:`gb_pin.experiments.distributed`, docs/CLUSTERS.md); results are identical to a local run.
        progress: show a progress bar over all trials (tqdm).
        checkpoint: a :class:`~gb_pin.experiments.journal.TrialJournal` file: every finished
            trial is appended to it, and trials already in it are not run again (resume an
            interrupted sweep by running the same call again).
        **grid: ``robot`` and babble arguments (values or lists of values).

    Returns:
        A :class:`~gb_pin.experiments.conditions.Sweep`, ``results[i]`` for ``conditions[i]``.

    Raises:
        InvalidArgumentError: bad conditions or arguments (checked before any trial starts).
        GbPinError: the Dask cluster cannot be reached.
    """
    if conditions is None:
        conditions = conditions_grid(**grid)
    elif grid:
        raise InvalidArgumentError(f"give either conditions or grid arguments, not both (got {sorted(grid)})")
    conditions = list(conditions)
    if not conditions:
        raise InvalidArgumentError("a sweep needs at least one condition, got none")
    if len(conditions) > MAX_CONDITIONS:
        raise InvalidArgumentError(
            f"{len(conditions)} conditions; a sweep has at most {MAX_CONDITIONS} "
            "(gb_pin.experiments.conditions.MAX_CONDITIONS): split it into several sweeps"
        )
    trials = check.positive_int("trials", trials, maximum=MAX_TRIALS)
    if trials * len(conditions) > MAX_TRIALS:
        raise InvalidArgumentError(
            f"{trials} trials x {len(conditions)} conditions = {trials * len(conditions)} trials; a sweep "
            f"runs at most {MAX_TRIALS} (gb_pin.experiments.execute.MAX_TRIALS): split it into several"
        )
    movements = check.positive_int("movements", movements)
    seed = check.positive_int("seed", seed, minimum=0)
    workers = _check_executor(workers, scheduler)
    plans = [_plan(c, movements, seed) for c in conditions]
    tasks: list[TrialTask] = []
    costs: list[float] = []
    for p in plans:
        for i in range(trials):
            tasks.append((p.robot, p.movements, seed + i, p.schedule, p.parameters))
            costs.append(p.cost)
    desc = plans[0].condition.label if len(plans) == 1 else f"{len(plans)} conditions"
    journal = None if checkpoint is None else TrialJournal(checkpoint)
    outputs = _execute(tasks, costs, workers, scheduler, progress, desc, journal)
    results = tuple(_assemble(p, seed, outputs[k * trials : (k + 1) * trials]) for k, p in enumerate(plans))
    return Sweep(conditions=tuple(conditions), results=results)


def run_trials(
    robot: Any = "planar5",
    trials: int = 100,
    movements: int = 300,
    seed: int = 0,
    workers: int | None = None,
    *,
    schedule: Sequence[int] | None = None,
    progress: bool = False,
    scheduler: Any = None,
    checkpoint: str | os.PathLike[str] | None = None,
    **babble_args: Any,
) -> TrialSet:
    """Run independent goal-babbling trials (trial i uses seed + i) in parallel.

    Args:
        robot: preset name, MODULE:NAME, a simulated plant (``so101@mujoco:kp=10``), a KinematicTarget
            loaded from a URDF or example-robot-data (each worker rebuilds it from its robot source,
            onboarding included), or a
            :class:`~gb_pin.runs.spec.RunSpec` (then ``movements`` and ``seed`` are the spec's, and no
            babble arguments are given here).
        trials: number of trials.
        movements: movements per trial.
        seed: seed of trial 0.
        workers: processes; None = all local cores, 1 = in this process.
        schedule: movement counts to record (0 is always added); default
            :func:`~gb_pin.learn.metrics.evaluation_schedule`.
        progress: show a progress bar (tqdm).
        scheduler: a Dask scheduler address or ``dask.distributed.Client`` to run on
            (see :func:`run_sweep`).
        checkpoint: a trial journal file; finished trials in it are not recomputed
            (see :class:`~gb_pin.experiments.journal.TrialJournal`).
        **babble_args: the hyperparameters of :data:`gb_pin.learn.config.NAMES`
            (learning_rate, sigma, sigma_delta, radius, path_length, p_home, cutoff), goals, targets,
            eval_targets, and safe babbling's obstacles, self_collision, collision_geometry, clearance.

    Returns:
        A :class:`~gb_pin.experiments.trialset.TrialSet`; identical for any number of
        workers, locally or on Dask.
    """
    if isinstance(robot, RunSpec):  # the run's one description: its robot, movements and seed too
        if babble_args:
            raise InvalidArgumentError(
                f"give the run as a RunSpec or as arguments, not both: {sorted(babble_args)}"
            )
        robot, movements, seed, babble_args = robot.trial_arguments()
    if babble_args.get("obstacles") is not None:  # trials carry obstacles as plain tables (journal keys)
        from gb_pin.safety.obstacles import check_obstacles, plain

        babble_args = {
            **babble_args,
            "obstacles": [plain(o) for o in check_obstacles(babble_args["obstacles"])],
        }
    task_robot(robot)  # a robot that workers cannot rebuild is refused here
    check_parameters(babble_args)
    movements = check.positive_int("movements", movements)
    at = None if schedule is None else tuple(int(s) for s in resolve_schedule(schedule, movements))
    condition = Condition(robot=robot, parameters=babble_args, schedule=at)
    sweep = run_sweep(
        [condition],
        trials=trials,
        movements=movements,
        seed=seed,
        workers=workers,
        scheduler=scheduler,
        progress=progress,
        checkpoint=checkpoint,
    )
    return sweep.results[0]
