"""What ``babble()`` and ``babble_session()`` share: the robot, the learner, the targets, the start state.

A robot is a preset name, a :class:`~gb_pin.robot.target.KinematicTarget` or a
:class:`~gb_pin.robot.function.FunctionTarget`. A run may continue a previous one
(``init=``): its map, exploration noise, random generator, goal generator and posture carry
over, the movement count and the history start afresh.
"""

from __future__ import annotations

import copy
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn import layout
from gb_pin.learn.config import BY_NAME, NAMES
from gb_pin.learn.history import Recording
from gb_pin.learn.learner import GoalBabbling
from gb_pin.learn.llm import LocalLinearMap
from gb_pin.learn.state import BabbleState
from gb_pin.robot.bodies import ChangedBody
from gb_pin.robot.external import ExternalRobot
from gb_pin.robot.function import FunctionTarget
from gb_pin.robot.presets import get_preset, load_robot
from gb_pin.robot.spec import is_robot_spec, load_robot_spec
from gb_pin.robot.target import KinematicTarget
from gb_pin.runs.scaling import scaled_spec
from gb_pin.runs.spec import RunSpec
from gb_pin.sim.spec import is_plant_spec

Target = KinematicTarget | FunctionTarget | ChangedBody | ExternalRobot


def resolve_robot(robot: Any) -> tuple[Target, str | None, dict[str, Any]]:
    """(target, preset name or None, the preset's learner defaults); ``MODULE:NAME`` loads a robot.

    ``ROBOT@mujoco[:options]`` builds a simulated plant (:mod:`gb_pin.sim`), with ROBOT's defaults.

    Raises:
        UnknownRobotError: unknown preset name.
        InvalidArgumentError: not a robot.
    """
    if isinstance(robot, KinematicTarget | FunctionTarget | ChangedBody | ExternalRobot):
        preset = getattr(robot, "preset", None)  # a plant of a preset learns with the preset's defaults
        if isinstance(preset, str):
            return robot, None, dict(get_preset(preset)[0].learner)
        # An onboarded robot (or a plant of one) brings the radius and sigma it measured.
        model = robot if isinstance(robot, KinematicTarget) else getattr(robot, "target", None)
        return robot, None, dict(model.learner_defaults) if isinstance(model, KinematicTarget) else {}
    if is_plant_spec(robot):  # "so101@mujoco:kp=10": a simulated plant (gb_pin.sim)
        from gb_pin.sim.plant import MujocoPlant

        return resolve_robot(MujocoPlant.from_spec(robot))
    if isinstance(robot, str) and is_robot_spec(robot):
        return resolve_robot(load_robot_spec(robot))[0], None, {}
    if isinstance(robot, str):
        preset, _ = get_preset(robot)
        return load_robot(robot), robot, dict(preset.learner)
    raise InvalidArgumentError(
        f"robot must be a preset name, a KinematicTarget, a ChangedBody or a FunctionTarget, got {robot!r}"
    )


def check_hooks(callback: Any = None, viewer: Any = None, record: Any = None) -> None:
    """Refuse, before any work, hooks of the wrong type.

    A callback must be callable, a viewer have ``start`` and ``update``, and ``record`` be a
    :class:`~gb_pin.learn.history.Recording`.

    Raises:
        InvalidArgumentError: naming the argument and what is valid.
    """
    if callback is not None and not callable(callback):
        raise InvalidArgumentError(
            f"callback must be callable (called with the movement count), got {callback!r}"
        )
    if viewer is not None and not (
        callable(getattr(viewer, "start", None)) and callable(getattr(viewer, "update", None))
    ):
        raise InvalidArgumentError(
            f"viewer must have start(target, targets) and update(state) methods (e.g. gb_pin.viewer.Viewer), "
            f"got {viewer!r}"
        )
    if record is not None and not isinstance(record, Recording):
        raise InvalidArgumentError(
            "record must be a gb_pin.Recording (e.g. Recording(every=1, first=0, last=50)) or None, "
            f"got {record!r}"
        )


