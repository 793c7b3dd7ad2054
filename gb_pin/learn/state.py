"""The complete, resumable state of a goal-babbling run, and the chunked calls of the compiled loop."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin._signals import deferring
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn import layout
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.learn.body.kinematics import Kinematics
from gb_pin.learn.clock import SLICE_SECONDS
from gb_pin.learn.config import BabbleConfig
from gb_pin.learn.divergence import divergence_error
from gb_pin.learn.exploration import noise_init
from gb_pin.learn.goals import GoalGenerator, PythonGoals, make_goals
from gb_pin.learn.goals.base import GoalArrays
from gb_pin.learn.history import History, RecordedSteps, Recording
from gb_pin.learn.llm import LocalLinearMap
from gb_pin.learn.loop import babble_loop
from gb_pin.learn.metrics import evaluation_schedule
from gb_pin.learn.sensor import NO_SENSOR, Sensor, SensorArrays, observe_into

REACH_WINDOW = 50
"""Goal-directed movements over which the free measure of progress is a running median."""

OUTLIER = 100.0
"""A reading beyond this many times the goal set's extent is named as the cause of a divergence."""


class BabbleState:
    """The complete state of a goal-babbling run: everything the compiled loop reads and writes.

    Holding it in plain arrays makes a run resumable: :meth:`run` continues it, and
    :meth:`to_arrays` / :meth:`from_arrays` (used by checkpoints) rebuild it exactly.
    ``changes`` is the schedule of body changes: at movement r the chain becomes the given
    one (same joints and task dimension), e.g. grown links or a tool.
    """

    VECTORS = ("q_prev", "q_start", "q_end", "x_prev", "target_prev", "path_start", "path_end", "q_exec")
    REC_DTYPES: ClassVar[dict[str, type]] = dict(zip(RecordedSteps.FIELDS, RecordedSteps.DTYPES, strict=True))

    def __init__(self) -> None:
        self.far_reading: tuple[int, int, NDArray[np.float64]] | None = None  # (note_reading)
        self._extent: tuple[NDArray[np.float64], float] | None = None  # (the goal set, its outlier bound)
        self.rng: np.random.Generator
        self.config: BabbleConfig
        self.chain: KinematicChain | None
        self.home: NDArray[np.float64]
        self.lower: NDArray[np.float64]
        self.upper: NDArray[np.float64]
        self.targets: NDArray[np.float64]
        self.eval_targets: NDArray[np.float64]
        self.schedule: NDArray[np.int64]
        self.errors: NDArray[np.float64]
        self.distances: NDArray[np.float64]
        self.components: NDArray[np.float64]
        self.llm: LocalLinearMap
        self.A: NDArray[np.float64]
        self.b: NDArray[np.float64]
        self.vectors: dict[str, NDArray[np.float64]]
        self.istate: NDArray[np.int64]
        self.record: tuple[int, int, int]
        self.rec: dict[str, NDArray[Any]]
        self.goals: GoalGenerator
        self.goal_state: GoalArrays
        self.changes: list[tuple[int, KinematicChain]] = []
        self.until_error: float | None = None
        self.max_step: float = np.inf
        self.sensor: SensorArrays | None = None
        self.reach: NDArray[np.float64] = np.zeros(REACH_WINDOW)
        self.reaches: NDArray[np.float64]
        # Ctrl-C: polled whenever the compiled loop returns at the end of a time slice (SLICE_SECONDS);
        # True stops :meth:`run` there, between movements or inside an evaluation (redone on resuming).
        self.interrupt: Callable[[], bool] | None = None
        self._progress = np.zeros(5)  # an evaluation under way, the slice (Evaluation.progress), not saved
        self._clock = np.zeros(2, dtype=np.int64)

    @classmethod
    def start(
        cls,
        kinematics: Kinematics,
        targets: ArrayLike,
        movements: int,
        config: BabbleConfig,
        *,
        seed: int | np.random.Generator = 0,
        eval_targets: ArrayLike | None = None,
        schedule: ArrayLike | None = None,
        record: Recording | None = None,
        goals: str | GoalGenerator | None = None,
        changes: dict[int, Kinematics] | None = None,
        until_error: float | None = None,
        max_joint_step: float | None = None,
        sensor: Sensor | None = None,
        reach_window: int = REACH_WINDOW,
        home_position: ArrayLike | None = None,
    ) -> BabbleState:
        """A fresh run at movement 0: the estimate is the constant q_home (paper Sec. II).

        ``until_error``: the run ends at the first evaluation with E^X <= this level [m].
        ``max_joint_step``: no step moves a joint farther than this from the last executed
        posture ([rad] or [m]; None: no limit). ``sensor``: what observes x (noise, missing
        readings; None: x = f(q) exactly, or the robot's own ``sensor``). ``reach_window``: the
        goal-directed movements over which the free measure of progress (the median reach
        error, ``History.reach``) is taken. ``home_position``: f(q_home) as observed, for a robot
        whose forward kinematics gb_pin cannot compute (a robot on hardware).
        """
        movements = check.positive_int("movements", movements)
        st = cls()
        st.until_error = None if until_error is None else check.positive_float("until_error", until_error)
        st.max_step = (
            np.inf if max_joint_step is None else check.positive_float("max_joint_step", max_joint_step)
        )
        st.reach = np.zeros(check.positive_int("reach_window", reach_window, 1, 10**6))
        st.rng = check.generator(seed)
        st.config = config
        # A robot given as a Python forward model has no compiled chain (ask/tell runs only).
        st.chain = getattr(kinematics, "chain", None)
        m, n = (st.chain.n_joints, st.chain.n_task) if st.chain is not None else _dimensions(kinematics)
        st.home = check.vector("home", kinematics.home, m)
        st.lower = np.ascontiguousarray(kinematics.lower, dtype=float)
        st.upper = np.ascontiguousarray(kinematics.upper, dtype=float)
        st.targets = check.points("targets", targets, n)
        st.eval_targets = (
            st.targets if eval_targets is None else check.points("eval_targets", eval_targets, n)
        )
        st.schedule = _schedule(schedule, movements)
        st.errors = np.full(st.schedule.shape[0], np.nan)
        st.distances = np.full(st.schedule.shape[0], np.nan)
        C = 0 if st.chain is None else st.chain.n_components  # no chain: a Python forward model
        st.components = np.full((st.schedule.shape[0], C), np.nan)
        st.reaches = np.full(st.schedule.shape[0], np.nan)
        st.goals = make_goals(goals)
        st.goal_state = st.goals.start(st.targets)
        st.set_changes(changes or {})
        sensor = sensor if sensor is not None else getattr(kinematics, "sensor", None)
        if sensor is not None and not isinstance(sensor, Sensor):
            raise InvalidArgumentError(f"sensor must be a gb_pin Sensor or None, got {sensor!r}")
        if sensor is not None and st.chain is None:
            raise InvalidArgumentError(
                "a sensor model needs a robot with compiled kinematics; a robot given as a function "
                "or on hardware returns its readings itself"
            )
        st.sensor = None if sensor is None or sensor.ideal else sensor.start(n)
        x_home = st._home_position(kinematics, home_position, n)
        st.llm = LocalLinearMap(config.radius, config.learning_rate, config.cutoff).initialize(
            x_home, st.home
        )
        st.A = np.empty((m, n))
        st.b = np.empty(m)
        deferring(noise_init, st.rng, config.sigma, st.A, st.b)
        # The robot starts at rest at home: previous posture, position and target are home's.
        st.vectors = {k: (st.home if k.startswith("q") else x_home).copy() for k in cls.VECTORS}
        st.istate = np.zeros(layout.ISTATE_SIZE, dtype=np.int64)
        st.istate[layout.KIND] = layout.NONE
        st.istate[layout.LAST_KIND] = layout.NONE
        st.istate[layout.PROTOTYPES] = 1
        if record is None:
            st.record = (1, 0, 0)
            size = 0
        else:
            last = movements if record.last is None else min(record.last, movements)
            st.record = (record.every, record.first, last)
            final = max(0, (last - record.first) * config.path_length // record.every + 1)
            nbytes = final * 8 * (2 + m + 2 * n)
            if nbytes > MAX_RECORD_BYTES:
                raise InvalidArgumentError(
                    f"record={record!r} over {movements} movements would record {final} steps "
                    f"({nbytes / 2**30:.1f} GiB); at most {MAX_RECORD_BYTES / 2**30:g} GiB "
                    "(gb_pin.learn.state.MAX_RECORD_BYTES): record fewer movements or every k-th step"
                )
            size = min(final, 4096)  # grown on demand by the loop (NEED_RECORD_CAPACITY)
        st.rec = {k: np.zeros((size, m) if k == "posture" else (size, n) if k in ("target", "position")
                              else size, dtype=d) for k, d in cls.REC_DTYPES.items()}  # fmt: skip
        return st

    def set_changes(self, changes: dict[int, Kinematics]) -> None:
        """Schedule body changes ``{movement: robot}``: from movement r on, the robot's chain is used.

        Raises:
            InvalidArgumentError: a movement count < 1, or a chain of other joint or task dimensions.
        """
        out = []
        if changes and self.chain is None:
            raise InvalidArgumentError(
                "body changes need robots with a compiled chain (not a Python forward model)"
            )
        for at, robot in sorted(dict(changes).items()):
            at = check.movements("changes movement", at, minimum=1)
            chain = getattr(robot, "chain", robot)
            if not isinstance(chain, KinematicChain):
                raise InvalidArgumentError(
                    f"changes[{at}] must be a robot or a KinematicChain, got {robot!r}"
                )
            base = self.chain
            assert base is not None
            if (chain.n_joints, chain.n_task, chain.n_components) != (
                base.n_joints, base.n_task, base.n_components
            ):  # fmt: skip
                raise InvalidArgumentError(
                    f"changes[{at}] has {chain.n_joints} joints and {chain.n_task} task axes; the run has "
                    f"{base.n_joints} and {base.n_task}"
                )
            out.append((at, chain))
        self.changes = out

    def _home_position(self, kinematics: Any, given: ArrayLike | None, n: int) -> NDArray[np.float64]:
        """f(q_home) as the learner first sees it: given, observed through the sensor, or computed."""
        if given is not None:
            return check.vector("home_position", given, n)
        if self.chain is None:  # a forward model; one whose reading is lost (None) is asked again
            for _ in range(1000):
                x = kinematics.forward(self.home.copy())
                if x is not None:
                    return check.vector("forward(home)", x, n)
            raise InvalidArgumentError(f"{kinematics!r:.80} lost 1000 readings of home in a row")
        x = self.chain.forward(self.home)
        if self.sensor is None:
            return x
        for _ in range(1000):  # a reading of home that arrives (the loss is < 1)
            reading = x.copy()
            if observe_into(self.sensor, reading):
                return reading
        raise InvalidArgumentError(
            f"the sensor lost 1000 readings of home in a row (loss {self.sensor.loss})"
        )

    @property
    def reached(self) -> bool:
        """True once an evaluation found E^X <= ``until_error``: the run is over."""
        if self.until_error is None:
            return False
        c = int(self.istate[layout.EVAL_CURSOR])
        return bool(np.any(self.errors[:c] <= self.until_error))

    @property
    def movements(self) -> int:
        """Completed movements r."""
        return int(self.istate[layout.MOVEMENTS])

    @property
    def steps(self) -> int:
        """Completed time steps t."""
        return int(self.istate[layout.STEPS])

    @property
    def missing(self) -> int:
        """Steps whose reading was missing (nothing was learnt from them)."""
        return int(self.istate[layout.MISSING])

    @property
    def posture(self) -> NDArray[np.float64]:
        """The last executed posture q_t."""
        return self.vectors["q_prev"]

    @property
    def position(self) -> NDArray[np.float64]:
        """The last reached position x_t [m]."""
        return self.vectors["x_prev"]

    @property
    def target(self) -> NDArray[np.float64]:
        """The last goal-directed target x*_t [m]."""
        return self.vectors["target_prev"]

    def kernel_args(self, seconds: float = math.inf) -> tuple[Any, ...]:
        """(learner, robot, run, goals, monitor): the compiled loop's arguments, built in this one place.

        ``seconds``: the loop's time slice (:data:`~gb_pin.learn.clock.SLICE_SECONDS`; inf: none).
        """
        cfg = self.config
        hyper = layout.Hyper(
            float(cfg.learning_rate), float(cfg.sigma), float(cfg.sigma_delta), float(cfg.radius),
            int(cfg.path_length), float(cfg.p_home),
        )  # fmt: skip
        m, n = self.home.shape[0], self.targets.shape[1]
        body = self.chain.forward_kernel() if self.chain is not None else None
        v = self.vectors
        q_prev, q_start, q_end, x_prev, target_prev, path_start, path_end, q_exec = (
            v[k] for k in self.VECTORS
        )
        motion = layout.Motion(
            q_prev, q_start, q_end, x_prev, target_prev, path_start, path_end,
            np.empty(m), np.empty(n), np.empty(n), q_exec,
        )  # fmt: skip
        r = self.rec
        recorder = layout.Recorder(*self.record, *(r[k] for k in RecordedSteps.FIELDS))
        until = -np.inf if self.until_error is None else float(self.until_error)
        evaluation = layout.Evaluation(
            self.schedule,
            self.eval_targets,
            self.errors,
            self.distances,
            self.components,
            until,
            self.reaches,
            float(seconds),
            self._progress,
            self._clock,
        )
        limits = layout.Limits(self.home, self.lower, self.upper, float(self.max_step))
        sensor = NO_SENSOR if self.sensor is None else self.sensor
        return (
            layout.Learner(hyper, self.llm.kernel(), self.llm.scratch(), layout.Noise(self.A, self.b)),
            layout.Robot(limits, body, sensor),  # type: ignore[arg-type]
            layout.Run(motion, self.istate, self.reach),
            self.goal_state,
            layout.Monitor(evaluation, recorder),
        )

    def run(self, stop: int) -> None:
        """Run the compiled loop until ``stop`` movements are complete (body changes applied on the way).

        Raises:
            DivergenceError: a posture became non-finite.
        """
        while not self.reached:
            self._apply_changes()
            due = [at for at, _ in self.changes if at > self.movements]
            until = min([stop, *due])
            stopped = self._run_until(until)
            if stopped or until >= stop or self.reached:
                self._apply_changes()
                return

    def _apply_changes(self) -> None:
        for at, chain in self.changes:
            if at <= self.movements:
                self.chain = chain

    def _run_until(self, stop: int) -> bool:
        """Run to ``stop``; True if :attr:`interrupt` stopped it before."""
        args = self.kernel_args(SLICE_SECONDS)
        while True:
            status = deferring(babble_loop, self.rng, stop, *args)
            self.llm.set_count(int(self.istate[layout.PROTOTYPES]))
            if status == layout.DONE:
                return False
            if status == layout.SLICE:
                if self.interrupt is not None and self.interrupt():
                    return True
                continue  # nothing was reallocated
            if status == layout.REACHED:
                self._end_at_cursor()
                return False
            if status == layout.NEED_CAPACITY:
                self.llm.reserve(2 * self.llm.capacity)
            elif status == layout.NEED_RECORD_CAPACITY:
                self._grow_recording()
            elif status == layout.NEED_GOAL:
                self._python_goal()
                continue  # nothing was reallocated
            else:
                self._diverged()
            args = self.kernel_args(SLICE_SECONDS)

    def _end_at_cursor(self) -> None:
        """The run stopped at E^X <= until_error: its schedule ends at the evaluation that found it."""
        c = int(self.istate[layout.EVAL_CURSOR])
        self.schedule = self.schedule[:c].copy()
        self.errors = self.errors[:c].copy()
        self.distances = self.distances[:c].copy()
        self.components = self.components[:c].copy()
        self.reaches = self.reaches[:c].copy()

    def _grow_recording(self) -> None:
        grow = max(16, 2 * self.rec["step"].shape[0])
        for key, arr in self.rec.items():
            bigger = np.zeros((grow, *arr.shape[1:]), dtype=arr.dtype)
            bigger[: arr.shape[0]] = arr
            self.rec[key] = bigger

    def _python_goal(self) -> None:
        goals = self.goals
        if not isinstance(goals, PythonGoals):
            raise InvalidArgumentError(f"goal generator {goals!r} of kind {goals.kind} is not compiled")
        goal = check.vector("the goal generator's goal", goals.next_goal(self.goal_state, self.rng),
                            self.targets.shape[1])  # fmt: skip
        self.vectors["path_end"][:] = goal

    def note_reading(self, x: NDArray[np.float64]) -> None:
        """Remember ``x`` if it lies beyond :data:`OUTLIER` times the goal set's extent (ask/tell).

        Should the estimate diverge later, the error names that reading, not the settings.
        """
        if self._extent is None or self._extent[0] is not self.targets:  # once per goal set
            self._extent = (self.targets, OUTLIER * max(float(np.max(np.abs(self.targets))), 0.1))
        if max(map(abs, x.tolist())) > self._extent[1]:  # (numpy's max costs 3 us a tell here)
            self.far_reading = (self.movements, self.steps, x.copy())

    def _diverged(self) -> None:
        raise divergence_error(self, OUTLIER)

    # -- checkpoints ------------------------------------------------------------
    def to_arrays(self) -> dict[str, NDArray[Any]]:
        """Every array of the state, trimmed to what is in use (for checkpoint files)."""
        from gb_pin.learn.snapshot import state_to_arrays

        return state_to_arrays(self)

    def rng_state(self) -> dict[str, Any]:
        """The random generator's bit-generator state (JSON-serialisable)."""
        return dict(self.rng.bit_generator.state)

    def sensor_rng_state(self) -> dict[str, Any] | None:
        """The sensor generator's bit-generator state (JSON-serialisable); None without a sensor."""
        return None if self.sensor is None else dict(self.sensor.rng.bit_generator.state)

    @classmethod
    def from_arrays(
        cls,
        arrays: dict[str, NDArray[Any]],
        config: BabbleConfig,
        rng_state: dict[str, Any],
        goals: str | GoalGenerator | None = None,
        sensor_rng: dict[str, Any] | None = None,
    ) -> BabbleState:
        """Rebuild a state written by :meth:`to_arrays` exactly (same numbers, same random stream).

        ``sensor_rng``: the sensor generator's state (:meth:`sensor_rng_state`), for a run with a sensor.

        Raises:
            InvalidArgumentError: arrays missing, of inconsistent shapes or out of range.
        """
        from gb_pin.learn.snapshot import state_from_arrays

        return state_from_arrays(cls(), arrays, config, rng_state, make_goals(goals), sensor_rng)

    def history(self) -> History:
        """E^X and D^home at the schedule's movement counts (NaN where not reached yet)."""
        components = self.components if self.components.shape[1] else None
        return History(
            movements=self.schedule,
            error=self.errors,
            home_distance=self.distances,
            components=components,
            reach=self.reaches,
        )

    def recorded(self) -> RecordedSteps | None:
        """The recorded steps so far, or None if recording was not asked for."""
        if self.record[2] <= self.record[1]:
            return None
        c = int(self.istate[layout.RECORDED])
        return RecordedSteps(**{k: self.rec[k][:c].copy() for k in RecordedSteps.FIELDS})


MAX_RECORD_BYTES = 2 * 2**30
"""The largest recording a run accepts (checked before the run starts; buffers grow as it goes)."""


def _dimensions(kinematics: Any) -> tuple[int, int]:
    """(m, n) of a robot without a compiled chain (``n_joints``, ``n_task``)."""
    try:
        return int(kinematics.n_joints), int(kinematics.n_task)
    except (AttributeError, TypeError, ValueError) as exc:
        raise InvalidArgumentError(
            f"robot {kinematics!r} has neither a compiled chain nor n_joints and n_task"
        ) from exc


def _schedule(schedule: ArrayLike | None, movements: int) -> NDArray[np.int64]:
    if schedule is None:
        return evaluation_schedule(movements)
    try:
        given = np.asarray(schedule)
        at = np.unique(given.astype(np.int64))
        integral = given.dtype.kind in "iu" or (
            given.dtype.kind == "f" and np.array_equal(at, np.unique(given))
        )
    except (TypeError, ValueError, OverflowError) as exc:
        raise InvalidArgumentError(f"schedule must be movement counts, got {schedule!r}") from exc
    if not integral:
        raise InvalidArgumentError(f"schedule must be integer movement counts, got {schedule!r}")
    if at.ndim != 1 or at.size == 0 or at[0] < 0 or at[-1] > movements:
        raise InvalidArgumentError(
            f"schedule must hold movement counts in [0, {movements}], got {schedule!r}"
        )
    return at
