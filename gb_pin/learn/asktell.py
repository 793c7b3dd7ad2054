"""Ask/tell stepping of a goal-babbling run: the robot executes each posture outside compiled code.

:class:`AskTell` drives a :class:`~gb_pin.learn.state.BabbleState` one step at a time: :meth:`ask`
returns the posture to execute, :meth:`tell` takes the observed task-space position (or None:
the reading is missing) and learns from it. The halves are the compiled
:func:`~gb_pin.learn.session_kernels.ask_step` and :func:`~gb_pin.learn.session_kernels.tell_step`;
everything between them lives in the state's arrays, so a checkpoint taken at any time resumes
exactly (an unanswered ask is asked again, giving the same posture: computing it consumes no
random numbers).

E^X (Eq. 9) at the schedule's counts comes from the robot's model (``evaluate="model"``: the
compiled chain, or a Python forward function), from evaluation movements the robot executes
(``"movements"``: the session asks the test postures g(x*) and learns nothing from them, see
:mod:`gb_pin.learn.probe`), or not at all (``"none"``: NaN). D^home (Eq. 10) and the free
measure of progress (the median reach error of the last goal-directed movements) need no robot.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin._signals import deferring
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn import layout
from gb_pin.learn.layout import MOVEMENT_DONE
from gb_pin.learn.metrics import reach_median
from gb_pin.learn.session_kernels import ask_step, evaluate_due, kernel_movement, tell_step
from gb_pin.learn.state import BabbleState

Forward = Callable[[NDArray[np.float64]], ArrayLike]
Guard = Callable[[NDArray[np.float64], NDArray[np.float64]], "NDArray[np.float64] | None"]
"""``guard(q_from, q_to)``: None when the straight joint-space move from the last executed posture
``q_from`` to the asked ``q_to`` is safe, else the posture to stop at (:mod:`gb_pin.safety`)."""
EVALUATE_MODES = ("model", "movements", "none")


def _real(value: Any, expected: str) -> NDArray[np.float64]:
    """``value`` as float64, refusing complex, boolean and non-numeric input (``expected``, got ...)."""
    try:
        raw = np.asarray(value)
        if raw.dtype.kind not in "fiu" or raw.dtype == np.bool_:
            raise TypeError(f"dtype {raw.dtype}")
        return np.asarray(raw, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(f"{expected}, got {value!r:.200}") from exc


def reading(x: Any, n: int) -> NDArray[np.float64] | None:
    """An observation checked: a finite real (n,) vector [m], or None for a missing reading.

    Raises:
        InvalidArgumentError: anything else (a complex, wrongly shaped or non-finite reading).
    """
    if x is None:
        return None
    arr = _real(x, f"x must be a real position of shape ({n},) [m] (or None: the reading is missing)")
    if arr.shape != (n,) or not np.isfinite(arr).all():
        raise InvalidArgumentError(
            f"x must be a finite position of shape ({n},) [m] (or None: the reading is missing), got "
            f"{np.array2string(arr, threshold=20)} of shape {arr.shape}"
        )
    return arr


def posture(q: Any, m: int) -> NDArray[np.float64] | None:
    """An executed posture checked: None, or a finite real (m,) vector [rad] or [m].

    Raises:
        InvalidArgumentError: anything else.
    """
    if q is None:
        return None
    arr = _real(q, f"executed must be a real posture of shape ({m},) (or None: the asked one)")
    if arr.shape != (m,) or not (np.abs(arr) <= layout.MAX_POSTURE).all():
        raise InvalidArgumentError(
            f"executed must be a finite posture of shape ({m},) (or None: the asked one), got "
            f"{np.array2string(arr, threshold=20)} of shape {arr.shape}"
        )
    return arr


class AskTell:
    """One step at a time over a babbling state, up to ``stop`` movements.

    Args:
        state: the run (fresh from :meth:`BabbleState.start`, or restored from a checkpoint).
        stop: movement count after which :meth:`ask` refuses (the run is complete).
        forward: the forward model used for E^X when the state has no compiled chain
            (a robot given as a Python function); None: no E^X from a model.
        evaluate: ``"model"``, ``"movements"`` or ``"none"`` (see the module docstring).
        guard: checks each asked posture and the move to it from the last executed one; an unsafe
            ask is cut short at the posture it returns, and the learner learns from that posture
            (as from a posture clipped to the joint limits). None: no check.
    """

    def __init__(
        self,
        state: BabbleState,
        stop: int,
        forward: Forward | None = None,
        evaluate: str = "model",
        guard: Guard | None = None,
    ) -> None:
        if evaluate not in EVALUATE_MODES:
            raise InvalidArgumentError(
                f"evaluate must be one of {', '.join(EVALUATE_MODES)}, got {evaluate!r}"
            )
        if evaluate == "model" and state.chain is None and forward is None:
            evaluate = "none"  # nothing can compute E^X: the robot is on hardware
        self.state = state
        self.stop = int(stop)
        self.forward = forward
        self.mode = evaluate
        self.pending = False
        self.guard = guard
        self.cuts = 0  # asks cut short by the guard
        self._build()

    def _build(self) -> None:
        """(Re)build the compiled arguments over the state's arrays (after a buffer grew)."""
        self._learner, self._robot, self._run, self._goals, self._monitor = self.state.kernel_args()
        self._limits = self._robot.limits
        self._rec = self._monitor.recorder
        self._q = self._run.motion.q
        self._q_exec = self._run.motion.q_exec
        self._x = self._run.motion.x
        self._n = self._x.shape[0]

    @property
    def movements(self) -> int:
        """Completed movements r."""
        return self.state.movements

    def ask(self) -> NDArray[np.float64]:
        """The next posture q_t to execute, (m,), clipped to the joint limits ([rad] or [m]).

        Raises:
            InvalidArgumentError: an ask still waiting for its :meth:`tell`, the run is complete, or
                evaluation movements are due (:meth:`due` says which; the session executes them).
            DivergenceError: the estimate diverged.
        """
        if self.pending:
            raise InvalidArgumentError(
                "ask() called twice: tell(x) the position reached for the last posture first"
            )
        st = self.state
        if st.istate[layout.KIND] == layout.NONE:
            if self.evaluate() is not None:
                raise InvalidArgumentError("evaluation movements are due before the next learning step")
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
            status = deferring(
                ask_step, st.rng, self._learner, self._limits, self._run, self._goals, self._rec
            )
            if status == layout.DONE:
                break
            self._handle(status)
        if self.guard is not None:
            cut = self.guard(self._q_exec.copy(), self._q.copy())
            if cut is not None:
                self._q[:] = cut  # what the arm executes, and what tell_step learns from
                self.cuts += 1
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
        if self.guard is not None:
            raise InvalidArgumentError("a guarded run checks each ask in Python: step it with ask/tell")
        st = self.state
        until = min(int(until), self.stop)
        while st.movements < until:
            if st.istate[layout.KIND] == layout.NONE:
                self.evaluate()
                if st.reached:
                    return
            while True:
                status = deferring(
                    kernel_movement,
                    st.rng,
                    self._learner,
                    self._limits,
                    self._run,
                    self._goals,
                    self._rec,
                    kernel,
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

    def tell(self, x: ArrayLike | None, executed: ArrayLike | None = None) -> bool:
        """Learn from the task-space position ``x`` (n,) [m] reached by the last asked posture.

        ``x`` None: the reading is missing (the tracker lost the hand). Nothing is learnt from
        the step; the movement goes on and t advances.

        ``executed``: the posture (m,) the robot actually reached (its encoders: clipped by the
        servos, stalled, quantised), learnt from in place of the asked one (the pair (x, q) of
        Eqs. 4-6 and the previous posture of the next step's weight). The next ask's joint-step
        limit still counts from the asked posture (the last command). None: the asked posture,
        exactly as before.

        Returns:
            True when this step completed a movement.

        Raises:
            InvalidArgumentError: no ask waiting, or ``x`` neither None nor a finite real vector of
                shape (n,); nothing is changed then.
        """
        if not self.pending:
            raise InvalidArgumentError("tell(x) without ask(): ask() for a posture first")
        arr = reading(x, self._n)
        done = posture(executed, self._q.shape[0])
        if arr is not None:
            self._x[:] = arr
            self.state.note_reading(arr)
        self.pending = False
        st = self.state
        if done is None:
            return bool(
                deferring(
                    tell_step, st.rng, self._learner, self._limits, self._run, self._rec, arr is not None
                )
                == MOVEMENT_DONE
            )
        asked = self._q.copy()
        self._q[:] = done
        status = deferring(
            tell_step, st.rng, self._learner, self._limits, self._run, self._rec, arr is not None
        )
        self._run.motion.q_exec[:] = asked  # the step limit goes on from the last command
        self._q[:] = asked
        return bool(status == MOVEMENT_DONE)

    def sync(self) -> None:
        """Bring the map's Python side up to the compiled counters (before reading or saving it)."""
        self.state.llm.set_count(int(self.state.istate[layout.PROTOTYPES]))

    def evaluate(self) -> int | None:
        """E^X, D^home and the reach median at the schedule entries due now (between movements only).

        Returns:
            None, or with ``evaluate="movements"`` the schedule index whose E^X awaits evaluation
            movements (recorded by :meth:`record_evaluation`; the cursor stays there until then).
        """
        st = self.state
        if st.istate[layout.KIND] != layout.NONE:
            return None
        if st.chain is not None and self.mode == "model":
            evaluate_due(self._learner, self._robot, self._run, self._monitor.evaluation)
        else:
            r = st.movements
            c = int(st.istate[layout.EVAL_CURSOR])
            while c < st.schedule.shape[0] and st.schedule[c] <= r:
                if st.schedule[c] == r:
                    if self.mode == "movements":
                        st.istate[layout.EVAL_CURSOR] = c
                        return c
                    error = self._evaluate_python() if self.mode == "model" else np.nan
                    self._record(c, error)
                c += 1
            st.istate[layout.EVAL_CURSOR] = c
        self._after_evaluation()
        return None

    def record_evaluation(self, c: int, error: float) -> None:
        """E^X measured by evaluation movements for the due schedule entry ``c``; the cursor moves on."""
        st = self.state
        if int(st.istate[layout.EVAL_CURSOR]) != c or st.schedule[c] != st.movements:
            raise InvalidArgumentError(f"schedule entry {c} is not the one due at movement {st.movements}")
        self._record(c, error)
        st.istate[layout.EVAL_CURSOR] = c + 1
        self.evaluate()  # later entries of the same count (none in a valid schedule) and until_error

    def _record(self, c: int, error: float) -> None:
        st = self.state
        self.sync()
        st.errors[c] = error
        st.distances[c] = float(np.mean(np.linalg.norm(st.home - self.predict(st.eval_targets), axis=1)))
        st.reaches[c] = reach_median(st.reach, int(st.istate[layout.REACHES]))

    def _after_evaluation(self) -> None:
        st = self.state
        if st.reached and st.schedule.shape[0] > st.istate[layout.EVAL_CURSOR]:
            st._end_at_cursor()  # until_error reached: the run ends here
            self._build()

    def predict(self, X: NDArray[np.float64]) -> NDArray[np.float64]:
        """g(x*) of the current map for targets (N, n) (unclipped)."""
        self.sync()
        return self.state.llm.predict(X, warn=False)

    def _evaluate_python(self) -> float:
        """E^X with the Python forward model (Eq. 9) over the postures clipped to the limits."""
        assert self.forward is not None
        st = self.state
        Qc = np.clip(self.predict(st.eval_targets), st.lower, st.upper)
        X = np.empty_like(st.eval_targets)
        for i, q in enumerate(Qc):
            value = np.asarray(self.forward(q), dtype=float)
            if value.shape != (self._n,) or not np.all(np.isfinite(value)):
                raise InvalidArgumentError(
                    f"the forward model {self.forward!r:.80} returned {value.tolist()!r:.120} at the "
                    "evaluation "
                    f"posture {q.tolist()!r:.120}: a finite position of shape ({self._n},) was expected"
                )
            X[i] = value
        return float(np.mean(np.linalg.norm(st.eval_targets - X, axis=1)))

    def finish(self) -> None:
        """At the end of a run: E^X due now, and body changes due now applied (as ``BabbleState.run``)."""
        if self.evaluate() is not None:
            return  # evaluation movements still to execute
        if self.state.istate[layout.KIND] == layout.NONE:
            self.state._apply_changes()
        self.sync()
