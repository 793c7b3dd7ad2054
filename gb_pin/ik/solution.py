"""What the IK solver returns: :class:`IKSolution` (a batch of targets) and :class:`IKPath`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["IKPath", "IKSolution"]


@dataclass(frozen=True, eq=False)
class IKSolution:
    """Refined postures for a batch of targets.

    Attributes:
        targets: (N, n) the targets x* [m].
        postures: (N, m) the refined postures q, within the joint limits [rad] or [m].
        positions: (N, n) f(q), the positions the postures reach [m].
        residuals: (N,) ||x* - f(q)|| [m].
        iterations: (N,) int64, damped least-squares steps taken (0: the seed was good enough).
        success: (N,) bool, residual <= tol.
        seeds: (N, m) the postures the refinement started from, clipped to the limits.
        tol: the tolerance asked [m].
        seed: how the seeds were chosen: ``"learned"``, ``"home"`` or ``"given"``.
    """

    targets: NDArray[np.float64]
    postures: NDArray[np.float64]
    positions: NDArray[np.float64]
    residuals: NDArray[np.float64]
    iterations: NDArray[np.int64]
    success: NDArray[np.bool_]
    seeds: NDArray[np.float64]
    tol: float
    seed: str

    def __len__(self) -> int:
        return int(self.targets.shape[0])

    @property
    def success_rate(self) -> float:
        """Fraction of targets solved to ``tol``."""
        return float(np.mean(self.success)) if len(self) else 0.0

    def home_distance(self, home: NDArray[np.float64]) -> NDArray[np.float64]:
        """(N,) ||q - q_home|| of each posture [rad] (the paper's comfort measure, per target)."""
        return np.asarray(np.linalg.norm(self.postures - np.asarray(home, dtype=float), axis=1))

    def records(self) -> list[dict[str, Any]]:
        """One JSON-ready dict per target: target, posture, position, residual, iterations, success."""
        return [
            {
                "target": self.targets[r].tolist(),
                "posture": self.postures[r].tolist(),
                "position": self.positions[r].tolist(),
                "residual": float(self.residuals[r]),
                "iterations": int(self.iterations[r]),
                "success": bool(self.success[r]),
            }
            for r in range(len(self))
        ]

    def summary(self) -> str:
        """One line: solved fraction, iterations and the largest residual."""
        it = self.iterations
        return (
            f"{int(self.success.sum())}/{len(self)} solved to {self.tol:g} m (seed {self.seed}); "
            f"iterations median {np.median(it):g}, max {int(it.max()) if len(self) else 0}; "
            f"largest residual {float(self.residuals.max()) if len(self) else 0.0:.3g} m"
        )


@dataclass(frozen=True, eq=False)
class IKPath:
    """A joint path along a straight task-space line, each point solved by the IK.

    Attributes:
        solution: the points' :class:`IKSolution` (targets along the line, in order).
        joint_length: sum over the path of ||q_{i+1} - q_i|| [rad] (joint-space length).
        max_joint_step: the largest |q_{i+1,j} - q_{i,j}| of any joint between two points [rad].
    """

    solution: IKSolution
    joint_length: float
    max_joint_step: float

    @property
    def postures(self) -> NDArray[np.float64]:
        """(steps, m) the path's postures."""
        return self.solution.postures

    @property
    def all_solved(self) -> bool:
        """Whether every point of the path reached its target to ``tol``."""
        return bool(np.all(self.solution.success))

    @classmethod
    def of(cls, solution: IKSolution) -> IKPath:
        """The path of a solution whose targets are consecutive points of a line."""
        steps = np.diff(solution.postures, axis=0)
        length = float(np.linalg.norm(steps, axis=1).sum()) if steps.size else 0.0
        largest = float(np.abs(steps).max()) if steps.size else 0.0
        return cls(solution, length, largest)
