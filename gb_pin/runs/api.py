"""``babble()``: one call from a robot name to a learned inverse model."""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin._files import check_writable
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.goals import GoalGenerator
from gb_pin.learn.history import Recording
from gb_pin.learn.learner import GoalBabbling
from gb_pin.learn.sensor import Sensor
from gb_pin.learn.state import BabbleState
from gb_pin.robot.bodies import ChangedBody
from gb_pin.robot.external import ExternalRobot
from gb_pin.robot.function import FunctionTarget
from gb_pin.robot.presets import load_robot
from gb_pin.robot.target import KinematicTarget
from gb_pin.runs import setup
from gb_pin.runs.result import BabbleResult, state_fields
from gb_pin.runs.spec import RunSpec


def warmup() -> float:
    """Compile (or load from the on-disk cache) the numba kernels; returns the seconds it took."""
    from gb_pin.runs.coldstart import parallel_compile

    start = time.perf_counter()
    with parallel_compile():  # a cold cache: the kernels compile in two processes
        babble("planar2", movements=1, seed=0, schedule=[0, 1])
    return time.perf_counter() - start


def babble(
    robot: str | setup.Target | RunSpec = "planar20",
    movements: int = 1000,
    seed: int | np.random.Generator = 0,
    learning_rate: float | None = None,
    *,
    sigma: float | None = None,
    sigma_delta: float | None = None,
    radius: float | None = None,
    path_length: int | None = None,
    p_home: float | None = None,
    cutoff: float | None = None,
    targets: ArrayLike | str | None = None,
    eval_targets: ArrayLike | None = None,
    schedule: ArrayLike | None = None,
    callback: Callable[[int], Any] | None = None,
    record: Recording | None = None,
    viewer: Any | None = None,
    observe_every: int = 10,
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: int | None = None,
    goals: str | GoalGenerator | None = None,
    changes: dict[int, Any] | None = None,
    init: BabbleResult | None = None,
    until_error: float | None = None,
    max_joint_step: float | None = None,
    sensor: Sensor | None = None,
    reach_window: int = 50,
    obstacles: Any = None,
    self_collision: bool = False,
    collision_geometry: str = "urdf",
    clearance: float = 0.01,
    slide: bool = True,
) -> BabbleResult:
    """Bootstrap an inverse model of ``robot`` by online goal babbling.

    Parameters left as None take the robot preset's defaults, else the paper's:
    learning_rate 0.1, sigma by Eq. 12 (0.05 at 5 joints), sigma_delta 0.1 sigma,
    radius 0.1 m, path_length 25, p_home 0.1.

    Args:
        robot: a preset name (``"planar5"``, ``"planar20"``, any ``planarN``, ``"so101"``), a
            :class:`~gb_pin.runs.spec.RunSpec` (the whole run: the other run arguments are then
            not given), a :class:`~gb_pin.robot.target.KinematicTarget`, a plant
            (:mod:`gb_pin.plants`: a mis-calibrated body observed through a sensor), or a
            :class:`~gb_pin.robot.function.FunctionTarget` (a forward model, run step
            by step; no viewer or checkpoints), a changed body (:mod:`gb_pin.robot.bodies`),
            a simulated plant (:class:`gb_pin.sim.MujocoPlant`, or ``"so101@mujoco:kp=10"``),
            or ``"MODULE:NAME"`` naming one of those in a module or ``.py`` file.
        movements: number of movements (home returns included).
        seed: an int seed or a numpy Generator; same seed, same result.
        learning_rate: eta.
        sigma: exploration noise per joint [rad].
        sigma_delta: random-walk step of the noise [rad].
        radius: prototype radius d [m].
        path_length: L, steps per movement.
        p_home: probability of a home return.
        cutoff: c [radii]: the map's sums leave out prototypes below exp(-c^2) of the nearest
            one's activation (faster with hundreds of prototypes); None: all (the paper's), 4 for
            a workspace region.
        targets: target set X* (N, n) [m], where the goals come from; default the robot's, or
            for a target without one the ``"auto"`` grid (:meth:`KinematicTarget.auto_targets`).
            Generators that need no goal set (``"directions"``, ``"motor"``) use it only as the
            default evaluation set. ``"workspace:fraction=0.5"``: a region of the arm's own reach
            (:mod:`gb_pin.robot.workspace`), its test points the default ``eval_targets`` and a
            curriculum from home outwards the default goals. Targets other than the robot's scale
            the radius, sigma and direction step not given (:mod:`gb_pin.runs.scaling`).
        eval_targets: the test set where E^X (Eq. 9) and D^home (Eq. 10) are measured, (M, n)
            [m]; default ``targets`` (the paper: the goal set is the test set).
        schedule: movement counts at which to record E^X and D^home.
        callback: called with the movement count as the run progresses.
        record: which steps to record (postures, targets, positions) into
            ``result.recording``, e.g. ``Recording(every=1, first=0, last=50)``.
        viewer: an object with ``start(target, targets)`` and ``update(state)``
            (e.g. :class:`gb_pin.viewer.Viewer`), updated every ``observe_every``
            movements while babbling; it throttles itself.
        observe_every: movements between viewer updates (10 keeps the slowdown of learning small).
        checkpoint: write the complete state of the run to this file every
            ``checkpoint_every`` movements and at the end (atomically); continue
            a stopped run with :func:`resume`. Ctrl-C then writes a final
            checkpoint before ``KeyboardInterrupt`` propagates.
        checkpoint_every: movements between checkpoints (default: a tenth of the run).
        goals: who chooses each movement's goal: a
            :class:`~gb_pin.learn.goals.GoalGenerator` or its name, optionally with parameters
            (``"uniform"``, the paper's and the default; ``"uniform:snap=0.05"``; ``"cyclic"``;
            ``"directions"``, no goal set needed; ``"error"``; ``"progress"``; ``"motor"``,
            motor babbling as a baseline): see :mod:`gb_pin.learn.goals` and docs/GOALS.md.
        changes: body changes ``{movement: robot}``: from movement r on the robot's
            kinematics are those of the given robot (same joints and task axes; see
            :mod:`gb_pin.robot.bodies`), one history throughout.
        init: a previous :class:`BabbleResult` to continue learning from: its map, noise,
            random stream (``seed`` is then not used), goal generator and posture carry
            over to this robot (same joints and task axes); movements count from 0 again.
        until_error: stop as soon as E^X on the test set is at most this level [m] (measured
            at the ``schedule``'s counts); ``movements`` is then the most the run may take.
        max_joint_step: no step moves a joint farther than this from the last executed posture
            ([rad] or [m]); the arm learns from what it executed. None: no limit.
        sensor: a :class:`~gb_pin.learn.sensor.Sensor` (noise per axis, missing readings) through
            which the learner observes the hand; None: the robot's own (a plant's), else exact.
            E^X is always measured on the true body.
        reach_window: goal-directed movements over which ``result.history.reach`` (the median
            reach error the robot observed: progress measured without extra movements) is taken.
        obstacles: ``[gb_pin.Table(height), gb_pin.Box(center, half_extents), gb_pin.Sphere(center,
            radius)]`` (world frame [m]): every ask and the straight move to it are checked, and an
            unsafe one is cut short at the last safe posture, then slides (``slide``; the arm learns
            from the posture it executed); ``result.cut_asks`` counts them. The run then steps in
            Python (:mod:`gb_pin.safety`).
        self_collision: check the robot against itself too (its collision matrix, generated once
            and cached).
        collision_geometry: ``"urdf"`` (the URDF's collision shapes) or ``"capsules"``.
        clearance: the margin [m] every checked pair keeps.
        slide: after a cut, each joint's remaining move is added alone where it stays safe (the
            arm slides along what it touched; default); False: it stops at the last safe posture.
            Measured (docs/SAFETY.md): stopping learns more slowly at first but steadily; sliding
            wandered over long runs on the Panda.

    Returns:
        A :class:`BabbleResult`.

    Raises:
        UnknownRobotError: unknown preset name.
        InvalidArgumentError: any other bad argument.
        DivergenceError: the estimate diverged (the last checkpoint stays on disk).
    """
    if isinstance(robot, RunSpec):
        spec = robot
    else:
        spec = RunSpec(
            robot, movements, seed, learning_rate, sigma, sigma_delta, radius, path_length, p_home, cutoff,
            targets, eval_targets, schedule, record, goals, changes, init, until_error, max_joint_step,
            sensor, reach_window, obstacles, self_collision, collision_geometry, clearance, slide,
        )  # fmt: skip
    region = _parted_region(spec, checkpoint)
    if region is not None:  # one learner per part of the region (gb_pin.runs.parted)
        from gb_pin.runs.parted import babble_parted

        if checkpoint is not None:
            raise InvalidArgumentError(
                f"a workspace region in parts (parts={region.parts}) writes no checkpoints: use parts=1"
            )
        return babble_parted(spec, region, callback=callback, viewer=viewer, observe_every=observe_every)
    run = setup.prepare(spec)
    if isinstance(run.target, ExternalRobot):
        raise InvalidArgumentError(
            f"{run.target!r} has no forward model: babble() cannot move it; drive it with "
            "gb_pin.babble_session (ask a posture, execute it, tell the reading)"
        )
    if checkpoint_every is not None:
        check.positive_int("checkpoint_every", checkpoint_every, 1, check.MAX_MOVEMENTS)
    setup.check_hooks(callback=callback, viewer=viewer)
    if checkpoint is not None:
        check_writable(checkpoint, "checkpoint")
    if isinstance(run.target, FunctionTarget) or run.guard is not None:
        from gb_pin.runs.stepped import babble_function

        return _continued(
            babble_function(run, callback, viewer, checkpoint, checkpoint_every, observe_every), spec.init
        )
    from gb_pin.runs.checkpoint import checkpoint_lock

    learner = run.learner
    learner.state_ = setup.start_state(run)
    runner = _Runner(run.target, run.name, run.seed, run.movements, checkpoint, wall_before=0.0)
    observer = _attach(
        viewer, run.target, learner.state_.eval_targets
    )  # the test set; the goal set on the way
    with checkpoint_lock(checkpoint), _deferred_sigint(enabled=checkpoint is not None) as interrupted:
        learner.resume(
            run.movements,
            callback=callback,
            observer=observer,
            observe_every=observe_every,
            checkpoint=runner.write if checkpoint is not None else None,
            checkpoint_every=checkpoint_every,
            should_stop=interrupted,
        )
    return _continued(runner.result(learner, interrupted()), spec.init)


