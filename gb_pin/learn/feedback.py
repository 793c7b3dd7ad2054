"""Reaching by feedback on the learned model: feedforward first, feedback later (paper Sec. IV).

The learned inverse g(x*) reaches in one shot, as well as it was learnt. On a robot whose model is
wrong that is already far better than exact IK on the model; to go below the learner's own error,
watch the hand and correct. No kinematic model is needed: the learned Jacobian dg/dx maps a
task-space miss to a joint correction,

    q_0 = g(x*),    q_{i+1} = clip(q_i + gain * dg/dx(x*) (x* - mean of k_i readings at q_i)),

with the readings averaged to beat the sensor's noise. :class:`FeedbackReach` is that controller as
an ask/tell loop (the robot executes each posture, a missing reading is asked again), as
sessions are; :func:`reach` drives it with a function.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.probe import joint_path

DEFAULT_OBSERVATIONS = (1, 1, 3)
"""Readings averaged before each correction (three corrections): the fewest that reach the noise floor
of a 0.2 mm tracker in docs/HARDWARE.md's measurement."""


class FeedbackReach:
    """Reach one target x*: ask g(x*), then corrections from averaged readings (see the module docstring).

    Args:
        model: the learned inverse (a :class:`~gb_pin.learn.llm.LocalLinearMap`).
        target: x* (n,) [m].
        lower: lower joint limits (m,).
        upper: upper joint limits (m,).
        observations: readings averaged before each correction, one entry per correction
            (e.g. (1, 1, 3): three corrections from 1, 1 and 3 readings); () for feedforward only.
        gain: the fraction of each measured miss corrected (1: all of it).
        start: the posture the robot holds now (m,), needed with ``max_joint_step``.
        max_joint_step: no ask moves a joint farther than this from the last ([rad] or [m]);
            larger moves are split into ``"transit"`` asks. None: no limit.
        retries: asks of the same posture after missing readings, before the reach gives up.

    Attributes (after ``done``):
        posture: the final posture (m,) (after the last correction), which the robot holds.
        readings: the readings the corrections used, in order.
        corrections: the joint corrections applied.
        final_reading: the reading at the final posture (not used; None if missing).
    """

    def __init__(
        self,
        model: Any,
        target: ArrayLike,
        lower: ArrayLike,
        upper: ArrayLike,
        *,
        observations: Sequence[int] = DEFAULT_OBSERVATIONS,
        gain: float = 1.0,
        start: ArrayLike | None = None,
        max_joint_step: float | None = None,
        retries: int = 10,
    ) -> None:
        n, m = model.n_inputs_, model.n_outputs_
        self.target = check.vector("target", target, n)
        self.lower = np.asarray(lower, dtype=float)
        self.upper = np.asarray(upper, dtype=float)
        if isinstance(observations, int | np.integer):
            observations = (int(observations),)
        self.observations = tuple(check.positive_int("observations", k, 1, 10**6) for k in observations)
        self.gain = check.positive_float("gain", gain)
        if self.gain > 2:
            raise InvalidArgumentError(f"gain must be in (0, 2] (1: correct the whole miss), got {gain!r}")
        self.max_step = (
            math.inf if max_joint_step is None else check.positive_float("max_joint_step", max_joint_step)
        )
        if math.isfinite(self.max_step) and start is None:
            raise InvalidArgumentError("max_joint_step needs start= (the posture the robot holds now)")
        self.retries = check.positive_int("retries", retries, 0, 10**6)
        self.model = model
        self.jacobian = model.jacobian(self.target)  # dg/dx at x*: (m, n)
        self.posture = np.clip(model.predict(self.target, warn=False), self.lower, self.upper)
        here = self.posture if start is None else check.vector("start", start, m)
        self._queue = joint_path(here, self.posture, self.max_step)
        self._round = 0
        self._sum = np.zeros(n)
        self._count = 0
        self._misses = 0
        self.readings: list[NDArray[np.float64]] = []
        self.corrections: list[NDArray[np.float64]] = []
        self.final_reading: NDArray[np.float64] | None = None
        self.gave_up = False

    @property
    def done(self) -> bool:
        """Whether the robot holds the last corrected posture (or the readings stopped arriving)."""
        return self.gave_up or not self._queue

    @property
    def kind(self) -> str:
        """What the next ask is.

        ``"observe"``: its reading counts; ``"transit"``: on the way, reading ignored; ``"final"``: the
        corrected posture, its reading kept in ``final_reading``.
        """
        if self._round >= len(self.observations):
            return "final" if len(self._queue) == 1 else "transit"
        return "transit" if len(self._queue) > 1 else "observe"

    def ask(self) -> NDArray[np.float64]:
        """The next posture (m,) to execute.

        Raises:
            InvalidArgumentError: the reach is done.
        """
        if self.done:
            raise InvalidArgumentError("the reach is done: read .posture")
        return self._queue[0].copy()

    def tell(self, x: ArrayLike | None) -> None:
        """The reading at the asked posture: (n,) [m], or None when it is missing.

        Raises:
            InvalidArgumentError: a reading that is not a finite real (n,) vector.
        """
        from gb_pin.learn.asktell import reading

        arr = reading(x, self.target.shape[0])
        if self.done:
            raise InvalidArgumentError("the reach is done: read .posture")
        if self._round >= len(self.observations) or len(self._queue) > 1:  # on the way: not used
            self._queue.pop(0)
            if not self._queue:
                self.final_reading = arr
            return
        if arr is None:
            self._misses += 1
            self.gave_up = self._misses > self.retries
            return
        self._misses = 0
        self.readings.append(arr)
        self._sum += arr
        self._count += 1
        if self._count < self.observations[self._round]:
            return
        miss = self.target - self._sum / self._count
        step = self.gain * (self.jacobian @ miss)
        new = np.clip(self.posture + step, self.lower, self.upper)
        self.corrections.append(new - self.posture)
        self._queue = joint_path(self.posture, new, self.max_step)  # the next posture is asked next
        self.posture = new
        self._round += 1
        self._sum[:] = 0.0
        self._count = 0


