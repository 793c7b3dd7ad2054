"""``babble_session()``: goal babbling as an ask/tell loop, for hardware and simulators.

>>> session = babble_session("planar5", movements=10, seed=0)
>>> while not session.done:
...     q = session.ask()            # the posture to execute (clipped to the limits)
...     session.tell(robot_moves_to(q))  # the position reached, or None if unseen  # doctest: +SKIP
>>> result = session.result()        # a BabbleResult, as babble() returns

Driven with the robot's compiled forward kinematics (``target.chain.forward``) a session is
bit-identical to ``babble()`` with the same seed and arguments. Nothing moves the robot but what
``ask()`` returns: a robot given without a forward model (:class:`~gb_pin.robot.external.ExternalRobot`)
is first asked for home, and E^X comes from evaluation movements (``evaluate="movements"``) or
not at all. ``ask_kind`` says what each ask is for. Checkpoints are written every
``checkpoint_every`` movements (after the tell that completes the movement; the file is locked
while the session lives) and continue with :func:`resume_session`.
"""

from __future__ import annotations

import contextlib
import os
import time
import warnings
from contextlib import ExitStack
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin._files import check_writable, fallback_path
from gb_pin.exceptions import FileWriteError, GbPinWarning, InvalidArgumentError
from gb_pin.learn.asktell import AskTell, posture, reading
from gb_pin.learn.feedback import FeedbackReach
from gb_pin.learn.metrics import evaluation_schedule
from gb_pin.learn.probe import EvaluationMoves
from gb_pin.learn.state import BabbleState
from gb_pin.robot.external import ExternalRobot
from gb_pin.runs import setup
from gb_pin.runs.result import BabbleResult, state_fields
from gb_pin.runs.spec import RunSpec
from gb_pin.safety.record import result_fields, settings_of

HOME, LEARN = "home", "learn"