def _parted_region(spec: RunSpec, checkpoint: Any = None) -> Any:
    """The workspace region of ``spec.targets`` if it is learnt in several parts, else None.

    ``parts=auto`` (the default) decides on the robot (:func:`~gb_pin.robot.workspace_parts.auto_parts`);
    a run continuing another (``init``), writing checkpoints, with body changes, a sensor, safety
    checks, a recording or ``until_error``, or of a simulated plant keeps one learner.
    """
    from gb_pin.robot.workspace import AUTO, WorkspaceRegion, is_workspace_spec
    from gb_pin.robot.workspace_parts import auto_parts

    if not is_workspace_spec(spec.targets):
        return None
    region = WorkspaceRegion.parse(str(spec.targets))
    if region.parts == AUTO:
        if (
            spec.init is not None or checkpoint is not None or spec.changes or spec.sensor is not None
            or spec.safe or spec.record is not None or spec.until_error is not None
            or (isinstance(spec.robot, str) and "@" in spec.robot)
        ):  # fmt: skip
            return None
        target = setup.resolve_robot(spec.robot)[0]
        if getattr(target, "sensor", None) is not None or not hasattr(target, "chain"):
            return None
        try:
            region = dataclasses.replace(region, parts=auto_parts(target, region))
        except InvalidArgumentError:  # no forward model: the one-learner path says what is missing
            return None
    return region if region.parts > 1 else None


