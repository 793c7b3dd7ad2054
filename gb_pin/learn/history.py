"""What a run measures and records: E^X / D^home histories and recorded steps."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError


@dataclass(frozen=True)
class History:
    """E^X and D^home recorded during a run.

    Attributes:
        movements: (T,) movement counts r at which the model was evaluated (starts at 0).
        error: (T,) E^X (Eq. 9) [m].
        home_distance: (T,) D^home (Eq. 10) [rad].
        components: (T, C) for a stacked task: E^X split by task component ([m] for a
            position, [deg] for an orientation or pointing direction; see
            :mod:`gb_pin.learn.component_metrics`); None for the paper's position task.
        reach: (T,) the free measure of progress [m]: the median reach error the robot observed
            at the end of its last goal-directed movements (a window of 50 by default), less the
            exploration noise's share estimated with the learned Jacobian, ||x_L - W^+ delta -
            x*_L|| (:func:`gb_pin.learn.loop.noise_free_reach`), measured with no extra movement;
            it includes the sensor's noise. NaN before the first such movement; None in files
            written before it existed. (Before gb_pin 0.x's issue 30 it was ||x_L - x*_L||, which
            the exploration dominates: it rose while E^X fell.)
    """

    movements: NDArray[np.int64]
    error: NDArray[np.float64]
    home_distance: NDArray[np.float64]
    components: NDArray[np.float64] | None = None
    reach: NDArray[np.float64] | None = None

    @property
    def initial_error(self) -> float:
        """E_0: E^X at movement 0, of the constant estimate q_home [m]; NaN if movement 0 was not recorded."""
        idx = np.flatnonzero(self.movements == 0)
        return float(self.error[idx[0]]) if idx.size else math.nan

    def at(self, movements: int) -> tuple[float, float]:
        """(E^X, D^home) at a recorded movement count."""
        idx = np.flatnonzero(self.movements == movements)
        if not idx.size:
            raise InvalidArgumentError(
                f"movements={movements!r} was not recorded; recorded: "
                f"{self.movements[0]}..{self.movements[-1]} (see History.movements)"
            )
        return float(self.error[idx[0]]), float(self.home_distance[idx[0]])


def versus_initial(error: float, initial: float, unit: str = " m") -> str:
    """E^X against E_0 for a summary: ``"E_0 = 0.3922 m, 1.5% of E_0"``, or why there is no ratio.

    E_0 is 0 when home reaches every target (then any E^X is infinitely many E_0), and NaN when
    movement 0 was not recorded.
    """
    if math.isnan(initial):
        return "E_0 not recorded: the schedule has no movement 0"
    if initial <= 0.0:
        return f"E_0 = 0{unit}: home reaches every target, no ratio to E_0"
    return f"E_0 = {initial:.4f}{unit}, {error / initial:.1%} of E_0"


@dataclass(frozen=True)
class Recording:
    """Which steps of a run to record (for replay and viewers).

    Attributes:
        every: record every ``every``-th time step.
        first: first movement recorded.
        last: movements ``first <= r < last`` are recorded; None for all.
    """

    every: int = 1
    first: int = 0
    last: int | None = None

    def __post_init__(self) -> None:
        check.positive_int("every", self.every)
        check.positive_int("first", self.first, minimum=0)
        if self.last is not None:
            check.positive_int("last", self.last, minimum=self.first)


@dataclass(frozen=True)
class RecordedSteps:
    """Recorded steps of a run.

    Attributes:
        step: (R,) time step t (1-based).
        movement: (R,) movement r the step belongs to.
        posture: (R, m) executed posture q_t.
        target: (R, n) target x*_t [m]; NaN during home returns.
        position: (R, n) reached position x_t = f(q_t) [m].
    """

    step: NDArray[np.int64]
    movement: NDArray[np.int64]
    posture: NDArray[np.float64]
    target: NDArray[np.float64]
    position: NDArray[np.float64]

    FIELDS = ("step", "movement", "posture", "target", "position")
    DTYPES = (np.int64, np.int64, np.float64, np.float64, np.float64)

    def to_arrays(self, prefix: str = "rec_") -> dict[str, NDArray[Any]]:
        """The arrays under the names files use (``rec_step``, ``rec_movement``, ...)."""
        return {prefix + k: getattr(self, k) for k in self.FIELDS}

    @classmethod
    def from_arrays(
        cls, arrays: dict[str, Any], n_joints: int, n_task: int, prefix: str = "rec_"
    ) -> RecordedSteps | None:
        """The recording stored under ``prefix`` names, None if there is none.

        Raises:
            InvalidArgumentError: some of the arrays missing, or of inconsistent shapes.
        """
        keys = [prefix + k for k in cls.FIELDS]
        present = [k for k in keys if k in arrays]
        if not present:
            return None
        if len(present) != len(keys):
            raise InvalidArgumentError(f"incomplete recording (has {present})")
        raw = {k: np.asarray(arrays[prefix + k]) for k in cls.FIELDS}
        if not all(a.dtype.kind in "iuf" and a.ndim >= 1 for a in raw.values()):
            raise InvalidArgumentError("recording arrays must be arrays of real numbers")
        values: dict[str, Any] = {
            k: raw[k].astype(dtype) for k, dtype in zip(cls.FIELDS, cls.DTYPES, strict=True)
        }
        rec = cls(**values)
        R = rec.step.shape[0]
        shapes_ok = (
            rec.step.shape == (R,)
            and rec.movement.shape == (R,)
            and rec.posture.shape == (R, n_joints)
            and rec.target.shape == (R, n_task)
            and rec.position.shape == (R, n_task)
        )
        if not shapes_ok:
            raise InvalidArgumentError("recording arrays of inconsistent shapes")
        return rec
