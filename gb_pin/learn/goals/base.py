"""Goal generators: who chooses where each goal-directed movement goes (the end of its path, Eq. 3).

The paper draws each goal uniformly from the target set X* (:class:`UniformGoals`); other
rules plug in here without touching the babbling loop. A generator is a small object with
documented parameters that describes its state as plain arrays (:class:`GoalArrays`): the
compiled loop advances the built-in ones itself (:func:`gb_pin.learn.goals.kernel.next_goal`
dispatches on ``kind``), and hands control back to Python for a :class:`PythonGoals`
subclass. Either way the state lives in arrays, so checkpoints resume bit-identical.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, ClassVar, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

# Kind codes of the generators the compiled loop runs itself; EXTERNAL: Python decides.
EXTERNAL = -1
UNIFORM = 0
CYCLIC = 1


class GoalArrays(NamedTuple):
    """A goal generator's target set and state, as the compiled loop takes them.

    Attributes:
        kind: the generator's kind code (``UNIFORM``, ``CYCLIC``, ... or ``EXTERNAL``).
        targets: (N, n) the goal set [m].
        istate: int64 state of the generator (saved in checkpoints).
        fstate: float64 state of the generator (saved in checkpoints).
    """

    kind: int
    targets: NDArray[np.float64]
    istate: NDArray[np.int64]
    fstate: NDArray[np.float64]


class GoalGenerator(ABC):
    """Chooses the goal x* at the start of every goal-directed movement.

    Subclasses store their parameters in ``__init__`` (returned by :meth:`get_params`) and
    describe a fresh state for a goal set with :meth:`start`.
    """

    name: ClassVar[str]
    kind: ClassVar[int]

    def get_params(self) -> dict[str, Any]:
        """The generator's parameters (JSON-serialisable; saved in checkpoints)."""
        return {}

    def start(self, targets: NDArray[np.float64]) -> GoalArrays:
        """The state at movement 0 for goal set ``targets`` (N, n)."""
        return GoalArrays(self.kind, targets, np.zeros(1, dtype=np.int64), np.zeros(1))

    def __repr__(self) -> str:
        params = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({params})"


class PythonGoals(GoalGenerator):
    """A goal generator written in Python: the loop returns to it at every goal-directed movement.

    This costs one return from compiled code per goal (a few microseconds); the built-in
    generators avoid it. Keep all state that must survive a checkpoint in
    ``state.istate`` / ``state.fstate`` (sized in :meth:`start`).
    """

    kind: ClassVar[int] = EXTERNAL

    @abstractmethod
    def next_goal(self, state: GoalArrays, rng: np.random.Generator) -> ArrayLike:
        """The next goal (n,) [m]; may update ``state.istate`` / ``state.fstate`` in place."""
