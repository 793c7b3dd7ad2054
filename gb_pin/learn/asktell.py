"""Ask/tell stepping of a goal-babbling run: the robot executes each posture outside compiled code.

:class:`AskTell` drives a :class:`~gb_pin.learn.state.BabbleState` one step at a time: :meth:`ask`
returns the posture to execute, :meth:`tell` takes the observed task-space position and learns
from it. The halves are the compiled :func:`~gb_pin.learn.session_kernels.ask_step` and
:func:`~gb_pin.learn.session_kernels.tell_step`; everything between them lives in the state's
arrays, so a checkpoint taken at any time resumes exactly (an unanswered ask is asked again,
giving the same posture: computing it consumes no random numbers).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn import layout
from gb_pin.learn.layout import MOVEMENT_DONE
from gb_pin.learn.session_kernels import ask_step, evaluate_due, kernel_movement, tell_step
from gb_pin.learn.state import BabbleState

Forward = Callable[[NDArray[np.float64]], ArrayLike]


class AskTell:
    """One step at a time over a babbling state, up to ``stop`` movements.

    Args:
        state: the run (fresh from :meth:`BabbleState.start`, or restored from a checkpoint).
        stop: movement count after which :meth:`ask` refuses (the run is complete).
        forward: the forward model used for E^X when the state has no compiled chain
            (a robot given as a Python function); None: no E^X for such a state (NaN).
    """

    def __init__(self, state: BabbleState, stop: int, forward: Forward | None = None) -> None:
        self.state = state
        self.stop = int(stop)
        self.forward = forward
        self.pending = False
        self._build()

    def _build(self) -> None:
        """(Re)build the compiled arguments over the state's arrays (after a buffer grew)."""
        self._learner, self._robot, self._run, self._goals, self._monitor = self.state.kernel_args()
        self._limits = self._robot.limits
        self._rec = self._monitor.recorder
        self._q = self._run.motion.q
        self._x = self._run.motion.x
        self._n = self._x.shape[0]

    @property
    def movements(self) -> int:
        """Completed movements r."""
        return self.state.movements

    def ask(self) -> NDArray[np.float64]:
        """The next posture q_t to execute, (m,), clipped to the joint limits ([rad] or [m]).

        Raises:
            InvalidArgumentError: an ask still waiting for its :meth:`tell`, or the run is complete.
            DivergenceError: the estimate diverged.
        """
        if self.pending:
            raise InvalidArgumentError(
                "ask() called twice: tell(x) the position reached for the last posture first"
            )
        st = self.state
        if st.istate[layout.KIND] == layout.NONE:
            self.evaluate()
            chain = st.chain
            st._apply_changes()
            if st.chain is not chain:
                self._build()
            if st.movements >= self.stop or st.reached:
                raise InvalidArgumentError(
                    f"the run is complete ({st.movements} movements"
                    f"{', E^X reached until_error' if st.reached else ''}); nothing more to ask"
                )
        while True:
            status = ask_step(st.rng, self._learner, self._limits, self._run, self._goals, self._rec)
            if status == layout.DONE:
                break
            self._handle(status)
        self.pending = True
        return self._q.copy()

    def run_kernel(self, kernel: Any, until: int) -> None:
        """Run whole movements up to ``until`` with a numba-compiled forward model ``kernel(q, x)``.

        The steps run in compiled code (:func:`~gb_pin.learn.session_kernels.kernel_movement`);
        between movements E^X is measured and body changes are applied, as by :meth:`ask`.

        Raises:
            InvalidArgumentError: an ask is waiting for its tell.
            DivergenceError: the estimate diverged.
        """
        if self.pending:
            raise InvalidArgumentError("an asked posture awaits its tell(x)")
        st = self.state
        until = min(int(until), self.stop)
        while st.movements < until:
            if st.istate[layout.KIND] == layout.NONE:
                self.evaluate()
                if st.reached:
                    return
            while True:
                status = kernel_movement(
                    st.rng, self._learner, self._limits, self._run, self._goals, self._rec, kernel
                )
                if status == MOVEMENT_DONE:
                    break
                self._handle(status)

    def _handle(self, status: int) -> None:
        """Act on an ask_step status other than DONE (then the half step is asked again)."""
        st = self.state
        if status == layout.NEED_GOAL:
            st._python_goal()
            return
        if status == layout.NEED_CAPACITY:
            st.llm.set_count(int(st.istate[layout.PROTOTYPES]))
            st.llm.reserve(2 * st.llm.capacity)
        elif status == layout.NEED_RECORD_CAPACITY:
            st._grow_recording()
        else:
            st._diverged()
        self._build()

    def tell(self, x: ArrayLike) -> bool:
        """Learn from the task-space position ``x`` (n,) [m] reached by the last asked posture.

        Returns:
            True when this step completed a movement.

        Raises:
            InvalidArgumentError: no ask waiting, or ``x`` not a finite vector of shape (n,);
                nothing is changed then.
        """
        if not self.pending:
            raise InvalidArgumentError("tell(x) without ask(): ask() for a posture first")
        try:
            arr = np.asarray(x, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InvalidArgumentError(f"x must be a position of shape ({self._n},) [m], got {x!r}") from exc
        if arr.shape != (self._n,) or not np.isfinite(arr).all():
            raise InvalidArgumentError(
                f"x must be a finite position of shape ({self._n},) [m], got {np.array2string(arr)} "
                f"of shape {arr.shape}"
            )
        self._x[:] = arr
        self.pending = False
        st = self.state
        return bool(tell_step(st.rng, self._learner, self._run, self._rec) == MOVEMENT_DONE)

    def sync(self) -> None:
        """Bring the map's Python side up to the compiled counters (before reading or saving it)."""
        self.state.llm.set_count(int(self.state.istate[layout.PROTOTYPES]))

    def evaluate(self) -> None:
        """E^X and D^home at the schedule entries due now (between movements only)."""
        st = self.state
        if st.istate[layout.KIND] != layout.NONE:
            return
        if st.chain is not None:
            evaluate_due(self._learner, self._robot, self._run, self._monitor.evaluation)
        else:
            r = st.movements
            c = int(st.istate[layout.EVAL_CURSOR])
            while c < st.schedule.shape[0] and st.schedule[c] <= r:
                if st.schedule[c] == r and self.forward is not None:
                    st.errors[c], st.distances[c] = self._evaluate_python()
                c += 1
            st.istate[layout.EVAL_CURSOR] = c
        if st.reached and st.schedule.shape[0] > st.istate[layout.EVAL_CURSOR]:
            st._end_at_cursor()  # until_error reached: the run ends here
            self._build()

    def _evaluate_python(self) -> tuple[float, float]:
        """(E^X, D^home) with the Python forward model (Eqs. 9, 10)."""
        assert self.forward is not None
        st = self.state
        self.sync()
        Q = st.llm.predict(st.eval_targets, warn=False)
        distance = float(np.mean(np.linalg.norm(st.home - Q, axis=1)))
        Qc = np.clip(Q, st.lower, st.upper)
        X = np.array([np.asarray(self.forward(q), dtype=float) for q in Qc]).reshape(st.eval_targets.shape)
        return float(np.mean(np.linalg.norm(st.eval_targets - X, axis=1))), distance

    def finish(self) -> None:
        """At the end of a run: E^X due now, and body changes due now applied (as ``BabbleState.run``)."""
        self.evaluate()
        if self.state.istate[layout.KIND] == layout.NONE:
            self.state._apply_changes()
        self.sync()