class ReachResult(NamedTuple):
    """Feedback reaching of several targets.

    Attributes:
        postures: (N, m) the final postures.
        initial: (N, m) the feedforward postures g(x*) (clipped).
        readings: (N,) readings used per target.
        reached: (N,) False where the readings stopped arriving (the posture is the last corrected one).
    """

    postures: NDArray[np.float64]
    initial: NDArray[np.float64]
    readings: NDArray[np.int64]
    reached: NDArray[np.bool_]


def reach(
    model: Any,
    X: ArrayLike,
    observe: Callable[[NDArray[np.float64]], ArrayLike | None],
    lower: ArrayLike,
    upper: ArrayLike,
    **options: Any,
) -> ReachResult:
    """Feedback reaching of each target of ``X`` (N, n), the robot driven by ``observe(q) -> x or None``.

    ``options`` are :class:`FeedbackReach`'s (``observations``, ``gain``, ``max_joint_step`` with
    ``start``: the robot's posture then carries over from one target to the next).
    """
    pts = check.points("X", X, model.n_inputs_, allow_single=True)
    out = np.empty((pts.shape[0], model.n_outputs_))
    initial = np.empty_like(out)
    used = np.zeros(pts.shape[0], dtype=np.int64)
    ok = np.ones(pts.shape[0], dtype=bool)
    for i, x_star in enumerate(pts):
        controller = FeedbackReach(model, x_star, lower, upper, **options)
        initial[i] = controller.posture
        while not controller.done:
            controller.tell(observe(controller.ask()))
        out[i] = controller.posture
        used[i] = len(controller.readings)
        ok[i] = not controller.gave_up
        if "start" in options:
            options = {**options, "start": controller.posture}
    return ReachResult(out, initial, used, ok)
