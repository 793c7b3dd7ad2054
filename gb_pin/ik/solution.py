"""What the IK solver returns: :class:`IKSolution` (a batch of targets) and :class:`IKPath`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.ik.search import IKOut
from gb_pin.ik.solver import IKSettings
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.learn.body.components import COMPONENT_KINDS, POSITION

__all__ = ["IKPath", "IKSolution"]


@dataclass(frozen=True, eq=False)
class IKSolution:
    """Postures for a batch of targets (k = the solutions asked; with k = 1 the k axis is absent).

    Attributes:
        targets: (N, n) the targets x* (task vectors).
        postures: (N, m), or (N, k, m) with k > 1: the solutions, within the joint limits, NaN
            rows where fewer were found; without a solution, the best posture found (row 0).
        positions: (N, n) or (N, k, n): f(q), the task vectors the postures reach.
        residuals: (N,) or (N, k): ||x* - f(q)|| in task units.
        errors: (N, C) or (N, k, C): each component's residual, [m] for positions, [rad] for
            orientations and pointing (the angle to the target).
        success: (N,) bool, at least one posture within the tolerances.
        found: (N,) int64, distinct solutions found (<= k).
        iterations: (N,) int64, damped least-squares steps over all attempts (0: the seed was good).
        restarts: (N,) int64, attempts after the first seed.
        seconds: (N,) the time of each query, its seed included [s] (one core, monotonic clock).
        seeds: (N, m) the postures the first attempt started from, clipped to the limits.
        tol: the position tolerance [m].
        angle_tol: the angle tolerance [rad].
        seed: how the seeds were chosen: ``"learned"``, ``"nearest"``, ``"home"``, ``"middle"``, ``"given"``.
        kinds: (C,) the components' kinds (``POSITION``, ``ORIENTATION``, ``POINTING``).
    """

    targets: NDArray[np.float64]
    postures: NDArray[np.float64]
    positions: NDArray[np.float64]
    residuals: NDArray[np.float64]
    errors: NDArray[np.float64]
    success: NDArray[np.bool_]
    found: NDArray[np.int64]
    iterations: NDArray[np.int64]
    restarts: NDArray[np.int64]
    seconds: NDArray[np.float64]
    seeds: NDArray[np.float64]
    tol: float
    angle_tol: float
    seed: str
    kinds: NDArray[np.int64]

    @classmethod
    def of(
        cls, targets: NDArray[np.float64], out: IKOut, settings: IKSettings, seed: str, chain: KinematicChain
    ) -> IKSolution:
        """The solution of the compiled search's output (the k axis dropped when k = 1)."""
        one = out.q.shape[1] == 1

        def pick(a: NDArray[Any]) -> NDArray[Any]:
            return a[:, 0] if one else a

        kinds = chain.components.kinds if chain.components is not None else np.array([POSITION])
        return cls(
            targets, pick(out.q), pick(out.x), pick(out.residual), pick(out.errors), out.found > 0,
            out.found, out.iterations, out.restarts, out.seconds, out.seeds, settings.tol,
            settings.angle_tol, seed, np.asarray(kinds, dtype=np.int64),
        )  # fmt: skip

    def __len__(self) -> int:
        return int(self.targets.shape[0])

    @property
    def success_rate(self) -> float:
        """Fraction of targets solved within the tolerances."""
        return float(np.mean(self.success)) if len(self) else 0.0

    @property
    def rotational(self) -> bool:
        """Whether the task has orientation or pointing components (``angle_tol`` applies)."""
        return bool(np.any(self.kinds != POSITION))

    def home_distance(self, home: NDArray[np.float64]) -> NDArray[np.float64]:
        """||q - q_home|| of each posture [rad]: (N,) (the paper's comfort measure, per target), or (N, k)."""
        return np.asarray(np.linalg.norm(self.postures - np.asarray(home, dtype=float), axis=-1))

    def records(self) -> list[dict[str, Any]]:
        """One JSON-ready dict per target: target, posture(s), position(s), residual(s), errors, counts."""
        one = self.postures.ndim == 2
        rows = []
        for r in range(len(self)):
            keep = slice(None) if one else slice(0, max(int(self.found[r]), 1))
            rows.append(
                {
                    "target": self.targets[r].tolist(),
                    "posture": self.postures[r][keep].tolist(),
                    "position": self.positions[r][keep].tolist(),
                    "residual": self.residuals[r][keep].tolist() if not one else float(self.residuals[r]),
                    "errors": self.errors[r][keep].tolist(),
                    "iterations": int(self.iterations[r]),
                    "restarts": int(self.restarts[r]),
                    "found": int(self.found[r]),
                    "success": bool(self.success[r]),
                }
            )
        return rows

    def summary(self) -> str:
        """One line: solved fraction, iterations, restarts and the largest residuals."""
        it = self.iterations
        tols = f"{self.tol:g} m" + (f" / {self.angle_tol:g} rad" if self.rotational else "")
        first = self.errors if self.errors.ndim == 2 else self.errors[:, 0]
        worst = [
            f"{float(np.nanmax(first[:, c])):.3g} {'m' if kind == POSITION else 'rad'}"
            for c, kind in enumerate(self.kinds)
        ] if len(self) else []  # fmt: skip
        names = [COMPONENT_KINDS[int(kind)] for kind in self.kinds]
        largest = ", ".join(f"{name} {w}" for name, w in zip(names, worst, strict=True))
        return (
            f"{int(self.success.sum())}/{len(self)} solved to {tols} (seed {self.seed}); "
            f"iterations median {np.median(it):g}, max {int(it.max()) if len(self) else 0}; "
            f"restarts {int(self.restarts.sum())}; largest residual {largest}"
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
        """Whether every point of the path reached its target within the tolerances."""
        return bool(np.all(self.solution.success))

    @classmethod
    def of(cls, solution: IKSolution) -> IKPath:
        """The path of a solution whose targets are consecutive points of a line."""
        steps = np.diff(solution.postures, axis=0)
        length = float(np.linalg.norm(steps, axis=1).sum()) if steps.size else 0.0
        largest = float(np.abs(steps).max()) if steps.size else 0.0
        return cls(solution, length, largest)
