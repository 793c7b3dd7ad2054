"""RunSpec: one description of a goal-babbling run, taken by ``babble()``, ``babble_session()`` and trials.

Everything that decides what a run learns is here, checked once: the robot, the movements and
seed, the learner's hyperparameters (the paper's, named in :data:`gb_pin.learn.config.NAMES`),
where goals and E^X come from, body changes, the joint-step limit and the sensor. How a run is
watched or saved (callbacks, viewers, checkpoints) is not part of it.

>>> spec = RunSpec("so101", movements=3000, seed=1, max_joint_step=0.05)
>>> result = gb_pin.babble(spec)                     # doctest: +SKIP
>>> session = gb_pin.babble_session(spec)            # doctest: +SKIP
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from gb_pin import _validation as check
from gb_pin._names import suggest
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.config import NAMES, check_values
from gb_pin.learn.goals import GoalGenerator, make_goals
from gb_pin.learn.history import Recording
from gb_pin.learn.sensor import Sensor


@dataclass(frozen=True, eq=False)
class RunSpec:
    """A goal-babbling run: what is learnt, on what, and how.

    Attributes:
        robot: a preset name (``"planar20"``, ``"so101"``), ``"MODULE:NAME"``, a
            :class:`~gb_pin.robot.target.KinematicTarget`, a changed body or plant, a
            :class:`~gb_pin.robot.function.FunctionTarget`, or (sessions only) an
            :class:`~gb_pin.robot.external.ExternalRobot`.
        movements: number of movements (home returns included).
        seed: an int seed or a numpy Generator; same seed, same result.
        learning_rate: eta (None: the preset's, else 0.1).
        sigma: exploration noise per joint (Eq. 8) [rad] (None: Eq. 12).
        sigma_delta: random-walk step of the noise [rad] (None: 0.1 sigma).
        radius: prototype radius d [m] (None: the preset's, else 0.1).
        path_length: L, steps per movement (None: 25).
        p_home: probability of a home return (None: 0.1).
        cutoff: c [radii], the map's truncated sums (None: all prototypes; a workspace region: 4).
        targets: the goal set X* (N, n) [m]; default the robot's, else its "auto" grid; or a
            workspace region, ``"workspace:fraction=0.5"`` (:mod:`gb_pin.robot.workspace`: goals
            and separate test points from the arm's own reach). Targets other than the robot's
            scale the radius, sigma and direction step not given (:mod:`gb_pin.runs.scaling`).
        eval_targets: the test set of E^X and D^home (M, n) [m]; default ``targets``.
        schedule: movement counts at which E^X, D^home and the reach median are recorded.
        record: which steps to record (:class:`~gb_pin.learn.history.Recording`).
        goals: the goal generator or its name (``"uniform"``, ``"directions"``, ...).
        changes: body changes ``{movement: robot}``.
        init: a previous result to continue from.
        until_error: stop once E^X <= this level [m].
        max_joint_step: no step moves a joint farther than this from the last executed posture
            ([rad] or [m]; the arm learns from what it executed); None: no limit.
        sensor: what observes the hand (:class:`~gb_pin.learn.sensor.Sensor`: noise per axis,
            missing readings); None: the robot's own (a plant's), else exact readings.
        reach_window: goal-directed movements over which ``History.reach`` (the median reach error
            the robot observed, the free measure of progress) is taken.
        obstacles: the environment, ``[gb_pin.Table(height), gb_pin.Box(center, half_extents),
            gb_pin.Sphere(center, radius)]`` (world frame [m]); every ask is checked against them
            and cut short before it would come within ``clearance`` (:mod:`gb_pin.safety`).
        self_collision: check every ask against the robot's own shapes too (through its generated
            collision matrix). None/False with no obstacles: no check (the paper's run, compiled).
        collision_geometry: the robot's shapes: ``"urdf"`` (its collision geometry, meshes as convex
            hulls) or ``"capsules"`` (one per link; for robots without collision geometry).
        clearance: the margin [m] every checked pair keeps.
        slide: after a cut, slide joint by joint along what was touched (default); False: stop at
            the last safe posture of the move (docs/SAFETY.md: steadier over long runs on the Panda).
    """

    robot: Any = "planar20"
    movements: int = 1000
    seed: int | np.random.Generator = 0
    learning_rate: float | None = None
    sigma: float | None = None
    sigma_delta: float | None = None
    radius: float | None = None
    path_length: int | None = None
    p_home: float | None = None
    cutoff: float | None = None
    targets: ArrayLike | str | None = None
    eval_targets: ArrayLike | None = None
    schedule: ArrayLike | None = None
    record: Recording | None = None
    goals: str | GoalGenerator | None = None
    changes: dict[int, Any] | None = None
    init: Any = None
    until_error: float | None = None
    max_joint_step: float | None = None
    sensor: Sensor | None = None
    reach_window: int = 50
    obstacles: Any = None
    self_collision: bool = False
    collision_geometry: str = "urdf"
    clearance: float = 0.01
    slide: bool = True

    def __post_init__(self) -> None:
        check.movements("movements", self.movements, minimum=1)
        check.generator(self.seed)
        check_values(self.hyperparameters())
        if self.record is not None and not isinstance(self.record, Recording):
            raise InvalidArgumentError(
                "record must be a gb_pin.Recording (e.g. Recording(every=1, first=0, last=50)) or None, "
                f"got {self.record!r}"
            )
        if self.goals is not None:
            make_goals(self.goals)  # an unknown name or parameter is refused now
        if isinstance(self.targets, str):
            from gb_pin.robot.workspace import WorkspaceRegion, is_workspace_spec

            if not is_workspace_spec(self.targets):
                raise InvalidArgumentError(
                    "targets must be an (N, n) array of points [m] or a workspace region "
                    f"('workspace:fraction=0.5'), got {self.targets!r}"
                )
            WorkspaceRegion.parse(self.targets)  # a malformed region is refused now
        if self.changes is not None:
            if not isinstance(self.changes, dict):
                raise InvalidArgumentError(
                    f"changes must be a dict {{movement: robot}}, got {self.changes!r}"
                )
            for at in self.changes:
                check.movements("changes movement", at, minimum=1)
        if self.until_error is not None:
            check.positive_float("until_error", self.until_error)
        if self.max_joint_step is not None and not (
            check._is_real(self.max_joint_step)
            and check._float(self.max_joint_step) > 0
            and math.isfinite(check._float(self.max_joint_step))
        ):
            raise InvalidArgumentError(
                "max_joint_step must be > 0 ([rad] or [m] per step; None: no limit), "
                f"got {self.max_joint_step!r}"
            )
        if self.sensor is not None and not isinstance(self.sensor, Sensor):
            raise InvalidArgumentError(f"sensor must be a gb_pin Sensor or None, got {self.sensor!r}")
        check.positive_int("reach_window", self.reach_window, 1, 10**6)
        if self.obstacles is not None:
            from gb_pin.safety.obstacles import check_obstacles

            object.__setattr__(self, "obstacles", check_obstacles(self.obstacles) or None)
        if not isinstance(self.self_collision, bool):
            raise InvalidArgumentError(f"self_collision must be True or False, got {self.self_collision!r}")
        if self.collision_geometry not in ("urdf", "capsules"):
            raise InvalidArgumentError(
                f"collision_geometry must be 'urdf' or 'capsules', got {self.collision_geometry!r}"
            )
        check.positive_float("clearance", self.clearance)
        if not isinstance(self.slide, bool):
            raise InvalidArgumentError(f"slide must be True or False, got {self.slide!r}")

    @property
    def safe(self) -> bool:
        """Whether asks are checked (obstacles given or self-collision asked)."""
        return self.obstacles is not None or self.self_collision

    @classmethod
    def of(cls, robot: Any = "planar20", movements: Any = 1000, seed: Any = 0, **options: Any) -> RunSpec:
        """A spec from keyword arguments, unknown names refused with the closest valid ones.

        Raises:
            InvalidArgumentError: an unknown option or a bad value.
        """
        names = [f.name for f in dataclasses.fields(cls)]
        for key in options:
            if key not in names:
                raise InvalidArgumentError(f"unknown run option {key!r}; {suggest(key, names)}")
        return cls(robot, movements, seed, **options)

    def hyperparameters(self) -> dict[str, Any]:
        """The learner's hyperparameters given (None: default), by the table's names."""
        return {name: getattr(self, name) for name in NAMES}

    def trial_arguments(self) -> tuple[Any, int, int, dict[str, Any]]:
        """(robot, movements, seed, babble arguments) for trials (:func:`gb_pin.run_trials`).

        Trials travel to worker processes and journals as plain values: the robot by name (or a
        model that records how to rebuild it: :func:`gb_pin.run_trials` checks), the goal generator
        by its name, point sets as lists.

        Raises:
            InvalidArgumentError: a field trials cannot carry (a robot object, a Generator seed,
                a recording, body changes, ...), named.
        """
        plain = {"robot", "movements", "seed", *NAMES, "goals", "targets", "eval_targets",
                 "obstacles", "self_collision", "collision_geometry", "clearance", "slide"}  # fmt: skip
        others = [f.name for f in dataclasses.fields(self)
                  if f.name not in plain and not _is_default(getattr(self, f.name), f.default)]  # fmt: skip
        if isinstance(self.seed, np.random.Generator):
            others.append("seed (a Generator: trial i uses seed + i)")
        if self.goals is not None and not isinstance(self.goals, str):
            others.append("goals (an object: trials take a generator's name)")
        if others:
            raise InvalidArgumentError(
                f"trials cannot carry these fields of the RunSpec: {', '.join(others)}"
            )
        args: dict[str, Any] = {k: v for k, v in self.hyperparameters().items() if v is not None}
        if self.goals is not None:
            args["goals"] = self.goals
        for key in ("targets", "eval_targets"):
            value = getattr(self, key)
            if isinstance(value, str):
                args[key] = value  # a workspace region travels as its spec
            elif value is not None:
                args[key] = np.asarray(value, dtype=float).tolist()
        if self.safe:
            from gb_pin.safety.obstacles import plain as plain_obstacle

            args["obstacles"] = [plain_obstacle(o) for o in self.obstacles or ()]
            args.update(self_collision=self.self_collision, collision_geometry=self.collision_geometry,
                        clearance=self.clearance)  # fmt: skip
            if not self.slide:
                args["slide"] = False  # (only when off: earlier runs' trials keep their arguments)
        return self.robot, int(self.movements), int(self.seed), args  # type: ignore[arg-type]

    def replace(self, **changes: Any) -> RunSpec:
        """A copy with some fields changed (checked again)."""
        return dataclasses.replace(self, **changes)

    def __repr__(self) -> str:
        always = ("robot", "movements", "seed")
        shown = [
            f"{f.name}={_short(getattr(self, f.name))}"
            for f in dataclasses.fields(self)
            if f.name in always or not _is_default(getattr(self, f.name), f.default)
        ]
        return f"RunSpec({', '.join(shown)})"


def _is_default(value: Any, default: Any) -> bool:
    plain = (int, float, str, bool)
    return value is default or (isinstance(value, plain) and isinstance(default, plain) and value == default)


def _short(value: Any) -> str:
    if isinstance(value, np.ndarray) or (isinstance(value, list) and len(value) > 4):
        return f"<{np.shape(value)} array>"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
