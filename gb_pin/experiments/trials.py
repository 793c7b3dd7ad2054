"""Independent trials and sweeps of goal babbling, run in parallel on local cores or on a Dask cluster.

Trial i of a condition uses seed ``seed + i``, so a set of trials gives the same
numbers whatever runs it: one process, a local process pool, or a Dask cluster
(:mod:`gb_pin.experiments.distributed`). A task carries only the robot's preset name, the
parameters, the seed and the movement counts to record, never a model: every
worker builds its robot from the name.
"""

from __future__ import annotations

import itertools
import json
import os
from collections.abc import Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError, ResultFileError
from gb_pin.learn.metrics import evaluation_schedule, speed
from gb_pin.robot.presets import get_preset
from gb_pin.runs.api import babble

BABBLE_ARGS = ("learning_rate", "sigma", "sigma_delta", "radius", "path_length", "p_home")
_JSON_KEYS = ("movements", "error", "home_distance", "initial_error")

# What one trial needs: (robot name, movements, seed, movement counts to record, babble arguments).
TrialTask = tuple[str, int, int, NDArray[np.int64], dict[str, Any]]
TrialOutput = tuple[NDArray[np.float64], NDArray[np.float64], int]


@dataclass(frozen=True, eq=False)
class TrialSet:
    """E^X and D^home of independent trials on one robot with one set of parameters.

    Attributes:
        robot: preset name.
        seed: seed of trial 0 (trial i used ``seed + i``).
        parameters: the babble arguments given (learning_rate, sigma, ...).
        movements: (T,) recorded movement counts, shared by all trials.
        error: (trials, T) E^X (Eq. 9) [m].
        home_distance: (trials, T) D^home (Eq. 10) [rad].
        initial_error: E_0, the error of the initial constant estimate q_home [m].
        prototypes: (trials,) prototypes at the end of each trial.
    """

    robot: str
    seed: int
    parameters: dict[str, Any]
    movements: NDArray[np.int64]
    error: NDArray[np.float64]
    home_distance: NDArray[np.float64]
    initial_error: float
    prototypes: NDArray[np.int64]

    @property
    def trials(self) -> int:
        """Number of trials."""
        return int(self.error.shape[0])

    def speed(self, quantile: float, level: float) -> int | None:
        """S(Q, e) of Eq. 11: first recorded movement count where a fraction >= Q of trials has E^X <= e."""
        return speed(self.movements, self.error, quantile, level)

    def quantiles(
        self, q: Sequence[float] = (0.1, 0.25, 0.5, 0.75, 0.9), metric: str = "error"
    ) -> NDArray[np.float64]:
        """Quantiles over trials at every recorded movement count: shape (len(q), T).

        Args:
            q: quantile levels in [0, 1].
            metric: ``"error"`` (E^X) or ``"home_distance"`` (D^home).
        """
        if metric not in ("error", "home_distance"):
            raise InvalidArgumentError(f"metric must be 'error' or 'home_distance', got {metric!r}")
        levels = np.asarray(q, dtype=float)
        if levels.ndim != 1 or np.any(~np.isfinite(levels)) or np.any((levels < 0) | (levels > 1)):
            raise InvalidArgumentError(f"q must be quantile levels in [0, 1], got {q!r}")
        return np.quantile(getattr(self, metric), levels, axis=0)

    def at(self, movements: int) -> int:
        """Column of ``error`` / ``home_distance`` recorded at a movement count.

        Raises:
            InvalidArgumentError: that movement count was not recorded.
        """
        idx = np.flatnonzero(self.movements == movements)
        if not idx.size:
            raise InvalidArgumentError(
                f"movements={movements!r} was not recorded; recorded: {self.movements[0]}.."
                f"{self.movements[-1]} (pass it in schedule=)"
            )
        return int(idx[0])

    def to_json(self) -> dict[str, Any]:
        """A JSON-serialisable dict (``movements``, ``error``, ``home_distance``, ``initial_error``, ...)."""
        return {
            "format": "gb_pin.trials",
            "format_version": 1,
            "robot": self.robot,
            "seed": self.seed,
            "parameters": self.parameters,
            "movements": self.movements.tolist(),
            "error": self.error.tolist(),
            "home_distance": self.home_distance.tolist(),
            "initial_error": self.initial_error,
            "prototypes": self.prototypes.tolist(),
        }

    @classmethod
    def from_json(cls, raw: Any, source: str = "trials") -> TrialSet:
        """Rebuild a TrialSet from :meth:`to_json`'s dict.

        Raises:
            ResultFileError: not a gb_pin trials dict, or inconsistent arrays (``source`` names it).
        """
        if not isinstance(raw, dict) or raw.get("format") != "gb_pin.trials":
            raise ResultFileError(f"{source}: not a gb_pin trials file")
        try:
            out = cls(
                robot=str(raw["robot"]),
                seed=int(raw["seed"]),
                parameters=dict(raw["parameters"]),
                movements=np.array(raw["movements"], dtype=np.int64),
                error=np.array(raw["error"], dtype=float, ndmin=2),
                home_distance=np.array(raw["home_distance"], dtype=float, ndmin=2),
                initial_error=float(raw["initial_error"]),
                prototypes=np.array(raw["prototypes"], dtype=np.int64),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ResultFileError(f"{source}: malformed trials file ({exc!r})") from exc
        if out.error.shape != out.home_distance.shape or out.error.shape[1] != out.movements.shape[0]:
            raise ResultFileError(f"{source}: arrays of inconsistent shapes")
        return out

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the trials to a JSON file (atomically: temporary file, then rename)."""
        _write_json(path, self.to_json())

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> TrialSet:
        """Read trials written by :meth:`save` (JSON, no pickle).

        Raises:
            ResultFileError: missing, malformed or foreign file.
        """
        path = os.fspath(path)
        return cls.from_json(_read_json(path), path)


@dataclass(frozen=True)
class Condition:
    """One experimental condition of a sweep: a robot and babble parameters.

    Attributes:
        robot: preset name, e.g. ``"planar5"``.
        parameters: babble arguments (``learning_rate``, ``sigma``, ``sigma_delta``,
            ``radius``, ``path_length``, ``p_home``); the rest take the preset's defaults.
        movements: movements per trial; None takes the sweep's.
        schedule: movement counts to record (0 is always added); None: the default
            :func:`~gb_pin.learn.metrics.evaluation_schedule` of the run length.
    """

    robot: str = "planar5"
    parameters: Mapping[str, Any] = field(default_factory=dict)
    movements: int | None = None
    schedule: tuple[int, ...] | None = None

    def __hash__(self) -> int:
        return hash((self.robot, tuple(sorted(self.parameters.items())), self.movements, self.schedule))

    @property
    def label(self) -> str:
        """A short readable name, e.g. ``planar5 learning_rate=0.1``."""
        parts = [self.robot, *(f"{k}={v:g}" for k, v in sorted(self.parameters.items()))]
        return " ".join(parts)

    def to_json(self) -> dict[str, Any]:
        """A JSON-serialisable dict."""
        return {
            "robot": self.robot,
            "parameters": dict(self.parameters),
            "movements": self.movements,
            "schedule": None if self.schedule is None else list(self.schedule),
        }

    @classmethod
    def from_json(cls, raw: Mapping[str, Any]) -> Condition:
        """Rebuild a condition from :meth:`to_json`'s dict."""
        sched = raw.get("schedule")
        mv = raw.get("movements")
        return cls(
            robot=str(raw["robot"]),
            parameters=dict(raw.get("parameters", {})),
            movements=None if mv is None else int(mv),
            schedule=None if sched is None else tuple(int(s) for s in sched),
        )


@dataclass(frozen=True, eq=False)
class Sweep:
    """Trials of several conditions: ``results[i]`` holds the trials of ``conditions[i]``.

    Iterating yields ``(condition, trial_set)`` pairs.
    """

    conditions: tuple[Condition, ...]
    results: tuple[TrialSet, ...]

    def __len__(self) -> int:
        return len(self.conditions)

    def __iter__(self) -> Iterator[tuple[Condition, TrialSet]]:
        return iter(zip(self.conditions, self.results, strict=True))

    def __getitem__(self, index: int) -> TrialSet:
        return self.results[index]

    def to_json(self) -> dict[str, Any]:
        """A JSON-serialisable dict: the conditions and each one's trials."""
        return {
            "format": "gb_pin.sweep",
            "format_version": 1,
            "conditions": [c.to_json() for c in self.conditions],
            "results": [r.to_json() for r in self.results],
        }

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the sweep to one JSON file (no pickle)."""
        _write_json(path, self.to_json())

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Sweep:
        """Read a sweep written by :meth:`save`.

        Raises:
            ResultFileError: missing, malformed or foreign file.
        """
        path = os.fspath(path)
        raw = _read_json(path)
        if not isinstance(raw, dict) or raw.get("format") != "gb_pin.sweep":
            raise ResultFileError(f"{path}: not a gb_pin sweep file")
        try:
            conditions = tuple(Condition.from_json(c) for c in raw["conditions"])
            results = tuple(TrialSet.from_json(r, path) for r in raw["results"])
        except (KeyError, TypeError, ValueError) as exc:
            raise ResultFileError(f"{path}: malformed sweep file ({exc!r})") from exc
        if len(conditions) != len(results):
            raise ResultFileError(f"{path}: {len(conditions)} conditions but {len(results)} results")
        return cls(conditions=conditions, results=results)


def _write_json(path: str | os.PathLike[str], data: Any) -> None:
    path = os.fspath(path)
    with open(path + ".tmp", "w", encoding="utf-8") as fh:
        json.dump(data, fh)
    os.replace(path + ".tmp", path)


def _read_json(path: str) -> Any:
    try:
        with open(path, encoding="utf-8") as fh:
            return json.load(fh)
    except FileNotFoundError as exc:
        raise ResultFileError(f"{path}: no such file") from exc
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ResultFileError(f"{path}: not a readable JSON file ({exc})") from exc


def run_one_trial(
    robot: str, movements: int, seed: int, schedule: NDArray[np.int64], kwargs: dict[str, Any]
) -> TrialOutput:
    """One trial, as a worker runs it: (E^X, D^home at ``schedule``, prototypes).

    Module-level and fed only plain values, so that a process pool or a Dask worker
    receives the robot's name, never a model.
    """
    result = babble(robot=robot, movements=movements, seed=seed, schedule=schedule, **kwargs)
    return result.history.error, result.history.home_distance, result.n_prototypes


def _resolve_schedule(schedule: ArrayLike | None, movements: int) -> NDArray[np.int64]:
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
    movements: int
    schedule: NDArray[np.int64]
    parameters: dict[str, Any]
    cost: float  # estimated work of one trial, to start the longest first


def _plan(condition: Condition, movements: int, seed: int) -> _Plan:
    """Validate a condition with a one-movement run here, before any worker starts."""
    if not isinstance(condition, Condition):
        raise InvalidArgumentError(f"conditions must be gb_pin.Condition objects, got {condition!r}")
    if not isinstance(condition.robot, str):
        raise InvalidArgumentError(f"robot must be a preset name for trials, got {condition.robot!r}")
    get_preset(condition.robot)
    parameters = dict(condition.parameters)
    unknown = set(parameters) - set(BABBLE_ARGS)
    if unknown:
        raise InvalidArgumentError(f"unknown babble arguments {sorted(unknown)}; valid: {list(BABBLE_ARGS)}")
    length = (
        movements if condition.movements is None else check.positive_int("movements", condition.movements)
    )
    at = _resolve_schedule(condition.schedule, length)
    probe = babble(robot=condition.robot, movements=1, seed=seed, schedule=[0, 1], **parameters)
    return _Plan(condition, length, at, parameters, float(length) * (probe.target.n_joints + 5))


class TrialJournal:
    """Finished trials, appended one JSON line each, so an interrupted sweep recomputes nothing finished.

    Each line holds a trial's key (robot, movements, seed, schedule, parameters) and its
    output; lines are flushed and fsynced as trials finish. A crash mid-write leaves at
    most one incomplete last line, which is ignored. The file can be shared by several
    sweeps: a trial is reused only if every part of its key matches.

    Args:
        path: the journal file (created if missing).

    Raises:
        ResultFileError: the file exists but is not a gb_pin trial journal.
    """

    HEADER: ClassVar[dict[str, Any]] = {"format": "gb_pin.trial-journal", "format_version": 1}

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = os.fspath(path)
        self.done: dict[str, TrialOutput] = {}
        if os.path.exists(self.path):
            self._read()
        else:
            with open(self.path, "w", encoding="utf-8") as fh:
                fh.write(json.dumps(self.HEADER) + "\n")

    @staticmethod
    def key(task: TrialTask) -> str:
        """A canonical string naming one trial."""
        robot, movements, seed, schedule, parameters = task
        return json.dumps(
            [
                robot,
                int(movements),
                int(seed),
                [int(v) for v in schedule],
                {k: _plain(v) for k, v in parameters.items()},
            ],
            sort_keys=True,
        )

    def _read(self) -> None:
        try:
            with open(self.path, encoding="utf-8") as fh:
                lines = fh.read().split("\n")
        except (OSError, UnicodeDecodeError) as exc:
            raise ResultFileError(f"{self.path}: unreadable trial journal ({exc})") from exc
        try:
            header = json.loads(lines[0])
        except ValueError:
            header = None
        if header != self.HEADER:
            raise ResultFileError(f"{self.path}: not a gb_pin trial journal (first line {lines[0][:80]!r})")
        complete = []
        for line in lines[1:]:
            try:
                entry = json.loads(line)
                out = (
                    np.array(entry["error"], dtype=float),
                    np.array(entry["home_distance"], dtype=float),
                    int(entry["prototypes"]),
                )
                self.done[str(entry["key"])] = out
                complete.append(line)
            except (ValueError, KeyError, TypeError):
                continue  # the last line of a run killed mid-write
        # Rewrite without a torn line, so that appended lines start on a fresh line.
        if len(complete) != len([ln for ln in lines[1:] if ln]):
            tmp = self.path + ".tmp"
            with open(tmp, "w", encoding="utf-8") as fh:
                fh.write("\n".join([lines[0], *complete]) + "\n")
            os.replace(tmp, self.path)

    def record(self, task: TrialTask, out: TrialOutput) -> None:
        """Append one finished trial durably."""
        k = self.key(task)
        self.done[k] = out
        line = json.dumps(
            {"key": k, "error": out[0].tolist(), "home_distance": out[1].tolist(), "prototypes": int(out[2])}
        )
        with open(self.path, "a", encoding="utf-8") as fh:
            fh.write(line + "\n")
            fh.flush()
            os.fsync(fh.fileno())


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
            results[i] = journal.done.get(TrialJournal.key(task))
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

            sub = [tasks[i] for i in todo]

            def done_sub(k: int, out: TrialOutput) -> None:
                done(todo[k], out)

            map_tasks(run_one_trial, sub, scheduler, done_sub, priorities=[costs[i] for i in todo])
        elif not todo:
            pass
        elif workers == 1 or len(todo) == 1:
            for i in order:
                done(i, run_one_trial(*tasks[i]))
        else:
            with ProcessPoolExecutor(max_workers=min(workers or 1, len(todo))) as pool:
                futures = {pool.submit(run_one_trial, *tasks[i]): i for i in order}
                for fut in as_completed(futures):
                    done(futures[fut], fut.result())
    finally:
        if bar is not None:
            bar.close()
    return [r for r in results if r is not None]


def _check_executor(workers: int | None, scheduler: Any) -> int | None:
    if scheduler is not None:
        if workers is not None:
            raise InvalidArgumentError(
                f"workers={workers!r} cannot be combined with a Dask scheduler: the cluster's workers run "
                "the trials (leave workers=None)"
            )
        return None
    if workers is None:
        workers = os.cpu_count() or 1
    return check.positive_int("workers", workers)


def _assemble(plan: _Plan, seed: int, outputs: Sequence[TrialOutput]) -> TrialSet:
    error = np.array([o[0] for o in outputs])
    return TrialSet(
        robot=plan.condition.robot,
        seed=seed,
        parameters=plan.parameters,
        movements=plan.schedule,
        error=error,
        home_distance=np.array([o[1] for o in outputs]),
        # E_0 is the same for every trial (the estimate starts constant at q_home).
        initial_error=float(error[0, 0]),
        prototypes=np.array([o[2] for o in outputs], dtype=np.int64),
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
        scheduler: a Dask scheduler address (``"tcp://host:8786"``) or a
            ``dask.distributed.Client``: run the trials on that cluster instead
            (see :mod:`gb_pin.experiments.distributed`); results are identical to a local run.
        progress: show a progress bar over all trials (tqdm).
        checkpoint: a :class:`TrialJournal` file: every finished trial is appended to it,
            and trials already in it are not run again (resume an interrupted sweep by
            running the same call again).
        **grid: ``robot`` and babble arguments (values or lists of values).

    Returns:
        A :class:`Sweep`, ``results[i]`` for ``conditions[i]``.

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
    trials = check.positive_int("trials", trials)
    movements = check.positive_int("movements", movements)
    seed = check.positive_int("seed", seed, minimum=0)
    workers = _check_executor(workers, scheduler)
    plans = [_plan(c, movements, seed) for c in conditions]
    tasks: list[TrialTask] = []
    costs: list[float] = []
    for p in plans:
        for i in range(trials):
            tasks.append((p.condition.robot, p.movements, seed + i, p.schedule, p.parameters))
            costs.append(p.cost)
    desc = plans[0].condition.label if len(plans) == 1 else f"{len(plans)} conditions"
    journal = None if checkpoint is None else TrialJournal(checkpoint)
    outputs = _execute(tasks, costs, workers, scheduler, progress, desc, journal)
    results = tuple(_assemble(p, seed, outputs[k * trials : (k + 1) * trials]) for k, p in enumerate(plans))
    return Sweep(conditions=tuple(conditions), results=results)


def conditions_grid(robot: str | Sequence[str] = "planar5", **parameters: Any) -> list[Condition]:
    """The Cartesian product of a robot (or robots) and babble arguments given as values or lists.

    >>> [c.label for c in conditions_grid("planar5", learning_rate=[0.01, 0.1])]
    ['planar5 learning_rate=0.01', 'planar5 learning_rate=0.1']
    """
    unknown = set(parameters) - set(BABBLE_ARGS)
    if unknown:
        raise InvalidArgumentError(
            f"unknown sweep arguments {sorted(unknown)}; valid: robot, {', '.join(BABBLE_ARGS)}"
        )

    def values(name: str, v: Any) -> list[Any]:
        out = [v] if isinstance(v, str) or not isinstance(v, Sequence | np.ndarray) else list(v)
        if not out:
            raise InvalidArgumentError(f"{name} must list at least one value, got {v!r}")
        return out

    robots = values("robot", robot)
    names = list(parameters)
    lists = [values(n, parameters[n]) for n in names]
    return [
        Condition(robot=r, parameters={n: _plain(v) for n, v in zip(names, combo, strict=True)})
        for r in robots
        for combo in itertools.product(*lists)
    ]


def _plain(value: Any) -> Any:
    """numpy scalars as Python numbers (JSON and labels)."""
    return value.item() if isinstance(value, np.generic) else value


def run_trials(
    robot: str = "planar5",
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
        robot: preset name.
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
            (see :class:`TrialJournal`).
        **babble_args: learning_rate, sigma, sigma_delta, radius, path_length, p_home.

    Returns:
        A :class:`TrialSet`; identical for any number of workers, locally or on Dask.
    """
    if not isinstance(robot, str):
        raise InvalidArgumentError(f"robot must be a preset name for run_trials, got {robot!r}")
    unknown = set(babble_args) - set(BABBLE_ARGS)
    if unknown:
        raise InvalidArgumentError(f"unknown babble arguments {sorted(unknown)}; valid: {list(BABBLE_ARGS)}")
    movements = check.positive_int("movements", movements)
    at = None if schedule is None else tuple(int(s) for s in _resolve_schedule(schedule, movements))
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