def _continued(result: BabbleResult, init: Any) -> BabbleResult:
    """``result``, with E_0 of the home estimate carried over from ``init`` when it continued a run.

    A continued run's history starts at the previous estimate, not at q_home: its movement 0 is no
    E_0 (a healthy run would read as "E^X is 69 % of E_0").
    """
    e0 = getattr(init, "initial_error", None)
    if init is None or e0 is None or not math.isfinite(e0):
        return result
    return dataclasses.replace(result, home_error=float(e0))


def resume(
    checkpoint: str | os.PathLike[str],
    robot: KinematicTarget | ChangedBody | None = None,
    *,
    callback: Callable[[int], Any] | None = None,
    checkpoint_every: int | None = None,
    viewer: Any | None = None,
    observe_every: int = 10,
) -> BabbleResult:
    """Continue a run from its checkpoint file; it ends bit-identical to an uninterrupted run.

    A safe run (``obstacles``, ``self_collision``) goes on checked with the obstacles and collision
    settings its checkpoint records (:mod:`gb_pin.safety.record`), stepped as ``babble`` stepped it.

    Args:
        checkpoint: the file written by ``babble(..., checkpoint=...)``; it keeps
            being updated as the run goes on.
        robot: the KinematicTarget, needed only for runs of a custom (non-preset) target.
        callback: called with the movement count as the run progresses.
        checkpoint_every: movements between checkpoints (default: a tenth of the run).
        viewer: as in :func:`babble`.
        observe_every: movements between viewer updates.

    Raises:
        ResultFileError: missing, corrupted or foreign checkpoint, or one written for another robot.
    """
    from gb_pin.runs.checkpoint import checkpoint_lock, read_checkpoint, same_robot

    check_writable(checkpoint, "checkpoint")
    setup.check_hooks(callback=callback, viewer=viewer)
    state, info = read_checkpoint(checkpoint)
    if robot is None and info.robot is None and info.source is not None:
        from gb_pin.runs.checkpoint import checkpoint_robot

        robot = checkpoint_robot(checkpoint, info)  # a URDF / example-robot-data model, rebuilt
    if robot is None:
        if info.robot is None:
            raise InvalidArgumentError(
                f"{os.fspath(checkpoint)}: the run used a custom KinematicTarget "
                f"{info.target_name!r}; pass it as robot= to resume"
            )
        robot = load_robot(info.robot)
    elif not isinstance(robot, KinematicTarget | ChangedBody):
        raise InvalidArgumentError(
            f"robot must be a KinematicTarget, a ChangedBody or None, got {robot!r}; a robot given as a "
            "function or on hardware continues with gb_pin.runs.session.resume_session"
        )
    if state.chain is None:
        raise InvalidArgumentError(
            f"{os.fspath(checkpoint)}: a session of a robot without compiled kinematics; continue it with "
            "gb_pin.runs.session.resume_session(path, robot=...)"
        )
    same_robot(checkpoint, robot, state)
    if checkpoint_every is not None:
        check.positive_int("checkpoint_every", checkpoint_every, 1, check.MAX_MOVEMENTS)
    if info.safety is not None:  # a safe run goes on checked, with the obstacles its checkpoint records
        if viewer is not None:
            raise InvalidArgumentError("a safe run (obstacles, self_collision) resumes without a viewer")
        from gb_pin.runs.stepped import resume_guarded

        return resume_guarded(checkpoint, robot, callback, checkpoint_every)
    learner = GoalBabbling.from_config(info.config)
    learner.state_ = state
    runner = _Runner(robot, info.robot, info.seed, info.movements, checkpoint, wall_before=info.wall_time)
    observer = _attach(viewer, robot, state.eval_targets)
    with checkpoint_lock(checkpoint), _deferred_sigint(enabled=True) as interrupted:
        learner.resume(
            info.movements,
            callback=callback,
            observer=observer,
            observe_every=observe_every,
            checkpoint=runner.write,
            checkpoint_every=checkpoint_every,
            should_stop=interrupted,
        )
    return runner.result(learner, interrupted())


