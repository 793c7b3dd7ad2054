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
from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import InvalidArgumentError

EVALUATION = "evaluation"
TRANSIT = "transit"


MAX_PATH_ASKS = 10**9
"""The most asks of one joint path (a path longer than this is refused: ``max_joint_step`` too small)."""
MAX_PLANNED_ASKS = 10**6
"""The most asks of one evaluation's plan (kept in memory: about 150 bytes an ask)."""


def path_steps(start: NDArray[np.float64], end: NDArray[np.float64], max_step: float) -> int:
    """The asks from ``start`` to ``end`` with no joint moving more than ``max_step`` per ask.

    Raises:
        InvalidArgumentError: more than :data:`MAX_PATH_ASKS` (``max_step`` far too small).
    """
    span = float(np.max(np.abs(end - start))) if start.size else 0.0
    if not math.isfinite(max_step) or span <= max_step:
        return 1
    k = span / max_step
    if not k <= MAX_PATH_ASKS:
        raise InvalidArgumentError(
            f"max_joint_step={max_step!r} makes a joint path of {k:.3g} asks (a joint moves {span:.3g}), "
            f"more than {MAX_PATH_ASKS:g}: raise max_joint_step"
        )
    return math.ceil(k)


class JointPath:
    """Postures from ``start`` (excluded) to ``end`` (included), no joint moving more than ``max_step``.

    A straight line in joint space in equal steps (one step when ``max_step`` is inf or not
    exceeded), computed one posture at a time: a tiny ``max_step`` costs asks, not memory (the
    whole path as a list took 2.7 GB and growing). It reads as the list of the postures left:
    ``len``, ``path[i]``, ``pop(0)`` (the next posture, then advance), iteration.

    Raises:
        InvalidArgumentError: more than :data:`MAX_PATH_ASKS` asks.
    """

    def __init__(self, start: NDArray[np.float64], end: NDArray[np.float64], max_step: float) -> None:
        self.steps = path_steps(start, end, max_step)
        self._start, self._delta, self._end = start.copy(), end - start, end.copy()
        self._next = 1  # the index of the next posture (1..steps)

    def __len__(self) -> int:
        return self.steps - self._next + 1

    def __bool__(self) -> bool:
        return self._next <= self.steps

    def __getitem__(self, i: int) -> NDArray[np.float64]:
        left = len(self)
        if i < 0:
            i += left
        if not 0 <= i < left:
            raise IndexError(f"joint path index {i} out of range ({left} postures left)")
        j = self._next + i
        return self._end.copy() if j == self.steps else self._start + self._delta * (j / self.steps)

    def __iter__(self) -> Iterator[NDArray[np.float64]]:
        return (self[i] for i in range(len(self)))

    def pop(self, i: int = 0) -> NDArray[np.float64]:
        """The next posture, then advance (only ``i`` = 0: a path is walked in order)."""
        if i != 0:
            raise IndexError("a joint path is walked in order: pop(0) only")
        item = self[0]
        self._next += 1
        return item


def joint_path(start: NDArray[np.float64], end: NDArray[np.float64], max_step: float) -> JointPath:
    """The :class:`JointPath` from ``start`` (excluded) to ``end`` (included)."""
    return JointPath(start, end, max_step)


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
        here, asks = start, 0
        for q in [*postures, start]:
            asks += path_steps(here, q, max_step)
            here = q
        if asks > MAX_PLANNED_ASKS:
            raise InvalidArgumentError(
                f"max_joint_step={max_step!r} makes one evaluation {asks} asks, more than "
                f"{MAX_PLANNED_ASKS}: raise max_joint_step"
            )
        here = start
        for i, q in enumerate(postures):
            plan += [(TRANSIT, -1, p) for p in list(joint_path(here, q, max_step))[:-1]]
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
