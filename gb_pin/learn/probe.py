"""Evaluation movements: E^X (Eq. 9) measured on the robot itself, for robots without a model.

On hardware nothing computes f(g(x*)): the robot must go there. An :class:`EvaluationMoves`
is the sequence of postures a session asks for one evaluation: for each test target x*_i the
posture g(x*_i) clipped to the limits (an ``"evaluation"`` ask, whose reading is kept), each
reached through ``"transit"`` asks when a joint-step limit would be exceeded, and finally back to
the posture the learning left off at, so that learning continues where it stopped. Nothing is
learnt from any of them and no random number is drawn: a run with evaluation movements learns
exactly what the same run without them learns.

E^X is the mean distance between each test target and its reading. A missing reading is asked
again (the arm holds still), up to ``retries`` times; a target never observed is left out of the
mean (and counted in :attr:`EvaluationMoves.unobserved`).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

EVALUATION = "evaluation"
TRANSIT = "transit"


def joint_path(
    start: NDArray[np.float64], end: NDArray[np.float64], max_step: float
) -> list[NDArray[np.float64]]:
    """Postures from ``start`` (excluded) to ``end`` (included), no joint moving more than ``max_step``.

    A straight line in joint space in equal steps; one step when ``max_step`` is inf or not exceeded.
    """
    span = float(np.max(np.abs(end - start))) if start.size else 0.0
    k = 1 if not math.isfinite(max_step) or span <= max_step else math.ceil(span / max_step)
    return [start + (end - start) * (i / k) for i in range(1, k)] + [end.copy()]


class EvaluationMoves:
    """The asks of one evaluation: test postures (and transits), then back to where learning stopped.

    Args:
        targets: (N, n) the test set X* [m].
        postures: (N, m) g(x*_i) clipped to the joint limits.
        start: (m,) the posture the robot holds now (the last executed one).
        max_step: the largest joint step per ask ([rad] or [m]; inf: none).
        retries: asks of the same posture after a missing reading, before the target is given up.
    """

    def __init__(
        self,
        targets: NDArray[np.float64],
        postures: NDArray[np.float64],
        start: NDArray[np.float64],
        max_step: float,
        retries: int = 10,
    ) -> None:
        self.targets = targets
        self.retries = int(retries)
        plan: list[tuple[str, int, NDArray[np.float64]]] = []
        here = start
        for i, q in enumerate(postures):
            plan += [(TRANSIT, -1, p) for p in joint_path(here, q, max_step)[:-1]]
            plan.append((EVALUATION, i, q.copy()))
            here = q
        plan += [(TRANSIT, -1, p) for p in joint_path(here, start, max_step)]
        self._plan = plan
        self._next = 0
        self._tries = 0
        self.readings = np.full(targets.shape, np.nan)

    @property
    def done(self) -> bool:
        """Whether every ask of the plan has been answered."""
        return self._next >= len(self._plan)

    @property
    def kind(self) -> str:
        """What the next ask is: ``"evaluation"`` (its reading counts) or ``"transit"`` (ignored)."""
        return self._plan[self._next][0]

    def ask(self) -> NDArray[np.float64]:
        """The next posture (m,) to execute."""
        return self._plan[self._next][2].copy()

    def tell(self, x: NDArray[np.float64] | None) -> None:
        """The reading at the last asked posture (None: missing; then an evaluation ask is repeated)."""
        kind, i, _ = self._plan[self._next]
        if kind == EVALUATION:
            if x is None and self._tries < self.retries:
                self._tries += 1
                return
            if x is not None:
                self.readings[i] = x
        self._tries = 0
        self._next += 1

    @property
    def unobserved(self) -> int:
        """Test targets whose reading never arrived."""
        return int(np.sum(np.isnan(self.readings[:, 0])))

    def error(self) -> float:
        """E^X over the observed test targets [m] (NaN if none was observed)."""
        seen = ~np.isnan(self.readings[:, 0])
        if not np.any(seen):
            return math.nan
        return float(np.mean(np.linalg.norm(self.targets[seen] - self.readings[seen], axis=1)))
