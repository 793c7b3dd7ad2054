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
from gb_pin.runs.results_file import read_result, write_result


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
        write_result(self, path)

    @classmethod
    def load(cls, path: str | os.PathLike[str], target: KinematicTarget | None = None) -> BabbleResult:
        """Read a result written by :meth:`save` (see :func:`load_result`)."""
        return cls(**read_result(path, target))


def save_result(result: BabbleResult, path: str | os.PathLike[str]) -> None:
    """Write ``result`` to ``path`` (an ``.npz`` archive of plain arrays and a JSON header).

    The file is written to a temporary name, flushed and renamed, so a crash never leaves half a file.
    """
    write_result(result, path)


def load_result(path: str | os.PathLike[str], target: KinematicTarget | None = None) -> BabbleResult:
    """Read a result written by :func:`save_result`.

    Args:
        path: the ``.npz`` file.
        target: the robot, needed only for results of a custom (non-preset) target.

    Raises:
        ResultFileError: missing, truncated, corrupted, foreign or newer-version file.
    """
    return BabbleResult.load(path, target)
