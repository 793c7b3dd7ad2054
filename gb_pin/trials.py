"""Independent trials of goal babbling, run in parallel on the local cores.

Trial i uses seed ``seed + i``, so a set of trials gives the same numbers
whatever the number of workers. Workers receive only the robot's name and the
parameters, never a model.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.api import babble
from gb_pin.exceptions import InvalidArgumentError, ResultFileError
from gb_pin.metrics import evaluation_schedule, speed
from gb_pin.robots import get_preset

_BABBLE_ARGS = ("learning_rate", "sigma", "sigma_delta", "radius", "path_length", "p_home")
_JSON_KEYS = ("movements", "error", "home_distance", "initial_error")


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

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the trials to a JSON file (atomically: temporary file, then rename)."""
        path = os.fspath(path)
        with open(path + ".tmp", "w", encoding="utf-8") as fh:
            json.dump(self.to_json(), fh)
        os.replace(path + ".tmp", path)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> TrialSet:
        """Read trials written by :meth:`save` (JSON, no pickle).

        Raises:
            ResultFileError: missing, malformed or foreign file.
        """
        path = os.fspath(path)
        try:
            with open(path, encoding="utf-8") as fh:
                raw = json.load(fh)
        except FileNotFoundError as exc:
            raise ResultFileError(f"{path}: no such file") from exc
        except (OSError, UnicodeDecodeError, ValueError) as exc:
            raise ResultFileError(f"{path}: not a readable JSON file ({exc})") from exc
        if not isinstance(raw, dict) or raw.get("format") != "gb_pin.trials":
            raise ResultFileError(f"{path}: not a gb_pin trials file")
        try:
            error = np.array(raw["error"], dtype=float, ndmin=2)
            out = cls(
                robot=str(raw["robot"]),
                seed=int(raw["seed"]),
                parameters=dict(raw["parameters"]),
                movements=np.array(raw["movements"], dtype=np.int64),
                error=error,
                home_distance=np.array(raw["home_distance"], dtype=float, ndmin=2),
                initial_error=float(raw["initial_error"]),
                prototypes=np.array(raw["prototypes"], dtype=np.int64),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ResultFileError(f"{path}: malformed trials file ({exc!r})") from exc
        if out.error.shape != out.home_distance.shape or out.error.shape[1] != out.movements.shape[0]:
            raise ResultFileError(f"{path}: arrays of inconsistent shapes")
        return out


def _one_trial(
    robot: str, movements: int, seed: int, schedule: NDArray[np.int64], kwargs: dict[str, Any]
) -> tuple[NDArray[np.float64], NDArray[np.float64], int]:
    result = babble(robot=robot, movements=movements, seed=seed, schedule=schedule, **kwargs)
    return result.history.error, result.history.home_distance, result.n_prototypes


def run_trials(
    robot: str = "planar5",
    trials: int = 100,
    movements: int = 300,
    seed: int = 0,
    workers: int | None = None,
    *,
    schedule: Sequence[int] | None = None,
    progress: bool = False,
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
            :func:`~gb_pin.metrics.evaluation_schedule`.
        progress: show a progress bar (tqdm).
        **babble_args: learning_rate, sigma, sigma_delta, radius, path_length, p_home.

    Returns:
        A :class:`TrialSet`; identical for any number of workers.
    """
    if not isinstance(robot, str):
        raise InvalidArgumentError(f"robot must be a preset name for run_trials, got {robot!r}")
    get_preset(robot)
    trials = check.positive_int("trials", trials)
    movements = check.positive_int("movements", movements)
    seed = check.positive_int("seed", seed, minimum=0)
    unknown = set(babble_args) - set(_BABBLE_ARGS)
    if unknown:
        raise InvalidArgumentError(f"unknown babble arguments {sorted(unknown)}; valid: {list(_BABBLE_ARGS)}")
    if workers is None:
        workers = os.cpu_count() or 1
    workers = check.positive_int("workers", workers)
    if schedule is None:
        at = evaluation_schedule(movements)
    else:
        # Movement 0 is always recorded: it gives E_0.
        at = np.unique(np.concatenate([[0], np.asarray(schedule, dtype=np.int64)]))
    # Run trial 0 here first: it validates the arguments with a clear error before any worker starts.
    first = _one_trial(robot, movements, seed, at, babble_args)
    results: list[Any] = [first] + [None] * (trials - 1)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=trials, unit="trial", desc=f"{robot} trials", initial=1)
    try:
        if workers == 1 or trials == 1:
            for i in range(1, trials):
                results[i] = _one_trial(robot, movements, seed + i, at, babble_args)
                if bar is not None:
                    bar.update(1)
        else:
            with ProcessPoolExecutor(max_workers=min(workers, trials - 1)) as pool:
                futures = {
                    pool.submit(_one_trial, robot, movements, seed + i, at, babble_args): i
                    for i in range(1, trials)
                }
                for fut in as_completed(futures):
                    results[futures[fut]] = fut.result()
                    if bar is not None:
                        bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    error = np.array([r[0] for r in results])
    home_distance = np.array([r[1] for r in results])
    # E_0 is the same for every trial (the estimate starts constant at q_home).
    initial_error = float(error[0, 0])
    return TrialSet(
        robot=robot,
        seed=seed,
        parameters=dict(babble_args),
        movements=at,
        error=error,
        home_distance=home_distance,
        initial_error=initial_error,
        prototypes=np.array([r[2] for r in results], dtype=np.int64),
    )