def make_learner(defaults: dict[str, Any], given: dict[str, Any]) -> GoalBabbling:
    """The learner: values given, else the preset's, else the table's defaults (gb_pin.learn.config)."""
    if given.get("sigma") is not None and given["sigma"] == 0:
        import warnings

        from gb_pin.exceptions import GbPinWarning

        warnings.warn(
            "sigma=0 means no exploration: goal babbling learns nothing new (the map stays near home)",
            GbPinWarning,
            stacklevel=3,
        )
    params: dict[str, Any] = {}
    for name in NAMES:
        value = given.get(name)
        params[name] = value if value is not None else defaults.get(name, BY_NAME[name].default)
    return GoalBabbling(**params)


def target_set(target: Target, targets: ArrayLike | None) -> NDArray[np.float64]:
    """The targets given (checked), else the robot's, else its ``"auto"`` grid."""
    if targets is None:
        return target.targets if target.targets is not None else target.auto_targets()
    return target.check_targets(targets)


class Prepared(NamedTuple):
    """A run's description resolved: the robot, its goal set, the learner and the random generator."""

    spec: RunSpec
    target: Target
    name: str | None
    movements: int
    X: NDArray[np.float64]
    learner: GoalBabbling
    rng: np.random.Generator
    seed: int | None
    guard: Any = None  # a gb_pin.safety.CollisionChecker when the spec asks for safe babbling


def start_state(
    run: Prepared, *, schedule: ArrayLike | None = None, home_position: ArrayLike | None = None
) -> BabbleState:
    """The state at movement 0: fresh, or continuing ``init`` (a result with a final state).

    Args:
        run: the prepared run.
        schedule: the evaluation schedule, if not the spec's (sessions evaluating by movements).
        home_position: f(q_home) as observed (a robot without a model).
    """
    spec = run.spec
    config = run.learner._resolve(run.target.n_joints)
    kinematics: Any = run.target  # a Kinematics, or a forward model without a compiled chain
    st = BabbleState.start(
        kinematics, run.X, run.movements, config, seed=run.rng, eval_targets=spec.eval_targets,
        schedule=spec.schedule if schedule is None else schedule, record=spec.record, goals=spec.goals,
        changes=spec.changes, until_error=spec.until_error, max_joint_step=spec.max_joint_step,
        sensor=spec.sensor, reach_window=spec.reach_window, home_position=home_position,
    )  # fmt: skip
    if spec.init is not None:
        continue_from(st, spec.init)
    return st


def continue_from(st: BabbleState, init: Any) -> None:
    """Carry the final state of a previous run (map, noise, random stream, goals, posture) into ``st``.

    Raises:
        InvalidArgumentError: ``init`` carries no final state, or one of other joint or task dimensions.
    """
    prev = getattr(init, "state", init)
    if not isinstance(prev, BabbleState):
        raise InvalidArgumentError(
            f"init must be a BabbleResult of this session (results loaded from files of gb_pin 0.1 "
            f"carry no final state) or a BabbleState, got {init!r}"
        )
    m, n = st.home.shape[0], st.targets.shape[1]
    if (prev.home.shape[0], prev.targets.shape[1]) != (m, n):
        raise InvalidArgumentError(
            f"init has {prev.home.shape[0]} joints and {prev.targets.shape[1]} task axes; "
            f"this run has {m} and {n}"
        )
    if prev.istate[layout.KIND] != layout.NONE:
        raise InvalidArgumentError("init must be stopped between movements")
    prev.llm.set_count(int(prev.istate[layout.PROTOTYPES]))
    st.llm = LocalLinearMap.from_arrays(
        prev.llm.to_arrays(),
        st.config.radius,
        st.config.learning_rate,
        capacity=max(2 * prev.llm.n_prototypes_, 256),
        cutoff=st.config.cutoff,
    )
    st.A[:] = prev.A
    st.b[:] = prev.b
    st.rng = copy.deepcopy(prev.rng)
    for key in st.VECTORS:
        st.vectors[key][:] = prev.vectors[key]
    st.istate[layout.PROTOTYPES] = prev.istate[layout.PROTOTYPES]
    st.istate[layout.LAST_KIND] = prev.istate[layout.LAST_KIND]
    old = prev.goal_state
    if old.kind == st.goal_state.kind and np.array_equal(old.targets, st.targets):
        st.goal_state = st.goal_state._replace(istate=old.istate.copy(), fstate=old.fstate.copy())