def _attach(viewer: Any | None, target: setup.Target, targets: NDArray[np.float64]) -> Any:
    if viewer is None:
        return None
    viewer.start(target, targets)
    return viewer.update


@contextlib.contextmanager
def _deferred_sigint(enabled: bool) -> Iterator[Callable[[], bool]]:
    """While active, Ctrl-C (SIGINT) only raises a flag that the run polls between chunks."""
    flag = [False]
    if not enabled or threading.current_thread() is not threading.main_thread():
        yield lambda: False
        return

    def handler(signum: int, frame: Any) -> None:
        flag[0] = True

    previous = signal.signal(signal.SIGINT, handler)
    try:
        yield lambda: flag[0]
    finally:
        signal.signal(signal.SIGINT, previous)


class _Runner:
    """Bookkeeping shared by babble() and resume(): wall time, checkpoints, the result."""

    def __init__(
        self,
        target: setup.Target,
        robot: str | None,
        seed: int | None,
        movements: int,
        checkpoint: str | os.PathLike[str] | None,
        wall_before: float,
    ) -> None:
        self.target = target
        self.robot = robot
        self.seed = seed
        self.movements = movements
        self.path = checkpoint
        self.wall_before = wall_before
        self.start = time.perf_counter()
        self.saved = True  # whether the last checkpoint write succeeded

    def wall(self) -> float:
        return self.wall_before + time.perf_counter() - self.start

    def write(self, state: BabbleState) -> None:
        from gb_pin.runs.checkpoint import CheckpointInfo, write_checkpoint
        from gb_pin.runs.robot_source import describe

        assert self.path is not None
        info = CheckpointInfo(
            robot=self.robot,
            target_name=self.target.name,
            movements=self.movements,
            seed=self.seed,
            config=state.config,
            wall_time=self.wall(),
            source=describe(self.target, self.robot),  # how to rebuild a robot that is no preset
        )
        try:
            write_checkpoint(self.path, state, info)
            self.saved = True
            return
        except OSError as exc:  # e.g. the disk filled up: keep the run's state somewhere
            first = exc
        import warnings

        from gb_pin._files import fallback_paths
        from gb_pin.exceptions import GbPinWarning

        for where in fallback_paths(self.path):
            try:
                write_checkpoint(where, state, info)
            except OSError:
                continue
            warnings.warn(
                f"cannot write the checkpoint {os.fspath(self.path)!r} ({first}); "
                f"writing it to {where!r} from now on",
                GbPinWarning,
                stacklevel=2,
            )
            self.path, self.saved = where, True
            return
        self.saved = False
        warnings.warn(
            f"cannot write the checkpoint {os.fspath(self.path)!r} ({first}) nor anywhere else; the run "
            "goes on, and tries again at the next checkpoint",
            GbPinWarning,
            stacklevel=2,
        )

    def result(self, learner: GoalBabbling, interrupted: bool) -> BabbleResult:
        if interrupted:
            where = os.fspath(self.path or "")
            saved = (
                f"checkpoint written to {where}"
                if self.saved
                else f"no checkpoint could be written ({where})"
            )
            raise KeyboardInterrupt(f"interrupted at movement {learner.movements_}; {saved}")
        state = learner.state_
        return BabbleResult(
            target=self.target,  # type: ignore[arg-type]
            targets=state.eval_targets,
            history=learner.history_,
            model=learner.model_,
            config=learner.config_,
            seed=self.seed,
            robot=self.robot,
            movements=learner.movements_,
            steps=learner.steps_,
            wall_time=self.wall(),
            recording=learner.recording_,
            state=state,
            **state_fields(state),
        )
