"""The trials of one condition: E^X and D^home of every trial, S(Q, e), quantiles, a JSON file.

A :class:`TrialSet` is what :func:`~gb_pin.experiments.execute.run_trials` returns and what
``gb-pin trials --json`` writes (``"format": "gb_pin.trials"``, version 1).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin._files import write_json
from gb_pin.exceptions import InvalidArgumentError, ResultFileError
from gb_pin.experiments._json import read_json
from gb_pin.learn.metrics import speed

FORMAT = "gb_pin.trials"
FORMAT_VERSION = 1


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
            "format": FORMAT,
            "format_version": FORMAT_VERSION,
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
        if not isinstance(raw, dict) or raw.get("format") != FORMAT:
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
        """Write the trials to a JSON file (atomically: :func:`gb_pin._files.write_json`)."""
        write_json(path, self.to_json())

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> TrialSet:
        """Read trials written by :meth:`save` (JSON, no pickle).

        Raises:
            ResultFileError: missing, malformed or foreign file.
        """
        path = os.fspath(path)
        return cls.from_json(read_json(path), path)