def generator(seed: Any, init: Any | None = None) -> tuple[np.random.Generator, int | None]:
    """(the generator, the int seed or None); with ``init``, the seed recorded is init's.

    Raises:
        InvalidArgumentError: a bad seed, or an ``init`` without a final state.
    """
    rng = check.generator(seed)
    if init is not None:
        if not isinstance(getattr(init, "state", init), BabbleState):
            raise InvalidArgumentError(
                f"init must be a BabbleResult of this session (results loaded from files of gb_pin 0.1 "
                f"carry no final state) or a BabbleState, got {init!r}"
            )
        return rng, getattr(init, "seed", None)
    return rng, None if isinstance(seed, np.random.Generator) else int(seed)


def prepare(spec: RunSpec) -> Prepared:
    """What ``babble()`` and ``babble_session()`` check and build first, in this order.

    Raises:
        UnknownRobotError: unknown preset name.
        InvalidArgumentError: a bad robot, movement count, target set, hyperparameter or seed.
    """
    target, name, defaults = resolve_robot(spec.robot)
    spec = scaled_spec(
        spec, target, defaults
    )  # a workspace region as points; radius and sigma follow the goals
    X = target_set(target, spec.targets)  # checked; warns about targets beyond reach
    learner = make_learner(defaults, spec.hyperparameters())
    rng, int_seed = generator(spec.seed, spec.init)
    if not spec.safe and name is not None and "@" not in name and ":" not in name:
        preset_safety = get_preset(name)[0].safety  # a preset's [safety] table, unless the run gives its own
        if preset_safety:
            spec = spec.replace(**preset_safety)
    guard = safety_guard(spec, target, X) if spec.safe else None
    return Prepared(spec, target, name, int(spec.movements), X, learner, rng, int_seed, guard)


def safety_guard(spec: RunSpec, target: Any, X: NDArray[np.float64]) -> Any:
    """The collision checker of a safe run, its setup checked (home clear, goals outside obstacles).

    A simulated plant is checked on the kinematic robot it was built from.

    Raises:
        UnsafeSetupError: a robot without a model, an obstacle at home, goals inside an obstacle, ...
    """
    checker = guard_for(
        target, spec.obstacles or (), spec.self_collision, spec.collision_geometry, spec.clearance, spec.slide
    )
    checker.check_setup(X)
    return checker


def guard_for(
    target: Any, obstacles: Any, self_collision: bool, geometry: str, clearance: float, slide: bool = True
) -> Any:
    """The collision checker of these settings on ``target`` (a simulated plant's own when it checks them).

    Raises:
        UnsafeSetupError: a robot without a Pinocchio model (or a collision setup that cannot work).
    """
    from gb_pin.exceptions import UnsafeSetupError
    from gb_pin.safety.checker import CollisionChecker

    kinematic = getattr(target, "target", target)
    if getattr(kinematic, "model", None) is None or not hasattr(kinematic, "to_pinocchio"):
        raise UnsafeSetupError(
            "safe babbling (obstacles, self_collision) needs a robot with a Pinocchio model, "
            f"got {target!r:.100}"
        )
    checker = getattr(target, "collision", None)  # a simulated plant's, with contacts on
    if (
        isinstance(checker, CollisionChecker)
        and checker.same_setup(obstacles, self_collision, geometry, clearance)
        and checker.slide == slide
    ):
        return checker
    return CollisionChecker(
        kinematic, obstacles, self_collision=self_collision, geometry=geometry, clearance=clearance,
        slide=slide,
    )  # fmt: skip


def recorded_guard(robot: Any, settings: dict[str, Any] | None) -> Any:
    """The collision checker of a checkpoint's recorded ``settings`` (:mod:`gb_pin.safety.record`), or None.

    On ``robot`` (a plant's own checker when it checks the same); its counts continue from the
    recorded ones; the setup is checked again (home clear).

    Raises:
        UnsafeSetupError: as :func:`safety_guard`.
    """
    if settings is None:
        return None
    checker = guard_for(
        robot, settings["obstacles"], settings["self_collision"], settings["collision_geometry"],
        settings["clearance"], settings.get("slide", True),
    )  # fmt: skip
    checker.check_setup()
    checker.asks = int(settings["checked_asks"])
    checker.cuts = int(settings["cut_asks"])
    return checker
