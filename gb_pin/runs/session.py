"""``babble_session()``: goal babbling as an ask/tell loop, for hardware and simulators.

>>> session = babble_session("planar5", movements=10, seed=0)
>>> while not session.done:
...     q = session.ask()            # the posture to execute (clipped to the limits)
...     session.tell(robot_moves_to(q))  # the position the robot reached  # doctest: +SKIP
>>> result = session.result()        # a BabbleResult, as babble() returns

Driven with the robot's compiled forward kinematics (``target.chain.forward``) a session is
bit-identical to ``babble()`` with the same seed and arguments. Checkpoints are written as in
``babble()`` (every ``checkpoint_every`` movements, after the tell that completes the movement)
and continue with :func:`resume_session`.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin._files import check_writable
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.asktell import AskTell
from gb_pin.learn.goals import GoalGenerator
from gb_pin.learn.history import Recording
from gb_pin.learn.learner import GoalBabbling
from gb_pin.robot.function import FunctionTarget
from gb_pin.runs import setup
from gb_pin.runs.result import BabbleResult, goal_fields


class BabbleSession:
    """A goal-babbling run stepped from outside: :meth:`ask` a posture, :meth:`tell` the position reached.

    Build it with :func:`babble_session`. Attributes: ``target`` (the robot), ``state`` (the
    :class:`~gb_pin.learn.state.BabbleState`), ``total`` (movements planned).
    """

    def __init__(
        self,
        target: setup.Target,
        state: Any,
        total: int,
        *,
        robot: str | None,
        seed: int | None,
        checkpoint: str | os.PathLike[str] | None = None,
        checkpoint_every: int | None = None,
        wall_before: float = 0.0,
    ) -> None:
        if checkpoint is not None and state.chain is None:
            raise InvalidArgumentError(
                "checkpoints need a robot with a compiled chain, not a Python forward model"
            )
        self.target = target
        self.state = state
        self.total = int(total)
        self.robot = robot
        self.seed = seed
        self.checkpoint = checkpoint
        self.every = check.positive_int("checkpoint_every", checkpoint_every or max(1, total // 10))
        self._wall_before = wall_before
        self._start = time.perf_counter()
        forward = None if state.chain is not None else target.forward
        self._stepper = AskTell(state, total, forward=forward)

    @property
    def movements(self) -> int:
        """Completed movements r (home returns included)."""
        return self._stepper.movements

    @property
    def steps(self) -> int:
        """Completed time steps t."""
        return self.state.steps

    @property
    def done(self) -> bool:
        """Whether all planned movements are complete, or E^X reached ``until_error``."""
        if self.movements >= self.total:
            return True
        if not self._stepper.pending:
            self._stepper.evaluate()  # due evaluations happen between movements (idempotent)
        return self.state.reached

    @property
    def waiting(self) -> bool:
        """Whether an asked posture awaits its :meth:`tell`."""
        return self._stepper.pending

    def ask(self) -> NDArray[np.float64]:
        """The next posture to execute, (m,) [rad] or [m], within the joint limits.

        Raises:
            InvalidArgumentError: asked twice without a tell, or the run is complete.
            DivergenceError: the estimate diverged.
        """
        return self._stepper.ask()

    def tell(self, x: ArrayLike) -> bool:
        """The task-space position (n,) [m] the robot reached at the asked posture.

        Returns:
            True when this step completed a movement.

        Raises:
            InvalidArgumentError: no ask waiting, or not a finite (n,) position (nothing changes).
        """
        finished = self._stepper.tell(x)
        if finished and self.checkpoint is not None and (self.done or self.movements % self.every == 0):
            self.save_checkpoint()
        return finished

    def save_checkpoint(self, path: str | os.PathLike[str] | None = None) -> None:
        """Write the complete state now (to ``path``, default the session's checkpoint file).

        An unanswered ask is not saved: after :func:`resume_session` it is asked again (same posture).
        """
        from gb_pin.runs.checkpoint import CheckpointInfo, write_checkpoint

        where = path if path is not None else self.checkpoint
        if where is None:
            raise InvalidArgumentError("no checkpoint file: pass path= or babble_session(checkpoint=...)")
        self._stepper.sync()
        info = CheckpointInfo(
            robot=self.robot, target_name=self.target.name, movements=self.total, seed=self.seed,
            config=self.state.config, wall_time=self.wall_time,
        )  # fmt: skip
        write_checkpoint(where, self.state, info)

    @property
    def wall_time(self) -> float:
        """Seconds since the session started (plus those before a resume)."""
        return self._wall_before + time.perf_counter() - self._start

    def result(self) -> BabbleResult:
        """The run so far as a :class:`BabbleResult` (E^X recorded up to the last complete movement)."""
        self._stepper.finish()
        learner = GoalBabbling.from_config(self.state.config)
        learner.state_ = self.state
        return BabbleResult(
            target=self.target,  # type: ignore[arg-type]
            targets=self.state.eval_targets,
            history=learner.history_,
            model=learner.model_,
            config=learner.config_,
            seed=self.seed,
            robot=self.robot,
            movements=learner.movements_,
            steps=learner.steps_,
            wall_time=self.wall_time,
            recording=learner.recording_,
            state=self.state,
            **goal_fields(self.state),
        )


def babble_session(
    robot: str | setup.Target = "planar20",
    movements: int = 1000,
    seed: int | np.random.Generator = 0,
    learning_rate: float | None = None,
    *,
    sigma: float | None = None,
    sigma_delta: float | None = None,
    radius: float | None = None,
    path_length: int | None = None,
    p_home: float | None = None,
    targets: ArrayLike | None = None,
    eval_targets: ArrayLike | None = None,
    schedule: ArrayLike | None = None,
    record: Recording | None = None,
    goals: str | GoalGenerator | None = None,
    changes: dict[int, Any] | None = None,
    init: BabbleResult | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: int | None = None,
    until_error: float | None = None,
) -> BabbleSession:
    """A goal-babbling run as an ask/tell loop; the arguments are :func:`gb_pin.babble`'s.

    Returns:
        A :class:`BabbleSession`: ``ask()`` / ``tell(x)`` until ``done``, then ``result()``.

    Raises:
        UnknownRobotError: unknown preset name.
        InvalidArgumentError: any other bad argument.
    """
    given = {"learning_rate": learning_rate, "sigma": sigma, "sigma_delta": sigma_delta,
             "radius": radius, "path_length": path_length, "p_home": p_home}  # fmt: skip
    target, name, movements, X, learner, rng, int_seed = setup.prepare(
        robot, movements, seed, given, targets, init
    )
    setup.check_hooks(record=record)
    if checkpoint is not None:
        check_writable(checkpoint, "checkpoint")
    state = setup.start_state(
        target, learner, X, movements, rng, eval_targets=eval_targets, schedule=schedule, record=record,
        goals=goals, changes=changes, init=init, until_error=until_error,
    )  # fmt: skip
    return BabbleSession(target, state, movements, robot=name, seed=int_seed, checkpoint=checkpoint,
                         checkpoint_every=checkpoint_every)  # fmt: skip


def resume_session(
    checkpoint: str | os.PathLike[str],
    robot: setup.Target | None = None,
    *,
    checkpoint_every: int | None = None,
) -> BabbleSession:
    """The session saved in a checkpoint file, ready to ask (and to keep checkpointing there).

    Raises:
        ResultFileError: missing, corrupted or foreign checkpoint.
    """
    from gb_pin.robot.presets import load_robot
    from gb_pin.runs.checkpoint import read_checkpoint

    check_writable(checkpoint, "checkpoint")
    state, info = read_checkpoint(checkpoint)
    if robot is None:
        if info.robot is None:
            raise InvalidArgumentError(
                f"{os.fspath(checkpoint)}: the run used a custom robot {info.target_name!r}; "
                "pass it as robot="
            )
        robot = load_robot(info.robot)
    return BabbleSession(
        robot, state, info.movements, robot=info.robot, seed=info.seed, checkpoint=checkpoint,
        checkpoint_every=checkpoint_every, wall_before=info.wall_time,
    )  # fmt: skip


def babble_function(
    target: FunctionTarget,
    learner: GoalBabbling,
    X: NDArray[np.float64],
    movements: int,
    rng: np.random.Generator,
    seed: int | None,
    callback: Callable[[int], Any] | None,
    viewer: Any | None,
    checkpoint: Any,
    options: dict[str, Any],
) -> BabbleResult:
    """babble() on a forward model, by the ask/tell stepping.

    A Python ``forward()`` is called once per step; a compiled kernel runs inside compiled code,
    whole movements at a time.

    Raises:
        InvalidArgumentError: a viewer or checkpoint was asked for (they need a compiled chain).
    """
    if viewer is not None or checkpoint is not None:
        raise InvalidArgumentError(
            "viewer= and checkpoint= need a robot with a compiled chain (a KinematicTarget)"
        )
    state = setup.start_state(target, learner, X, movements, rng, **options)
    session = BabbleSession(target, state, movements, robot=None, seed=seed)
    forward = target.function
    every = max(1, movements // 100)
    if target.kernel is not None:  # a compiled forward model: whole movements in compiled code
        while not session.done:
            session._stepper.run_kernel(target.kernel, min(movements, session.movements + every))
            if callback is not None:
                callback(session.movements)
        return session.result()
    while not session.done:
        if session.tell(forward(session.ask())) and callback is not None and session.movements % every == 0:
            callback(session.movements)
    return session.result()
