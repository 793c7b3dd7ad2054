"""MujocoPlant: a robot gb_pin loads, simulated by MuJoCo: position servos, gravity, settling.

>>> plant = MujocoPlant("so101", kp=10.0, settle=0.2, gravity=True, seed=0)   # doctest: +SKIP
>>> result = gb_pin.babble(plant, movements=3000)                              # doctest: +SKIP

A kinematic chain, even a mis-calibrated one, answers every posture at once and exactly. A real
arm has dynamics: each servo holds its joint short of the command by the gravity torque over its
gain (a posture-dependent sag), and takes time to get there. The plant is such an arm
(:mod:`gb_pin.sim.mjcf`: the learner's own chain and Pinocchio's inertias as a MuJoCo model,
:mod:`gb_pin.sim.servos`), read through an optional :class:`~gb_pin.learn.sensor.Sensor`.

It is a robot wherever a :class:`~gb_pin.robot.function.FunctionTarget` is: ``babble(plant)``
runs it step by step through the ask/tell stepping, ``babble_session(plant)`` sessions take its
readings, ``"so101@mujoco:kp=10"`` names it for trials and the command line (:mod:`gb_pin.sim.spec`).

- :meth:`forward` is one ask: the servos are commanded to q and the simulation runs from where
  the arm is now until the settling rule (:mod:`gb_pin.sim.settling`) says to read; the task
  vector is read at the simulated joint positions (through the learner's task map: the same
  frame, axes and components), then through the sensor (None: the reading was lost). The plant
  keeps its state between asks, as a real arm does: with a short settling the arm is still on
  its way from the last posture when it is read.
- :meth:`true_forward` is the body without lag or noise: the resting posture under the command
  (:func:`~gb_pin.sim.equilibrium.static_posture`), pure (it does not move the arm). E^X and the
  reach errors of docs/SIMULATION.md are measured with it.

Determinism: the same plant settings, seed and sequence of asks give the same readings, bit for
bit (MuJoCo is deterministic on one machine and build). Sessions save the plant's state in their
checkpoints (:mod:`gb_pin.sim.snapshot`), so a resumed session continues bit-identical.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.body.chain import body_forward
from gb_pin.learn.sensor import Sensor, observe_into
from gb_pin.robot.function import FunctionTarget
from gb_pin.sim import health, snapshot
from gb_pin.sim.dependency import require_mujoco
from gb_pin.sim.equilibrium import static_posture
from gb_pin.sim.mjcf import mjcf
from gb_pin.sim.servos import Servos, short

if TYPE_CHECKING:
    from gb_pin.sim.camera import PlantCamera
from gb_pin.sim.contacts import counted, named_pairs
from gb_pin.sim.settling import Settling, ramp
from gb_pin.sim.spec import spec_of, split_spec


class MujocoPlant(FunctionTarget):
    """A robot simulated by MuJoCo: position servos per moved joint, gravity, a settling rule, a sensor.

    Args:
        robot: a preset name (``"so101"``), a :class:`~gb_pin.robot.target.KinematicTarget`
            (from a URDF or example-robot-data), or ``"MODULE:NAME"`` naming one.
        kp: servo position gain [N m/rad] (one number, or one per joint).
        damping: servo damping kv [N m s/rad]; None: 0.05 kp.
        force_limit: largest servo torque [N m]; None: unlimited.
        armature: rotor inertia added to each joint [kg m^2] (stability of light links).
        gravity: gravity on (the robot model's, -9.81 m/s^2 along z) or off.
        settle: longest hold of an ask [s] (default 0.5), ended earlier once the arm is at rest.
        tolerance: joint speed of "at rest" [rad/s] (default 0.01).
        period: instead of settling: hold each ask exactly this long [s] (a fixed control period).
        timestep: MuJoCo's integration step [s].
        noise: the sensor's noise per task axis [m] (one number or one per axis).
        loss: probability that a reading is lost (:meth:`forward` returns None).
        seed: the sensor's seed (the physics draws nothing).
        targets: the goal set (N, n) [m]; default the robot's (its preset's), else its "auto" grid.
        name: a label; default e.g. ``"so101 in MuJoCo (kp 10)"``.
        camera: render the arm (docs/CAMERA.md): a preset (``"side"``, ``"front"``: 50 cm from the
            goal box) or a :class:`~gb_pin.sim.scene.CameraPose`; None: no rendering.
        marker: the ArUco plate on the hand (:class:`~gb_pin.sim.scene.Marker`; default id 7 of
            DICT_4X4_50, 25 mm, 3 cm from the task frame towards the camera).
        meshes: draw the URDF's visual meshes (decimated), else capsules.
        pixel_noise: the camera's noise [grey levels of 255] (3: a webcam's).
        obstacles, self_collision, collision_geometry, clearance: contacts on (:mod:`gb_pin.safety`):
            the robot's collision shapes and the obstacles as MuJoCo geoms, contacts for the pairs
            the checker checks (``self_collision``: the collision matrix's), counted in
            :attr:`contacts`. The plant's ``collision`` is that checker (``clearance`` is its margin;
            MuJoCo's contacts have none). Default: no geometry, contacts off.
        speed: the servo targets travel each ask's joint-space segment at this speed [rad/s], as
            checked (:func:`gb_pin.sim.settling.ramp`; docs/SAFETY.md); None: they jump to the ask.

    Attributes:
        target: the kinematic robot it was built from (its URDF kinematics: exact IK runs on it).
        servos, settling: the servos and the settling rule (:class:`~gb_pin.sim.servos.Servos`,
            :class:`~gb_pin.sim.settling.Settling`).
        tracker: the :class:`~gb_pin.learn.sensor.Sensor` that reads the hand (named apart from a
            kinematic plant's ``sensor``, which the compiled loop applies itself; this one is
            applied by :meth:`forward`).
        gravity: whether gravity is on.
        text: the MJCF model text; ``mj_model`` and ``mj_data``: MuJoCo's model and the arm's state.
        asks, steps: asks answered and MuJoCo steps taken so far.
        preset: the preset's name when the robot was given by it (``babble`` then takes the preset's
            learner settings, as for a kinematic plant).
        spec: the string that rebuilds this plant (``"so101@mujoco:kp=10,..."``), None for a
            robot given as an object.

    Raises:
        SimulationError: MuJoCo is not installed (the message says how to install it).
        UnknownRobotError: an unknown preset.
        InvalidArgumentError: a robot without a Pinocchio model, or a bad setting.
    """

    def __init__(
        self,
        robot: Any = "so101",
        *,
        kp: float | ArrayLike = 10.0,
        damping: float | ArrayLike | None = None,
        force_limit: float | ArrayLike | None = None,
        armature: float | ArrayLike = 0.01,
        gravity: bool = True,
        settle: float | None = None,
        tolerance: float | None = None,
        period: float | None = None,
        timestep: float = 0.002,
        noise: float | ArrayLike = 0.0,
        loss: float = 0.0,
        seed: int = 0,
        targets: ArrayLike | None = None,
        name: str | None = None,
        camera: Any = None,
        marker: Any = None,
        meshes: bool = True,
        pixel_noise: float = 3.0,
        obstacles: Any = None,
        self_collision: bool = False,
        collision_geometry: str = "urdf",
        clearance: float = 0.01,
        speed: float | None = None,
    ) -> None:
        mujoco = require_mujoco()
        self._mj = mujoco
        self.target, robot_name = _kinematic_robot(robot)
        self.preset: str | None = robot_name if robot_name is not None and ":" not in robot_name else None
        given = {
            "kp": kp, "damping": damping, "force_limit": force_limit, "armature": armature,
            "gravity": gravity, "settle": settle, "tolerance": tolerance, "period": period,
            "timestep": timestep, "noise": noise, "loss": loss, "seed": seed, "speed": speed,
        }  # fmt: skip
        m = self.target.n_joints
        self.servos = Servos.of(m, kp, damping, force_limit, armature)
        self.settling = Settling.of(settle, tolerance, period)
        if not isinstance(gravity, bool | np.bool_):
            raise InvalidArgumentError(f"gravity must be True or False, got {gravity!r}")
        self.gravity = bool(gravity)
        self.timestep = check.positive_float("timestep", timestep)
        if not health.MIN_TIMESTEP <= self.timestep <= 0.05:
            raise InvalidArgumentError(
                f"timestep must be in [{health.MIN_TIMESTEP:g}, 0.05] s (MuJoCo's default is 0.002), "
                f"got {timestep!r}"
            )
        health.hold_steps("period" if self.settling.tolerance is None else "settle", self.settling.time,
                          self.timestep)  # fmt: skip
        self.seed = check.positive_int("seed", seed, 0, 2**63 - 1)
        self.speed = None if speed is None else check.positive_float("speed", speed)
        self.tracker = Sensor(noise, loss, np.random.default_rng(self.seed))
        self.tracker.std(self.target.n_task)  # a per-axis noise of the wrong length is refused now
        self.collision: Any = None
        if obstacles is not None or self_collision:
            from gb_pin.safety.checker import CollisionChecker

            self.collision = CollisionChecker(
                self.target, obstacles or (), self_collision=self_collision, geometry=collision_geometry,
                clearance=clearance,
            )  # fmt: skip
        self._contacts: list[Any] | None = None if self.collision is None else [0, {}]
        self.text = mjcf(self.target, self.servos, gravity=self.gravity, timestep=self.timestep,
                         name=self.target.name, collision=self.collision)  # fmt: skip
        self.mj_model = mujoco.MjModel.from_xml_string(self.text)
        self.mj_data = mujoco.MjData(self.mj_model)
        self._scratch = mujoco.MjData(self.mj_model)  # for true_forward: the arm's own state is untouched
        self._dofs = np.array(
            [self.mj_model.jnt_dofadr[self.mj_model.joint(j).id] for j in self.target.joints], dtype=np.int64
        )
        self._body = self.target.chain.kernel()
        self._x = np.empty(self.target.n_task)
        self._state_kind = mujoco.mjtState.mjSTATE_INTEGRATION
        ramp = () if self.speed is None else (f"speed={self.speed!r}",)  # (a jump: the digest as before)
        self._settings = snapshot.digest(self.text, repr(self.settling), repr(self.tracker), *ramp)
        label = name or f"{self.target.name} in MuJoCo (kp {short(self.servos.kp)})"
        super().__init__(
            self.true_forward, self.target.home, lower=self.target.lower, upper=self.target.upper,
            targets=self.target.targets if targets is None else targets, name=label,
        )  # fmt: skip
        self.axes = getattr(self.target, "axes", None)
        self.spec = spec_of(robot_name, given)  # (after every check: the values are valid)
        self.camera: PlantCamera | None = None
        if camera is not None:
            self._add_camera(camera, marker, meshes, pixel_noise)
            if self.spec is not None:
                self.spec = None  # (a rendering plant is not named by a string yet)
        self.reset()

    def _add_camera(self, camera: Any, marker: Any, meshes: bool, pixel_noise: float) -> None:
        """Rebuild the model with the scene (drawn only: the physics is unchanged) and a camera on it."""
        from gb_pin.sim.camera import PlantCamera
        from gb_pin.sim.scene import CameraPose, Marker, build_scene, preset_pose

        pose = preset_pose(camera, self.target) if isinstance(camera, str) else camera
        if not isinstance(pose, CameraPose):
            raise InvalidArgumentError(f"camera must be a preset name or a CameraPose, got {camera!r:.80}")
        marker = Marker() if marker is None else marker
        if not isinstance(marker, Marker):
            raise InvalidArgumentError(f"marker must be a gb_pin.sim.scene.Marker, got {marker!r:.80}")
        noise = check.nonnegative_float("pixel_noise", pixel_noise)
        chain = self.target.chain
        if chain.frame_parent < 0 or self.target.n_task != 3:
            raise InvalidArgumentError("a camera watches a hand on a moved link with a 3-D position task")
        body = int(chain.q_index[chain.frame_parent])
        rest = self.posture_at(self.home)
        self._scratch.qpos[self._dofs] = rest
        self._mj.mj_kinematics(self.mj_model, self._scratch)
        link = self._scratch.body(f"link_{body}")
        R_home = np.array(link.xmat).reshape(3, 3)
        p_home = np.array(self._scratch.site("frame").xpos)
        scene = build_scene(
            self.target, pose, marker, (body, chain.frame_translation, R_home, p_home), meshes
        )
        self.text = mjcf(self.target, self.servos, gravity=self.gravity, timestep=self.timestep,
                         name=self.target.name, scene=scene, collision=self.collision)  # fmt: skip
        self.mj_model = self._mj.MjModel.from_xml_string(self.text, scene.assets)
        self.mj_data = self._mj.MjData(self.mj_model)
        self._scratch = self._mj.MjData(self.mj_model)
        self._settings = snapshot.digest(self.text, repr(self.settling), repr(self.tracker), repr(noise))
        self.scene = scene
        self._marker_body = f"link_{body}"
        self.camera = PlantCamera(self._mj, self.mj_model, scene, noise, self.seed)

    @classmethod
    def from_spec(cls, spec: str) -> MujocoPlant:
        """The plant a string names: ``"so101@mujoco:kp=10,settle=0.2"`` (see :mod:`gb_pin.sim.spec`).

        Raises:
            InvalidArgumentError: a malformed string or a bad option.
            UnknownRobotError: an unknown preset.
            SimulationError: MuJoCo is not installed.
        """
        robot, options = split_spec(spec)
        return cls(robot, **options)

    # -- the arm ---------------------------------------------------------------------------
    def reset(self) -> None:
        """Back to rest at home (the resting posture under the home command), the sensor re-seeded."""
        mj = self._mj
        mj.mj_resetData(self.mj_model, self.mj_data)
        self.mj_data.qpos[self._dofs] = self.posture_at(self.home)
        self.mj_data.ctrl[:] = self.home
        mj.mj_forward(self.mj_model, self.mj_data)
        self._readings = self.tracker.start(self.target.n_task)
        self.asks = 0
        self.steps = 0
        if self._contacts is not None:
            self._contacts[:] = [0, {}]

    @property
    def contacts(self) -> int:
        """Contacts MuJoCo found so far, summed over the steps (0: nothing ever touched); contacts on only.

        Raises:
            InvalidArgumentError: the plant was built without collision geometry (contacts off).
        """
        return int(counted(self._contacts)[0])

    @property
    def contact_pairs(self) -> dict[tuple[str, str], tuple[int, float]]:
        """Which geoms touched: (geom name, geom name) -> (simulation steps in contact, deepest [m]).

        Raises:
            InvalidArgumentError: the plant was built without collision geometry (contacts off).
        """
        return named_pairs(self._mj, self.mj_model, counted(self._contacts)[1])

    def forward(self, q: ArrayLike) -> NDArray[np.float64] | None:  # type: ignore[override]
        """One ask: command ``q`` (m,), simulate by the settling rule, read the task vector (n,) [m].

        The simulation goes on from the arm's current state. ``q`` is executed as given (the
        session clips it to the limits). (N, m) postures are asked one after the other, giving
        (N, n) readings (NaN rows where a reading was lost).

        Returns:
            The sensor's reading, or None when it was lost.

        Raises:
            InvalidArgumentError: a posture of the wrong shape or not finite.
            SimulationError: the simulation went unstable (:func:`~gb_pin.sim.health.check_state`).
        """
        if np.ndim(q) == 2:
            arr = check.points("q", q, self.n_joints)
            rows = [self.forward(row) for row in arr]
            return np.array([np.full(self.n_task, np.nan) if r is None else r for r in rows])
        self.move(q)
        x = self._task(self.mj_data.qpos[self._dofs])
        if self.tracker.ideal:  # (the compiled sensor's call costs 35 us: skipped when it would do nothing)
            return x
        return x if observe_into(self._readings, x) else None

    def true_forward(self, q: ArrayLike) -> NDArray[np.float64]:
        """Where the hand rests under the command ``q``: (m,) -> (n,), (N, m) -> (N, n) [m].

        No lag, no noise, and the arm is not moved: the true body of the plant.

        Raises:
            InvalidArgumentError: postures of the wrong shape or not finite.
            SimulationError: the arm went unstable, or the postures took more than
                :data:`~gb_pin.sim.health.EVALUATION_STEPS` MuJoCo steps to come to rest.
        """
        single = np.ndim(q) == 1
        Q = check.points("q", q, self.n_joints, allow_single=True)
        budget = health.StepBudget(self._describe())  # one evaluation: all of Q together
        out = np.array([self._task(self.posture_at(c, budget)) for c in Q])
        return out[0] if single else out

    def posture_at(self, q: ArrayLike, budget: health.StepBudget | None = None) -> NDArray[np.float64]:
        """The joint positions (m,) at which the arm rests under the command ``q`` (m,) [rad].

        Raises:
            SimulationError: the arm had to be simulated and went unstable, or took longer than
                ``budget`` (default :data:`~gb_pin.sim.health.EVALUATION_STEPS` MuJoCo steps).
        """
        command = check.vector("q", q, self.n_joints)
        budget = budget or health.StepBudget(self._describe())
        mj, model, scratch = self._mj, self.mj_model, self._scratch
        return static_posture(mj, model, scratch, self._dofs, command, self.servos, budget)

    @property
    def posture(self) -> NDArray[np.float64]:
        """The simulated joint positions now (m,) [rad] (what the servos hold, not what was asked)."""
        return np.array(self.mj_data.qpos[self._dofs])

    @property
    def home_position(self) -> NDArray[np.float64]:
        """Where the hand rests under the home command [m] (:meth:`true_forward`; the arm is not moved)."""
        return self.true_forward(self.home)

    def frame_position(self, q: ArrayLike) -> NDArray[np.float64]:
        """MuJoCo's own kinematics: the task frame's world position (3,) [m] at joint positions ``q``.

        The joints are set, not commanded (infinitely stiff servos); the arm is not moved. Equals
        the learner's chain (:attr:`target`) to rounding: the model conversion's check.
        """
        posture = check.vector("q", q, self.n_joints)
        self._scratch.qpos[self._dofs] = posture
        self._mj.mj_kinematics(self.mj_model, self._scratch)
        return np.array(self._scratch.site("frame").xpos)

    def _describe(self) -> str:
        """The settings an instability depends on, as ``kp=10, damping=0.5, ...`` (named in errors)."""
        return (
            f"kp={short(self.servos.kp)}, damping={short(self.servos.kv)}, "
            f"armature={short(self.servos.armature)}, timestep={self.timestep:g}"
        )

    def _task(self, posture: NDArray[np.float64]) -> NDArray[np.float64]:
        """The learner's task vector at joint positions ``posture`` (a fresh array)."""
        body_forward(np.ascontiguousarray(posture), self._body, self._x)
        return self._x.copy()

    # -- the camera (a rendering plant) ------------------------------------------------------
    def _camera(self) -> PlantCamera:
        if self.camera is None:
            raise InvalidArgumentError("this plant has no camera: MujocoPlant(..., camera='side')")
        return self.camera

    def move(self, q: ArrayLike) -> None:
        """Command ``q`` (m,) and simulate by the settling rule, reading nothing (a camera reads after)."""
        q = check.vector("q", q, self.n_joints)
        before = health.warnings_seen(self._mj, self.mj_data)
        if self.speed is not None:
            self.steps += ramp(self._mj, self.mj_model, self.mj_data, q, self.speed, self._contacts)
        self.mj_data.ctrl[:] = q
        self.steps += self.settling.hold(self._mj, self.mj_model, self.mj_data, self._contacts)
        self.asks += 1
        health.check_state(self._mj, self.mj_data, before, self._describe(), f"ask {self.asks}")

    def render(self) -> NDArray[np.uint8]:
        """The camera's picture of the arm now (H, W, 3) uint8 RGB, without noise.

        Raises:
            InvalidArgumentError: a plant without a camera.
        """
        return self._camera().render(self.mj_data)

    def read(self) -> NDArray[np.uint8]:
        """A webcam's picture of the arm now (H, W, 3) uint8 BGR with pixel noise (the plant is a camera)."""
        return self._camera().read(self.mj_data)

    def marker_position(self, posture: ArrayLike | None = None) -> NDArray[np.float64]:
        """The marker's centre in the world (3,) [m] at joint positions ``posture`` (default: now)."""
        camera = self._camera()
        if posture is None:
            data = self.mj_data
        else:
            data = self._scratch
            data.qpos[self._dofs] = check.vector("posture", posture, self.n_joints)
            self._mj.mj_kinematics(self.mj_model, data)
        body = data.body(self._marker_body)
        return np.array(body.xpos) + np.array(body.xmat).reshape(3, 3) @ camera.scene.marker_offset

    def true_marker(self, q: ArrayLike) -> NDArray[np.float64]:
        """Where the marker's centre rests under the command ``q``, in the camera frame (3,) [m].

        (N, m) commands give (N, 3). No lag, no noise, the arm not moved: the truth E^X is measured on.
        """
        camera = self._camera()
        single = np.ndim(q) == 1
        Q = check.points("q", q, self.n_joints, allow_single=True)
        out = np.array([camera.pose.to_camera(self.marker_position(self.posture_at(c))) for c in Q])
        return out[0] if single else out

    # -- goal sets: the kinematic robot's -----------------------------------------------------
    def auto_targets(self) -> NDArray[np.float64]:
        """The kinematic robot's "auto" grid (the largest reachable grid around home)."""
        return self.target.auto_targets()

    def check_targets(self, targets: ArrayLike, what: str = "targets") -> NDArray[np.float64]:
        """Targets checked by the kinematic robot (shape, finite, a warning for those beyond reach)."""
        return self.target.check_targets(targets, what)

    # -- checkpoints ---------------------------------------------------------------------------
    def robot_state(self) -> dict[str, NDArray[Any]]:
        """The arm's and the sensor's state as arrays (see :mod:`gb_pin.sim.snapshot`)."""
        out: dict[str, NDArray[Any]] = {
            "counters": np.array([self.asks, self.steps], dtype=np.int64),
            "mujoco": self._state(),
            "sensor": snapshot.generator_words(self._readings.rng),
            "settings": self._settings.copy(),
        }
        if self.camera is not None:  # a rendering plant: its pictures' noise continues too
            words = snapshot.generator_words(self.camera.rng)
            out["camera"] = np.concatenate([np.array([self.camera.frames], dtype=np.uint64), words])
        return out

    def _state(self) -> NDArray[np.float64]:
        state = np.empty(self._mj.mj_stateSize(self.mj_model, self._state_kind))
        self._mj.mj_getState(self.mj_model, self.mj_data, state, self._state_kind)
        return state

    def set_robot_state(self, arrays: dict[str, NDArray[Any]]) -> None:
        """Continue from a state of :meth:`robot_state` (a checkpoint's), checked first.

        Raises:
            InvalidArgumentError: arrays missing or malformed, written by a plant of other settings,
                or a state no run of this plant could leave (:func:`~gb_pin.sim.health.check_restored`).
        """
        size = self._mj.mj_stateSize(self.mj_model, self._state_kind)
        checked = snapshot.unpack(arrays, size, self._settings)
        asks, steps = (int(v) for v in checked["counters"])
        saved = self._state()
        self._mj.mj_setState(self.mj_model, self.mj_data, checked["mujoco"], self._state_kind)
        try:
            health.check_restored(self.mj_data, self._dofs, steps, self.timestep, self.lower, self.upper)
        except InvalidArgumentError:
            self._mj.mj_setState(self.mj_model, self.mj_data, saved, self._state_kind)
            raise
        self._mj.mj_forward(self.mj_model, self.mj_data)
        snapshot.set_generator(self._readings.rng, checked["sensor"])
        if self.camera is not None and "camera" in checked:
            self.camera.frames = int(checked["camera"][0])
            snapshot.set_generator(self.camera.rng, checked["camera"][1:])
        self.asks, self.steps = asks, steps

    def __repr__(self) -> str:
        return (
            f"MujocoPlant({self.target.name!r}, {self.servos.describe()}, gravity "
            f"{'on' if self.gravity else 'off'}, {self.settling.describe()}, tracker={self.tracker!r})"
        )


def _kinematic_robot(robot: Any) -> tuple[Any, str | None]:
    """(the KinematicTarget, its name as given: a preset or ``MODULE:NAME``, or None) of ``robot``.

    Raises:
        UnknownRobotError: an unknown preset.
        InvalidArgumentError: a robot without a compiled chain and a Pinocchio model.
    """
    name = robot if isinstance(robot, str) else None
    if isinstance(robot, str) and ":" in robot:
        from gb_pin.robot.spec import load_robot_spec

        robot = load_robot_spec(robot)
    elif isinstance(robot, str):
        from gb_pin.robot.presets import load_robot

        robot = load_robot(robot)
    from gb_pin.robot.target import KinematicTarget

    if not isinstance(robot, KinematicTarget):
        raise InvalidArgumentError(
            "a MuJoCo plant is built from a robot with a Pinocchio model (a preset name, or a "
            f"KinematicTarget from a URDF or example-robot-data), got {robot!r:.120}"
        )
    return robot, name
