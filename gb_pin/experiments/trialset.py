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

from gb_pin._files import check_writable, write_json
from gb_pin._names import printable
from gb_pin._validation import INT64_MAX, MAX_MOVEMENTS
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
        components: (trials, T, C) E^X per task component of a stacked task ([m] for positions,
            [deg] for rotations; :mod:`gb_pin.learn.component_metrics`), None for the paper's task.
    """

    robot: str
    seed: int
    parameters: dict[str, Any]
    movements: NDArray[np.int64]
    error: NDArray[np.float64]
    home_distance: NDArray[np.float64]
    initial_error: float
    prototypes: NDArray[np.int64]
    components: NDArray[np.float64] | None = None

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
            **({} if self.components is None else {"components": self.components.tolist()}),
        }

    @classmethod
    def from_json(cls, raw: Any, source: str = "trials") -> TrialSet:
        """Rebuild a TrialSet from :meth:`to_json`'s dict.

        Raises:
            ResultFileError: not a gb_pin trials dict, or inconsistent arrays (``source`` names it).
        """
        if not isinstance(raw, dict) or raw.get("format") != FORMAT:
            raise ResultFileError(f"{source}: not a gb_pin trials file")
        _check_fields(raw, source)
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
                components=None
                if raw.get("components") is None
                else np.array(raw["components"], dtype=float),
            )
        except (KeyError, TypeError, ValueError, OverflowError) as exc:
            raise ResultFileError(f"{source}: malformed trials file ({str(exc)[:120]})") from exc
        trials, points = out.error.shape
        if (
            out.error.shape != out.home_distance.shape
            or out.movements.shape != (points,)
            or out.prototypes.shape != (trials,)
            or (
                out.components is not None
                and (out.components.ndim != 3 or out.components.shape[:2] != (trials, points))
            )
        ):
            raise ResultFileError(f"{source}: arrays of inconsistent shapes")
        if out.movements.size and (out.movements[0] < 0 or np.any(np.diff(out.movements) <= 0)):
            raise ResultFileError(f"{source}: movements must be increasing counts >= 0")
        curves = (out.error, out.home_distance, *(() if out.components is None else (out.components,)))
        if any(np.any(np.isinf(c) | (c < 0)) for c in curves):
            raise ResultFileError(f"{source}: infinite or negative E^X or D^home (a distance is >= 0)")
        return out

    def plot(self, path: str | os.PathLike[str] | None = None, ax: Any = None) -> Any:
        """Median and quartiles (10 % and 90 % thin) of E^X and D^home over movements, log axes.

        Args:
            path: write the figure there (``.png``, ``.svg``, ``.pdf``), if given.
            ax: draw into these matplotlib axes (D^home on a twin axis); default: a new two-panel figure.

        Returns:
            The ``matplotlib.figure.Figure``.

        Raises:
            GbPinError: matplotlib is not installed (``pip install 'gb_pin[plots]'``).
        """
        from gb_pin.runs.plot import plot_quantiles

        params = ", ".join(
            f"{k} {v:g}" if isinstance(v, float) else f"{k} {v}" for k, v in self.parameters.items()
        )
        final = float(np.median(self.error[:, -1]))
        title = (
            f"{printable(self.robot, 80)}: {self.trials} trials of {int(self.movements[-1])} movements"
            + (f" ({params})" if params else "")
            + f", median final $E^X$ = {final:.4g} m"
        )
        return plot_quantiles(title, self.movements, self.error, self.home_distance, path, ax)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the trials to a JSON file (atomically: :func:`gb_pin._files.write_json`)."""
        write_json(check_writable(path, "trial set file"), self.to_json())

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> TrialSet:
        """Read trials written by :meth:`save` (JSON, no pickle).

        Raises:
            ResultFileError: missing, malformed or foreign file.
        """
        path = os.fspath(path)
        return cls.from_json(read_json(path), path)


def _check_fields(raw: dict[str, Any], source: str) -> None:
    """Check the fields of a trials file before they are converted.

    robot a string, seed an int >= 0, parameters an object, initial_error a finite number >= 0,
    the arrays lists (of real numbers, checked when converted).

    Raises:
        ResultFileError: naming the field.
    """
    seed, e0 = raw.get("seed"), raw.get("initial_error")
    problems = {
        "robot": not isinstance(raw.get("robot"), str),
        "seed": isinstance(seed, bool) or not isinstance(seed, int) or seed < 0,
        "parameters": not isinstance(raw.get("parameters"), dict),
        "initial_error": isinstance(e0, bool)
        or not isinstance(e0, int | float)
        or not np.isfinite(e0)
        or e0 < 0,
    }
    for key in ("movements", "error", "home_distance", "prototypes"):
        problems[key] = not isinstance(raw.get(key), list)
    for key, top in (("movements", MAX_MOVEMENTS), ("prototypes", INT64_MAX)):  # whole counts, in int64
        found = raw.get(key)
        values: list[Any] = found if isinstance(found, list) else []
        problems[key] = problems[key] or not all(
            isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= top for v in values
        )
    for key in ("error", "home_distance"):  # (trials, T) numbers (NaN: not measured), no text
        problems[key] = problems[key] or not all(
            isinstance(row, list) and all(_is_number(v) for v in row) for row in raw[key]
        )
    problems["components"] = raw.get("components") is not None and not isinstance(raw["components"], list)
    wrong = [k for k, bad in problems.items() if bad]
    if wrong:
        raise ResultFileError(f"{source}: malformed trials file (bad {', '.join(wrong)})")


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)
