"""The numbers each figure reports, computed from a condition's trials.

Quantiles over trials (the paper's 10, 25, 50, 75 and 90 %), the speed S(Q, e) of Eq. 11,
and the first movement count at which the median E^X reaches the level of Sec. III-A.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gb_pin.experiments.trials import TrialSet
from gb_pin.reproduce.conditions import QUANTILES
from gb_pin.reproduce.paper import MEDIAN_LEVEL


def _opt(value: Any) -> Any:
    return None if value is None else int(value)


def first_median_below(ts: TrialSet, level: float) -> int | None:
    """First recorded movement count at which the median E^X over trials is <= ``level`` [m]."""
    med = np.median(ts.error, axis=0)
    hit = np.flatnonzero(med <= level)
    return int(ts.movements[hit[0]]) if hit.size else None


def speeds(ts: TrialSet, fraction: float = 0.1) -> dict[str, int | None]:
    """S(Q, fraction * E_0) (Eq. 11) for the five quantiles Q, keyed ``"0.1"`` ... ``"0.9"``."""
    return {f"{q:g}": _opt(ts.speed(q, fraction * ts.initial_error)) for q in QUANTILES}


def quantiles_at(ts: TrialSet, movements: int, metric: str) -> list[float]:
    """The five quantiles over trials of ``metric`` (``"error"``, ``"home_distance"``) at a movement count."""
    col = ts.at(movements)
    return [float(v) for v in np.quantile(getattr(ts, metric)[:, col], QUANTILES)]


def curve_numbers(ts: TrialSet, movements: int) -> dict[str, Any]:
    """The numbers of one E^X / D^home-over-movements curve (Figs. 4 and 7).

    Args:
        ts: the condition's trials.
        movements: the count N at which final errors are read.

    Returns:
        E_0, the speeds S(Q, 0.1 E_0), the median E^X after 100 movements, the first count
        with median E^X <= 0.04 m, the peak of the median D^home and the final quantiles.
    """
    med_d = np.median(ts.home_distance, axis=0)
    peak = int(np.argmax(med_d))
    out: dict[str, Any] = {
        "robot": ts.robot,
        "learning_rate": ts.parameters.get("learning_rate"),
        "length": int(ts.movements[-1]),
        "initial_error": ts.initial_error,
        "speed": speeds(ts),
        "median_error_at_100": float(np.median(ts.error[:, ts.at(100)])) if movements >= 100 else None,
        "first_median_le_0.04": first_median_below(ts, MEDIAN_LEVEL),
        "home_distance_median_peak": float(med_d[peak]),
        "home_distance_median_peak_at": int(ts.movements[peak]),
        "final_movements": movements,
        "final_error": quantiles_at(ts, movements, "error"),
        "final_home_distance": quantiles_at(ts, movements, "home_distance"),
    }
    return out


def row_numbers(ts: TrialSet, movements: int) -> dict[str, Any]:
    """The numbers of one point of Figs. 5 and 8: S(Q, 0.1 E_0), final E^X and D^home quantiles.

    Args:
        ts: the condition's trials.
        movements: the count N at which final errors are read (``end_error`` is read at
            the run's last movement, later for Fig. 5's low learning rates).
    """
    return {
        "robot": ts.robot,
        "learning_rate": ts.parameters.get("learning_rate"),
        "length": int(ts.movements[-1]),
        "initial_error": ts.initial_error,
        "speed": speeds(ts),
        "final_movements": movements,
        "final_error": quantiles_at(ts, movements, "error"),
        "final_home_distance": quantiles_at(ts, movements, "home_distance"),
        "end_error": [float(v) for v in np.quantile(ts.error[:, -1], QUANTILES)],
    }


def speedup(fast: int | None, slow: int | None) -> float | None:
    """Ratio of the movement counts two learning rates need to reach the median level (Fig. 4a)."""
    return None if fast is None or slow is None else slow / fast
