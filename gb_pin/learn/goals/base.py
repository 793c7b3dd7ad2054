"""Goal generators: who chooses where each goal-directed movement goes (the end of its path, Eq. 3).

The paper draws each goal uniformly from the target set X* (:class:`UniformGoals`); other
rules plug in here without touching the babbling loop. A generator is a small object with
documented parameters that describes its parameters and state as plain arrays
(:class:`GoalArrays`): the compiled loop advances the built-in ones itself
(:func:`gb_pin.learn.goals.kernel.next_goal` dispatches on ``kind``), and hands control back to
Python for a :class:`PythonGoals` subclass. Either way the state lives in arrays, so
checkpoints resume bit-identical.

Every generator has a ``snap`` lag threshold [task units, m]: when a goal-directed movement
ends farther than ``snap`` from its goal, the next path starts where the arm got to (and not at
the unreached goal). Off (infinite) for the paper's uniform choice, so its runs stay bit-identical.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any, ClassVar, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin.exceptions import InvalidArgumentError

# Kind codes of the generators the compiled loop runs itself; EXTERNAL: Python decides.
EXTERNAL = -1
UNIFORM = 0
CYCLIC = 1
DIRECTIONS = 2
ERROR = 3
PROGRESS = 4
MOTOR = 5
CURRICULUM = 6

# params[SNAP] of every generator: the lag threshold of the snap-back (inf: off).
SNAP = 0


class GoalArrays(NamedTuple):
    """A goal generator's target set, parameters and state, as the compiled loop takes them.

    Attributes:
        kind: the generator's kind code (``UNIFORM``, ``CYCLIC``, ... or ``EXTERNAL``).
        targets: (N, n) the goal set [m] (unused by generators that need none).
        params: float64 parameters; ``params[SNAP]`` is the snap-back threshold (not saved:
            rebuilt from the generator's parameters).
        istate: int64 state of the generator (saved in checkpoints).
        fstate: float64 state of the generator (saved in checkpoints).
    """

    kind: int
    targets: NDArray[np.float64]
    params: NDArray[np.float64]
    istate: NDArray[np.int64]
    fstate: NDArray[np.float64]


# The other families of generators: the same fields, other classes. numba compiles the loop once
# per class (gb_pin.learn.goals.kernel picks each family's code by the class), so that a run of the
# paper's uniform goals compiles none of the other generators' code.
class DirectionArrays(GoalArrays):
    """:class:`GoalArrays` of direction sampling (:class:`~gb_pin.learn.goals.DirectionGoals`)."""

    __slots__ = ()


class SelectorArrays(GoalArrays):
    """:class:`GoalArrays` of the score-based selectors (``ErrorGoals``, ``ProgressGoals``)."""

    __slots__ = ()


class MotorArrays(GoalArrays):
    """:class:`GoalArrays` of motor babbling (:class:`~gb_pin.learn.goals.MotorGoals`)."""

    __slots__ = ()


def snap_threshold(snap: Any) -> float:
    """``snap`` as a float: None or inf is off, else a number >= 0 [task units].

    Raises:
        InvalidArgumentError: negative, NaN or not a number.
    """
    if snap is None:
        return math.inf
    if isinstance(snap, bool) or not isinstance(snap, int | float | np.integer | np.floating):
        raise InvalidArgumentError(f"snap must be a lag threshold >= 0 (or None: off), got {snap!r}")
    value = float(snap)
    if not value >= 0.0:
        raise InvalidArgumentError(f"snap must be a lag threshold >= 0 (or None: off), got {snap!r}")
    return value


class GoalGenerator(ABC):
    """Chooses the goal x* at the start of every goal-directed movement.

    Subclasses store their parameters in ``__init__`` (returned by :meth:`get_params`) and
    describe their parameters and a fresh state for a goal set with :meth:`start`.

    Attributes:
        snap: the snap-back lag threshold (inf: off).
        needs_targets: False for generators that choose goals without a goal set.
    """

    name: ClassVar[str]
    kind: ClassVar[int]
    needs_targets: ClassVar[bool] = True
    arrays_class: ClassVar[type] = GoalArrays
    snap: float = math.inf

    def get_params(self) -> dict[str, Any]:
        """The generator's parameters (JSON-serialisable; saved in checkpoints)."""
        return {"snap": None if math.isinf(self.snap) else self.snap}

    def param_array(self) -> NDArray[np.float64]:
        """The parameters as the compiled loop reads them (``[snap, ...]``)."""
        return np.array([self.snap], dtype=np.float64)

    def start(self, targets: NDArray[np.float64]) -> GoalArrays:
        """The state at movement 0 for goal set ``targets`` (N, n)."""
        arrays: GoalArrays = self.arrays_class(
            self.kind, targets, self.param_array(), np.zeros(1, dtype=np.int64), np.zeros(1)
        )
        return arrays

    def check_state(self, state: GoalArrays) -> None:
        """Refuse a state (read from a file) that compiled code could not use safely.

        Raises:
            InvalidArgumentError: an index out of range or a negative count.
        """
        if state.istate.ndim != 1 or state.fstate.ndim != 1:
            raise InvalidArgumentError(f"{self.name} goals: corrupted state (not vectors)")

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