class BabbleSession:
    """A goal-babbling run stepped from outside: :meth:`ask` a posture, :meth:`tell` the position reached.

    Build it with :func:`babble_session` (or :func:`resume_session`). Attributes: ``target`` (the
    robot), ``state`` (the :class:`~gb_pin.learn.state.BabbleState`; None until an external robot's
    home reading arrived), ``total`` (movements planned), ``evaluate`` (where E^X comes from).
    """

    def __init__(
        self,
        target: setup.Target,
        state: BabbleState | None,
        total: int,
        *,
        robot: str | None,
        seed: int | None,
        checkpoint: str | os.PathLike[str] | None = None,
        checkpoint_every: int | None = None,
        wall_before: float = 0.0,
        evaluate: str = "model",
        start: Any = None,
        guard: Any = None,
    ) -> None:
        self.target = target
        self.guard = guard  # a gb_pin.safety.CollisionChecker (or any guard(q_from, q_to)); None: no check
        self.cuts = 0  # asks cut short by the guard (all kinds: learning, evaluation, transit, reaching)
        self._held: NDArray[np.float64] | None = None  # the posture the robot holds (the last asked)
        self.state = state
        self.total = int(total)
        self.robot = robot
        self.seed = seed
        self.checkpoint = None if checkpoint is None else check_writable(checkpoint, "checkpoint")
        self.every = (
            max(1, self.total // 10)
            if checkpoint_every is None
            else check.positive_int("checkpoint_every", checkpoint_every, 1, check.MAX_MOVEMENTS)
        )
        self.evaluate = evaluate
        self.unobserved = 0  # test targets of evaluation movements whose reading never arrived
        self._wall_before = wall_before
        self._start = time.perf_counter()
        self._begin = start  # for a robot without a model: builds the state from home's reading
        self._probe: EvaluationMoves | None = None
        self._probe_entry = -1
        self._kind: str | None = None
        self._locks = ExitStack()
        if self.checkpoint is not None:
            from gb_pin.runs.checkpoint import checkpoint_lock

            self._locks.enter_context(checkpoint_lock(self.checkpoint))
        self._stepper: AskTell | None = None
        if state is not None:
            self._attach(state)

    def _attach(self, state: BabbleState) -> None:
        self.state = state
        forward = (  # E^X of a plant on its true body (no lag, no noise): its true_forward
            None
            if state.chain is not None or isinstance(self.target, ExternalRobot)
            else getattr(self.target, "true_forward", self.target.forward)
        )
        guard = None if self.guard is None else self._guard_learning
        self._stepper = AskTell(state, self.total, forward=forward, evaluate=self.evaluate, guard=guard)
        self._held = state.vectors["q_exec"].copy()

    def _guard_learning(self, q_from: NDArray[np.float64], q_to: NDArray[np.float64]) -> Any:
        """The learner's asks are checked from where the robot is (after evaluation moves too)."""
        cut = self.guard(q_from if self._held is None else self._held, q_to)
        self.cuts += cut is not None
        return cut

    def _safe(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """An ask other than a learning step, checked from the held posture (cut short if unsafe)."""
        cut = None if self.guard is None or self._held is None else self.guard(self._held, q)
        self.cuts += cut is not None
        q = q if cut is None else np.asarray(cut, dtype=float)
        self._held = q.copy()
        return q

    # -- the lock on the checkpoint file ------------------------------------------------
    def close(self) -> None:
        """Release the checkpoint file's lock (the session can go on; a later run may take the file)."""
        self._locks.close()

    def __enter__(self) -> BabbleSession:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        if getattr(self, "checkpoint", None) is None:
            return  # no lock held (and nothing to do at interpreter exit)
        with contextlib.suppress(Exception):  # at interpreter exit the lock dies with the process anyway
            self._locks.close()

    # -- progress -----------------------------------------------------------------------
    @property
    def movements(self) -> int:
        """Completed movements r (home returns included)."""
        return 0 if self.state is None else self.state.movements

    @property
    def steps(self) -> int:
        """Completed learning steps t."""
        return 0 if self.state is None else self.state.steps

    @property
    def missing(self) -> int:
        """Learning steps whose reading was missing (told None)."""
        return 0 if self.state is None else self.state.missing

    @property
    def done(self) -> bool:
        """Whether the planned movements (and their evaluations) are complete, or E^X reached until_error."""
        if self.state is None or self._probe is not None or self._stepper is None:
            return False
        if self._stepper.pending:
            return False
        if self._stepper.evaluate() is not None:
            return False  # evaluation movements are due
        return self.movements >= self.total or self.state.reached

    @property
    def waiting(self) -> bool:
        """Whether an asked posture awaits its :meth:`tell`."""
        return self._kind is not None

    @property
    def ask_kind(self) -> str | None:
        """What the waiting ask is for (None: no ask waiting).

        ``"learn"``: a babbling step; ``"home"``: the first reading of an external robot, at home;
        ``"evaluation"``: a test posture g(x*), its reading measures E^X; ``"transit"``: on the way
        to or from one, its reading is ignored. Nothing is learnt from any but ``"learn"``.
        """
        return self._kind

    # -- ask / tell -----------------------------------------------------------------------
    def ask(self) -> NDArray[np.float64]:
        """The next posture to execute, (m,) [rad] or [m], within the joint limits (see :attr:`ask_kind`).

        Raises:
            InvalidArgumentError: asked twice without a tell, or the run is complete.
            DivergenceError: the estimate diverged.
        """
        if self._kind is not None:
            raise InvalidArgumentError(
                "ask() called twice: tell(x) the position reached for the last posture first"
            )
        if self._stepper is None:
            self._kind = HOME
            return np.array(self.target.home, dtype=float)
        st = self.state
        assert st is not None
        if self._probe is None and not self._stepper.pending:
            entry = self._stepper.evaluate()
            if entry is not None:
                postures = np.clip(self._stepper.predict(st.eval_targets), st.lower, st.upper)
                self._probe = EvaluationMoves(
                    st.eval_targets, postures, st.vectors["q_exec"].copy(), st.max_step
                )
                self._probe_entry = entry
        if self._probe is not None:
            self._kind = self._probe.kind
            return self._safe(self._probe.ask())
        q = self._stepper.ask()
        self._held = q.copy()
        self._kind = LEARN
        return q

    def tell(self, x: ArrayLike | None, executed: ArrayLike | None = None) -> bool:
        """The task-space position (n,) [m] the robot reached at the asked posture; None if unseen.

        A missing reading (None) teaches nothing: the movement goes on and t advances (a missing
        reading of home or of a test posture is asked again).

        ``executed``: the posture (m,) the robot actually reached, when it differs from the one
        asked (a servo clipped, stalled or rounded it to its ticks; e.g. what
        :meth:`gb_pin.hardware.FeetechArm.move` returns): a learning step learns from it instead.
        Ignored for home, evaluation and transit asks. None (the default): the asked posture,
        bit-identical to a tell without it.

        Returns:
            True when this tell completed a learning movement.

        Raises:
            InvalidArgumentError: no ask waiting, or not None nor a finite real (n,) position
                (nothing changes then).
        """
        if self._kind is None:
            raise InvalidArgumentError("tell(x) without ask(): ask() for a posture first")
        arr = reading(x, self.target.n_task)
        done = None if self._stepper is None else posture(executed, self.target.n_joints)
        kind, self._kind = self._kind, None
        if kind == HOME:
            if arr is not None:
                self._attach(self._begin(arr))
            return False
        if kind != LEARN:
            assert self._probe is not None and self._stepper is not None
            self._probe.tell(arr)
            if self._probe.done:
                probe, self._probe = self._probe, None
                self.unobserved += probe.unobserved
                self._stepper.record_evaluation(self._probe_entry, probe.error())
            return False
        assert self._stepper is not None
        finished = self._stepper.tell(arr, done)
        if (
            finished
            and self.checkpoint is not None
            and (self.movements % self.every == 0 or self.movements >= self.total)
        ):
            self._checkpoint_or_fall_back()
        return finished

    def reacher(self, target: ArrayLike, **options: Any) -> FeedbackReach:
        """Feedback reaching of ``target`` (n,) [m] on the session's current model, as an ask/tell loop.

        It starts where the robot is and keeps the session's joint-step limit; nothing is learnt.
        Drive it (``while not r.done: r.tell(robot(r.ask()))``) between the session's own asks.

        Args:
            target: x* [m].
            **options: :class:`~gb_pin.learn.feedback.FeedbackReach`'s (``observations``, ``gain``, ...).

        Raises:
            InvalidArgumentError: nothing learnt yet, or an ask of the session awaits its tell.
        """
        if self.state is None or self._stepper is None or self._kind is not None:
            raise InvalidArgumentError(
                "reach between the session's steps, after home's reading: tell() first"
            )
        st = self.state
        self._stepper.sync()
        step = None if not np.isfinite(st.max_step) else float(st.max_step)
        options.setdefault("start", st.vectors["q_exec"].copy() if self._held is None else self._held.copy())
        reach = FeedbackReach(st.llm, target, st.lower, st.upper, max_joint_step=step, **options)
        if self.guard is not None:
            reach.ask = lambda: self._safe(FeedbackReach.ask(reach))  # type: ignore[method-assign]
        return reach

    # -- files ------------------------------------------------------------------------------
    def save_checkpoint(self, path: str | os.PathLike[str] | None = None) -> str:
        """Write the complete state now (to ``path``, default the session's checkpoint file); returns where.

        An unanswered ask is not saved: after :func:`resume_session` it is asked again (same posture).
        A robot with a state of its own (a simulated plant: ``robot_state()``) is saved with it;
        save between a tell and the next ask, when robot and learner agree.

        Raises:
            InvalidArgumentError: no file given or set, a path that cannot be written, another run's
                file, or nothing to save yet (an external robot's home reading has not arrived).
            FileWriteError: the write failed (a full disk), naming the file (also an OSError).
        """
        from gb_pin.runs.checkpoint import CheckpointInfo, checkpoint_lock, robot_state, write_checkpoint
        from gb_pin.runs.robot_source import describe

        where = path if path is not None else self.checkpoint
        if where is None:
            raise InvalidArgumentError("no checkpoint file: pass path= or babble_session(checkpoint=...)")
        if self.state is None or self._stepper is None:
            raise InvalidArgumentError("nothing to save yet: the reading of home has not arrived")
        where = check_writable(where, "checkpoint")
        self._stepper.sync()
        info = CheckpointInfo(
            robot=self.robot, target_name=self.target.name, movements=self.total, seed=self.seed,
            config=self.state.config, wall_time=self.wall_time, safety=settings_of(self.guard, self.cuts),
            source=describe(self.target, self.robot) if self.state.chain is not None else None,
            evaluate=self.evaluate, unobserved=self.unobserved, robot_state=robot_state(self.target),
        )  # fmt: skip
        same = self.checkpoint is not None and os.path.abspath(where) == os.path.abspath(self.checkpoint)
        with ExitStack() as locks:
            if not same:
                locks.enter_context(checkpoint_lock(where))
            try:
                write_checkpoint(where, self.state, info)
            except OSError as exc:
                if isinstance(exc, FileWriteError):
                    raise
                error = FileWriteError(f"cannot write the checkpoint {where!r}: {exc.strerror or exc}")
                error.errno = exc.errno
                raise error from exc
        return where

    def _checkpoint_or_fall_back(self) -> None:
        """The periodic checkpoint; a failed write (a full disk) goes elsewhere, with a warning."""
        assert self.checkpoint is not None
        try:
            self.save_checkpoint()
            return
        except OSError as exc:
            failure = exc
        where = fallback_path(self.checkpoint)
        try:
            self.save_checkpoint(where)
        except (OSError, InvalidArgumentError) as exc:
            warnings.warn(
                f"cannot write the checkpoint {os.fspath(self.checkpoint)!r} ({failure}) "
                f"nor {where!r} ({exc}); the session goes on, unsaved",
                GbPinWarning,
                stacklevel=3,
            )
            return
        warnings.warn(
            f"cannot write the checkpoint {os.fspath(self.checkpoint)!r} ({failure}); "
            f"writing it to {where!r} from now on",
            GbPinWarning,
            stacklevel=3,
        )
        self._locks.close()
        self._locks = ExitStack()
        self.checkpoint = where

    @property
    def wall_time(self) -> float:
        """Seconds since the session started (plus those before a resume)."""
        return self._wall_before + time.perf_counter() - self._start

    def result(self) -> BabbleResult:
        """The run so far as a :class:`BabbleResult` (E^X recorded up to the last complete movement).

        Raises:
            InvalidArgumentError: nothing learnt yet (an external robot's home reading has not arrived).
        """
        if self.state is None or self._stepper is None:
            raise InvalidArgumentError("no result yet: the reading of home has not arrived")
        if self._probe is None and not self._stepper.pending:
            self._stepper.finish()
        self._stepper.sync()
        from gb_pin.learn.learner import GoalBabbling

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
            **state_fields(self.state),
            **result_fields(self.guard, self.cuts),
        )


def babble_session(
    robot: str | setup.Target | RunSpec = "planar20",
    movements: int = 1000,
    seed: int | np.random.Generator = 0,
    *,
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: int | None = None,
    evaluate: str | None = None,
    **options: Any,
) -> BabbleSession:
    """A goal-babbling run as an ask/tell loop.

    Args:
        robot: a :class:`~gb_pin.runs.spec.RunSpec` (the whole run), or the robot: any robot
            :func:`gb_pin.babble` takes, or an :class:`~gb_pin.robot.external.ExternalRobot` (a robot
            on hardware: no forward model).
        movements: movements to run (home returns included).
        seed: an int seed or a numpy Generator.
        checkpoint: write the complete state to this file every ``checkpoint_every`` movements (and
            at the last); the file is locked while the session lives (:meth:`BabbleSession.close`).
        checkpoint_every: movements between checkpoints (default a tenth of the run).
        evaluate: where E^X comes from: ``"model"`` (the robot's forward kinematics; the default
            where there is one), ``"movements"`` (the session asks the test postures g(x*) and
            measures their readings; learns nothing from them; the default for an external robot is
            ``"none"``: no E^X, only the free measure ``History.reach``). With ``"movements"`` the
            default schedule is sparse (5 evaluations per decade of movements).
        **options: the rest of the run's description, as :func:`gb_pin.babble` takes them
            (``learning_rate``, ``sigma``, ..., ``targets``, ``goals``, ``max_joint_step``, ...):
            see :class:`~gb_pin.runs.spec.RunSpec`.

    Returns:
        A :class:`BabbleSession`: ``ask()`` / ``tell(x)`` until ``done``, then ``result()``.

    Raises:
        UnknownRobotError: unknown preset name.
        InvalidArgumentError: any other bad argument.
    """
    spec = robot if isinstance(robot, RunSpec) else RunSpec.of(robot, movements, seed, **options)
    if isinstance(robot, RunSpec) and options:
        raise InvalidArgumentError(f"give the run as a RunSpec or as arguments, not both: {sorted(options)}")
    run = setup.prepare(spec)
    external = isinstance(run.target, ExternalRobot)
    if evaluate is None:
        evaluate = "none" if external else "model"
    if evaluate not in ("model", "movements", "none"):
        raise InvalidArgumentError(f"evaluate must be 'model', 'movements' or 'none', got {evaluate!r}")
    if evaluate == "model" and external:
        raise InvalidArgumentError(
            "evaluate='model' needs a forward model; an ExternalRobot is evaluated by 'movements' or 'none'"
        )
    schedule = spec.schedule
    if schedule is None and evaluate == "movements":
        schedule = evaluation_schedule(run.movements, dense_until=0, per_decade=5)

    def begin(home_position: Any = None) -> BabbleState:
        return setup.start_state(run, schedule=schedule, home_position=home_position)

    return BabbleSession(
        run.target, None if external else begin(), run.movements, robot=run.name, seed=run.seed,
        checkpoint=checkpoint, checkpoint_every=checkpoint_every, evaluate=evaluate, start=begin,
        guard=run.guard,
    )  # fmt: skip


def resume_session(
    checkpoint: str | os.PathLike[str],
    robot: setup.Target | None = None,
    *,
    checkpoint_every: int | None = None,
    guard: Any = None,
) -> BabbleSession:
    """The session saved in a checkpoint file, ready to ask (and to keep checkpointing there).

    Args:
        checkpoint: the file.
        robot: the robot; needed (and checked against the file) for a robot given as a function,
            an external robot, a plant, or a model the file cannot rebuild. A simulated plant
            continues from the state the checkpoint saved.
        checkpoint_every: movements between checkpoints (default a tenth of the run).
        guard: a collision checker instead of the one built from the obstacles and settings a safe
            session's checkpoint records (:mod:`gb_pin.safety.record`).

    Raises:
        ResultFileError: missing, corrupted or foreign checkpoint, or one of another robot.
        InvalidArgumentError: the robot is needed and not given.
    """
    from gb_pin.runs.checkpoint import checkpoint_robot, read_checkpoint, restore_robot_state, same_robot

    check_writable(checkpoint, "checkpoint")
    state, info = read_checkpoint(checkpoint)
    if robot is None:
        robot = checkpoint_robot(checkpoint, info)
    same_robot(checkpoint, robot, state)
    restore_robot_state(checkpoint, robot, info.robot_state)  # a simulated plant continues where it was
    guard = guard or setup.recorded_guard(robot, info.safety)  # its obstacles and settings, checked again
    session = BabbleSession(
        robot, state, info.movements, robot=info.robot, seed=info.seed, checkpoint=checkpoint,
        checkpoint_every=checkpoint_every, wall_before=info.wall_time, evaluate=info.evaluate, guard=guard,
    )  # fmt: skip
    session.unobserved, session.cuts = info.unobserved, int((info.safety or {}).get("cut_asks", 0))
    return session
