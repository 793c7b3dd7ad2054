"""BabbleResult: what a goal-babbling run learned and measured."""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin.learn.config import BabbleConfig
from gb_pin.learn.history import History, RecordedSteps
from gb_pin.learn.llm import LocalLinearMap
from gb_pin.robot.target import KinematicTarget


@dataclass(frozen=True, eq=False)
class BabbleResult:
    """What a goal-babbling run learned and measured.

    Attributes:
        target: the robot (:class:`~gb_pin.robot.target.KinematicTarget`).
        targets: (N, n) evaluation target set X* [m].
        history: E^X and D^home over movements.
        model: the learned local-linear map g.
        config: hyperparameters used.
        seed: the integer seed, or None if a Generator was given.
        robot: the preset name, or None for a custom target.
        movements: movements run.
        steps: time steps run.
        wall_time: seconds spent babbling (compilation excluded after the first call).
        recording: the recorded steps, if ``record`` was given.
    """

    target: KinematicTarget
    targets: NDArray[np.float64]
    history: History
    model: LocalLinearMap
    config: BabbleConfig
    seed: int | None
    robot: str | None
    movements: int
    steps: int
    wall_time: float
    recording: RecordedSteps | None = None

    def inverse(self, X: ArrayLike) -> NDArray[np.float64]:
        """Postures g(X) suggested by the inverse estimate: (N, n) -> (N, m), (n,) -> (m,)."""
        return self.model.predict(X)

    @property
    def error(self) -> float:
        """Final E^X [m]."""
        return float(self.history.error[-1])

    @property
    def home_distance(self) -> float:
        """Final D^home [rad]."""
        return float(self.history.home_distance[-1])

    @property
    def n_prototypes(self) -> int:
        """Number of local linear models K."""
        return self.model.n_prototypes_

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the result to one ``.npz`` file (no pickle); see :func:`gb_pin.load_result`."""
        from gb_pin.runs.results_file import save_result

        save_result(self, path)
