"""The goal-babbling learner with scikit-learn conventions (paper Sec. II), robot-agnostic.

The learner sees forward kinematics (a :class:`~gb_pin.learn.body.chain.KinematicChain`),
a home posture, joint limits and a target set, nothing else; it imports neither
pinocchio nor meshcat.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError, NotFittedError
from gb_pin.learn.config import BY_NAME, NAMES, BabbleConfig
from gb_pin.learn.goals import GoalGenerator
from gb_pin.learn.history import History, RecordedSteps, Recording
from gb_pin.learn.llm import LocalLinearMap
from gb_pin.learn.state import BabbleState, Kinematics

_D = {name: BY_NAME[name].default for name in NAMES}


class GoalBabbling:
    """Online goal babbling learner (paper Sec. II) with a local-linear map inverse estimate.

    ``__init__`` only stores hyperparameters (scikit-learn convention); ``fit`` runs. The
    defaults come from :data:`gb_pin.learn.config.HYPERPARAMETERS`.

    Args:
        learning_rate: eta.
        sigma: exploration noise [rad]; None: Eq. 12 from the number of joints.
        sigma_delta: random-walk step [rad]; None: 0.1 * sigma (Sec. III-B).
        radius: d [m].
        path_length: L (Eq. 3).
        p_home: home-return probability (Eq. 7).
        cutoff: c [radii] of the map's truncated sums; None: every prototype.

    Attributes:
        state_: the :class:`~gb_pin.learn.state.BabbleState` of the run (resumable with :meth:`resume`).
        model_: the learned :class:`~gb_pin.learn.llm.LocalLinearMap`.
        config_: the :class:`~gb_pin.learn.config.BabbleConfig` used.
        history_: the :class:`~gb_pin.learn.history.History` of the last ``fit``.
        movements_: completed movements r (home returns included).
        steps_: completed time steps t.
        noise_: (A, b) of Eq. 8 at the end of the run.
    """

    def __init__(
        self,
        learning_rate: float = _D["learning_rate"],  # type: ignore[assignment]
        sigma: float | None = _D["sigma"],
        sigma_delta: float | None = _D["sigma_delta"],
        radius: float = _D["radius"],  # type: ignore[assignment]
        path_length: int = _D["path_length"],  # type: ignore[assignment]
        p_home: float = _D["p_home"],  # type: ignore[assignment]
        cutoff: float | None = _D["cutoff"],
    ) -> None:
        self.learning_rate = learning_rate
        self.sigma = sigma
        self.sigma_delta = sigma_delta
        self.radius = radius
        self.path_length = path_length
        self.p_home = p_home
        self.cutoff = cutoff

    def get_params(self, deep: bool = True) -> dict[str, Any]:
        """The hyperparameters as given (scikit-learn convention)."""
        return {name: getattr(self, name) for name in NAMES}

    def set_params(self, **params: Any) -> GoalBabbling:
        """Set hyperparameters by name (scikit-learn convention)."""
        unknown = sorted(set(params) - set(NAMES))
        if unknown:
            raise InvalidArgumentError(f"unknown hyperparameters {unknown}; valid: {', '.join(NAMES)}")
        for name, value in params.items():
            setattr(self, name, value)
        return self

    @classmethod
    def from_config(cls, config: BabbleConfig) -> GoalBabbling:
        """A learner with the (resolved) hyperparameters of ``config``."""
        return cls(**config.as_dict())

    def _resolve(self, n_joints: int) -> BabbleConfig:
        return BabbleConfig.resolve(n_joints, **self.get_params())

    def fit(
        self,
        kinematics: Kinematics,
        targets: ArrayLike,
        movements: int,
        *,
        seed: int | np.random.Generator = 0,
        eval_targets: ArrayLike | None = None,
        schedule: ArrayLike | None = None,
        record: Recording | None = None,
        goals: str | GoalGenerator | None = None,
        changes: dict[int, Kinematics] | None = None,
        callback: Callable[[int], Any] | None = None,
        observer: Callable[[BabbleState], Any] | None = None,
        observe_every: int = 1,
        checkpoint: Callable[[BabbleState], Any] | None = None,
        checkpoint_every: int | None = None,
        should_stop: Callable[[], bool] | None = None,
    ) -> GoalBabbling:
        """Bootstrap an inverse estimate from scratch by goal babbling.

        Args:
            kinematics: the robot (chain, home, lower, upper).
            targets: target set X*, (N, n) [m]; the goal generator chooses goals from it.
            movements: number of movements r to run (home returns included).
            seed: an int seed or a numpy Generator (advanced in place).
            eval_targets: where E^X and D^home are measured; default ``targets``.
            schedule: movement counts to evaluate at; default
                :func:`~gb_pin.learn.metrics.evaluation_schedule`.
            record: which steps to record (postures, targets, positions); default none.
            goals: the goal generator (a :class:`~gb_pin.learn.goals.GoalGenerator` or its
                name); default the paper's uniform choice over ``targets``.
            changes: body changes ``{movement: robot}`` (same joints and task dimension).
            callback: called with the movement count after each chunk (progress bars).
            observer: called with the state every ``observe_every`` movements (live
                viewers); it must not modify the state.
            observe_every: movements between observer calls.
            checkpoint: called with the state every ``checkpoint_every`` movements and at the end.
            checkpoint_every: movements between checkpoints (default: a tenth of the run).
            should_stop: polled between chunks; True stops the run early, resumable.

        Raises:
            InvalidArgumentError: a bad argument.
            DivergenceError: a posture became non-finite or exploded.
        """
        self.state_ = BabbleState.start(
            kinematics, targets, movements, self._resolve(kinematics.chain.n_joints),
            seed=seed, eval_targets=eval_targets, schedule=schedule, record=record,
            goals=goals, changes=changes,
        )  # fmt: skip
        return self.resume(
            movements, callback=callback, observer=observer, observe_every=observe_every,
            checkpoint=checkpoint, checkpoint_every=checkpoint_every, should_stop=should_stop,
        )  # fmt: skip

    def resume(
        self,
        until: int,
        *,
        callback: Callable[[int], Any] | None = None,
        observer: Callable[[BabbleState], Any] | None = None,
        observe_every: int = 1,
        checkpoint: Callable[[BabbleState], Any] | None = None,
        checkpoint_every: int | None = None,
        should_stop: Callable[[], bool] | None = None,
    ) -> GoalBabbling:
        """Continue the run held in ``state_`` until ``until`` movements are complete.

        Checkpoints are written at every multiple of ``checkpoint_every`` and at the end.

        Args:
            until: movement count to reach.
            callback: called with the movement count after each chunk.
            observer: called with the state every ``observe_every`` movements.
            observe_every: movements between observer calls.
            checkpoint: called with the state every ``checkpoint_every`` movements and at the end.
            checkpoint_every: movements between checkpoints.
            should_stop: polled between chunks; when it returns True the run stops early
                (after a checkpoint, if any), leaving a consistent, resumable state.
        """
        if not hasattr(self, "state_"):
            raise NotFittedError("this GoalBabbling learner has no run to resume: call fit() first")
        state = self.state_
        until = check.movements("until", until)
        observe_every = check.positive_int("observe_every", observe_every)
        total = int(state.schedule[-1])
        chunk = observe_every if observer is not None else max(1, min(total // 100, 1000))
        every = 0
        if checkpoint is not None:
            every = check.positive_int("checkpoint_every", checkpoint_every or max(1, total // 10))
        state.interrupt = should_stop  # also polled inside a chunk, every SLICE_SECONDS (learn/clock.py)
        try:
            self._chunks(state, until, chunk, every, callback, observer, checkpoint, should_stop)
        finally:
            state.interrupt = None
        return self

    @staticmethod
    def _chunks(
        state: BabbleState,
        until: int,
        chunk: int,
        every: int,
        callback: Callable[[int], Any] | None,
        observer: Callable[[BabbleState], Any] | None,
        checkpoint: Callable[[BabbleState], Any] | None,
        should_stop: Callable[[], bool] | None,
    ) -> None:
        while state.movements < until and not state.reached:
            stop = min(until, state.movements + chunk)
            if every:  # never step over a checkpoint
                stop = min(stop, (state.movements // every + 1) * every)
            state.run(stop)
            # The checkpoint comes first, so that a failing observer or callback loses nothing.
            stopping = should_stop is not None and should_stop()
            if checkpoint is not None and (
                stopping or state.movements % every == 0 or state.movements >= until
            ):
                checkpoint(state)
            if observer is not None:
                observer(state)
            if callback is not None:
                callback(state.movements)
            if stopping:
                break

    @property
    def model_(self) -> LocalLinearMap:
        """The learned local-linear map g."""
        return self._state().llm

    @property
    def config_(self) -> BabbleConfig:
        """The hyperparameters used."""
        return self._state().config

    @property
    def noise_(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(A, b) of Eq. 8 now."""
        st = self._state()
        return st.A, st.b

    @property
    def movements_(self) -> int:
        """Completed movements r (home returns included)."""
        return self._state().movements

    @property
    def steps_(self) -> int:
        """Completed time steps t."""
        return self._state().steps

    @property
    def history_(self) -> History:
        """E^X and D^home recorded so far (NaN where not reached yet)."""
        return self._state().history()

    @property
    def recording_(self) -> RecordedSteps | None:
        """The recorded steps, if recording was asked for."""
        return self._state().recorded()

    def _state(self) -> BabbleState:
        if not hasattr(self, "state_"):
            raise NotFittedError("this GoalBabbling learner is not fitted: call fit() first")
        return self.state_

    def predict(self, X: ArrayLike) -> NDArray[np.float64]:
        """The learned inverse estimate g(X): (N, n) -> (N, m), (n,) -> (m,)."""
        return self._state().llm.predict(X)
