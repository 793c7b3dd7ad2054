"""KinematicTarget: forward kinematics of one operational frame of a Pinocchio model.

This is the robot side of goal babbling: a posture q of the joints the learner
moves goes in, the position of one frame on the chosen task axes comes out (or, with
``task=``, a stacked task vector: positions, orientations and pointing directions of one or
several frames, see :mod:`gb_pin.robot.task_spec`). It
also carries the home posture, the joint limits and a target set. The learner never
sees this class's robot-specific parts, only :attr:`KinematicTarget.chain` (plain
arrays for compiled forward kinematics), :attr:`home` and the limits.

A target is built from any ``pin.Model`` (:class:`KinematicTarget`), a URDF file
(:meth:`KinematicTarget.from_urdf`) or an example-robot-data robot
(:meth:`KinematicTarget.from_example_robot_data`). Positions are always world
coordinates of the full model (locked joints at the reference posture) on the
chosen axes [m].

Construction reads the model in steps, each in its own module: the reference posture
and the home (:mod:`gb_pin.robot.postures`), the moved joints and the reduced model
(:mod:`gb_pin.robot.reduction`), joint kinds, limits and the learner's chain
(:mod:`gb_pin.robot.chain_reader`), the target set (:mod:`gb_pin.robot.targets_auto`).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import GbPinError, InvalidArgumentError, UnreachableTargetWarning
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.robot.chain_reader import JointTable, parse_axes, read_chain, read_joints, read_limits
from gb_pin.robot.pinocchio_models import PinocchioModels
from gb_pin.robot.postures import home_posture, reference_posture, to_configuration
from gb_pin.robot.reachability import beyond_reach, positions
from gb_pin.robot.reduction import find_frame, lock_joints, select_joints
from gb_pin.robot.targets_auto import TargetSpec, auto_grid, auto_task_grid, resolve_targets
from gb_pin.robot.task_spec import TaskComponentSpec, TaskSpec, component_label, resolve_task

if TYPE_CHECKING:
    import pinocchio as pin

# Pinocchio (and the modules that load models with it) is imported where a model is built or
# read: a planar preset builds its arrays directly (:func:`gb_pin.robot.planar.planar_target`)
# and its pin.Model only when something asks for it (a viewer, Pinocchio checks), which keeps
# the first 0.1 s of pinocchio's import out of a planar run.


class KinematicTarget(PinocchioModels):
    """Forward kinematics of one frame of a Pinocchio model, over the joints the learner moves.

    Joints not in ``joints`` (a floating base included) are locked at the reference
    posture with ``pinocchio.buildReducedModel``. The reference posture is the
    model's ``half_sitting`` (or its only named reference configuration) where there
    is one, else ``pinocchio.neutral``.

    Joint limits: a posture is executed clipped to the model's position limits, and
    the learner learns from the executed posture (what a real robot does).
    Continuous joints (nq = 2 in Pinocchio) are seen by the learner as one angle.

    Args:
        model: the Pinocchio model (not modified).
        frame: name of the operational frame whose position is the task variable.
        joints: names of the joints the learner moves, in the order of q. ``None``
            means every joint of the model (all must be 1-DOF: a model with a free
            floating base must name its joints, so that the base is locked).
        home: the home posture over ``joints`` ([rad] or [m]) or the name of a
            reference configuration of the model; default the reference posture.
        axes: the task coordinates the learner sees, e.g. ``"xy"`` or ``"xyz"``
            (default).
        targets: default target set: an (N, n) array [m] in world coordinates,
            ``"auto"`` (the largest reachable regular grid around the home effector
            position, seeded), or a spec mapping (``lower``/``upper``/``shape`` grid,
            ``points``, or ``auto`` with ``shape``/``scale``). None: no default set
            (``babble`` then uses ``"auto"``).
        name: a label for messages and saved files.
        task: what x is: None or ``"position"`` (the frame's position on ``axes``),
            ``"pose"`` (position and full orientation of ``frame``), ``"pointing"`` (position
            and the direction of ``pointing_axis``), or a sequence of
            :class:`~gb_pin.robot.task_spec.Position`, :class:`~gb_pin.robot.task_spec.Orientation`
            and :class:`~gb_pin.robot.task_spec.Pointing` specs of one or several frames.
        orientation_scale: s [m/rad] of the rotational rows of ``"pose"`` and ``"pointing"``
            (default 0.2).
        pointing_axis: the frame axis of ``"pointing"`` (``"x"``, ``"y"``, ``"z"``, ``"-z"`` or a 3-vector).

    Raises:
        UnknownRobotError: unknown frame or joint name.
        InvalidArgumentError: unsupported joint type, an unlocked floating base, bad
            home, bad axes or targets; a bad task (a frame the joints do not move, a scale
            not finite and > 0, a bad axis).
    """

    def __init__(
        self,
        model: pin.Model,
        frame: str,
        joints: Sequence[str] | None = None,
        home: ArrayLike | str | None = None,
        axes: str | None = None,
        *,
        targets: TargetSpec = None,
        name: str | None = None,
        task: TaskSpec = None,
        orientation_scale: float | None = None,
        pointing_axis: str | ArrayLike = "z",
    ) -> None:
        import pinocchio as pin

        if not isinstance(model, pin.Model):
            raise InvalidArgumentError(f"model must be a pinocchio.Model, got {type(model).__name__}")
        self.name: str = name if name is not None else (model.name or "robot")
        self.reference: NDArray[np.float64] = reference_posture(model)
        self.joints: tuple[str, ...] = tuple(select_joints(model, joints, self.name))
        self._model: pin.Model | None = lock_joints(model, self.joints, self.reference, self.name)
        self._frame_id: int | None = find_frame(self._model, frame, self.name)
        self.frame: str = frame
        self.chain: KinematicChain
        self._data: pin.Data | None = None  # created on first use: pinocchio's Data is O(nv^3)
        self._full_model: pin.Model | None = pin.Model(model)
        self._model_source: Callable[[], pin.Model] | None = None
        self.axes: str = parse_axes(axes)
        self.task: tuple[TaskComponentSpec, ...] | None = resolve_task(
            task, frame, self.axes, orientation_scale, pointing_axis
        )
        self._urdf: str | None = None
        self._package_dirs: list[str] | None = None
        self._auto: NDArray[np.float64] | None = None
        self._read_kinematics()
        limits = (self.lower, self.upper)
        self.home: NDArray[np.float64] = home_posture(
            home, model, self.reference, self.joints, self._table.continuous, limits, self.name
        )
        if self.task is not None:
            from gb_pin.robot.task_reader import stack_task

            self.chain = stack_task(self.chain, self.model, self.task, self.home, self.name)
        self.targets: NDArray[np.float64] | None = (
            None if targets is None else resolve_targets(targets, self, what="targets")
        )

    @classmethod
    def _from_arrays(
        cls,
        *,
        name: str,
        frame: str,
        joints: Sequence[str],
        chain: KinematicChain,
        table: JointTable,
        limits: tuple[NDArray[np.float64], NDArray[np.float64]],
        home: ArrayLike,
        axes: str,
        model_source: Callable[[], pin.Model],
        targets: TargetSpec = None,
    ) -> KinematicTarget:
        """A target whose learner arrays are given and whose pin.Model is built on first use.

        For procedural models whose arrays are cheaper to write than to read (the planar
        chains, :func:`gb_pin.robot.planar.planar_target`): ``model_source()`` must build the
        full model those arrays describe, with every joint moved (nothing to lock) and the
        neutral configuration as reference. Tests compare every array with the ones read from
        the model.
        """
        self = cls.__new__(cls)
        self.name = name
        self.joints = tuple(joints)
        self.frame = frame
        self.axes = parse_axes(axes)
        self.task = None
        self.chain = chain
        self._table = table
        self.lower, self.upper = limits
        self.reference = np.zeros(len(self.joints))
        self._q_ref = np.zeros(len(self.joints))
        self._full_ids = table.order
        self._model = None
        self._full_model = None
        self._frame_id = None
        self._data = None
        self._model_source = model_source
        self._urdf = None
        self._package_dirs = None
        self._auto = None
        self.home = home_posture(home, None, self.reference, self.joints, table.continuous, limits, name)
        self.targets = None if targets is None else resolve_targets(targets, self, what="targets")
        return self

    def _read_kinematics(self) -> None:
        """The learner's view of the reduced model: joint kinds and axes, limits, the chain."""
        import pinocchio as pin

        self._table: JointTable = read_joints(self.model, self.joints)
        self._full_ids = tuple(int(self.full_model.getJointId(j)) for j in self.joints)
        self._q_ref: NDArray[np.float64] = pin.neutral(self.model)
        limits = read_limits(self.model, self._table)
        self.lower: NDArray[np.float64] = limits[0]
        self.upper: NDArray[np.float64] = limits[1]
        self.chain = read_chain(self.model, self._table, self.frame_id, self.axes)

    # -- other constructors ---------------------------------------------------------
    @classmethod
    def from_urdf(
        cls,
        path: str | os.PathLike[str],
        frame: str,
        joints: Sequence[str] | None = None,
        home: ArrayLike | str | None = None,
        axes: str | None = None,
        package_dirs: Sequence[str | os.PathLike[str]] | None = None,
        *,
        srdf: str | os.PathLike[str] | None = None,
        floating_base: bool = False,
        targets: TargetSpec = None,
        name: str | None = None,
        task: TaskSpec = None,
        orientation_scale: float | None = None,
        pointing_axis: str | ArrayLike = "z",
    ) -> KinematicTarget:
        """A target from a URDF file (kinematics only: no mesh is loaded).

        Args:
            path: the URDF file.
            frame: operational frame (a link name or any frame of the model).
            joints: joints the learner moves (see the class); default every joint.
            home: home posture over ``joints`` or a reference configuration name.
            axes: task axes, default ``"xyz"``.
            package_dirs: where ``package://`` mesh paths resolve; used only by
                :meth:`visual_model`.
            srdf: SRDF file whose group states become reference configurations
                (e.g. ``half_sitting``).
            floating_base: add a free-flyer root joint (a mobile robot); then name
                ``joints`` (the base is locked at the reference posture).
            targets: default target set (see the class).
            name: label; default the file's stem.
            task: what x is (see the class).
            orientation_scale: s [m/rad] of ``"pose"`` and ``"pointing"`` (see the class).
            pointing_axis: the frame axis of ``"pointing"`` (see the class).

        Raises:
            InvalidArgumentError: missing or malformed URDF/SRDF, or any constructor error.
        """
        from gb_pin.robot.models import load_urdf_model

        model = load_urdf_model(path, srdf=srdf, floating_base=floating_base)
        target = cls(
            model,
            frame,
            joints,
            home,
            axes,
            targets=targets,
            name=name if name is not None else Path(os.fspath(path)).stem,
            task=task,
            orientation_scale=orientation_scale,
            pointing_axis=pointing_axis,
        )
        target._urdf = os.fspath(path)
        target._package_dirs = None if package_dirs is None else [os.fspath(p) for p in package_dirs]
        return target

    @classmethod
    def from_example_robot_data(
        cls,
        name: str,
        frame: str,
        joints: Sequence[str] | None = None,
        home: ArrayLike | str | None = None,
        axes: str | None = None,
        *,
        targets: TargetSpec = None,
        label: str | None = None,
        task: TaskSpec = None,
        orientation_scale: float | None = None,
        pointing_axis: str | ArrayLike = "z",
    ) -> KinematicTarget:
        """A target from a robot of the example-robot-data package (e.g. ``"talos"``, ``"panda"``).

        Mobile robots (humanoids, quadrupeds) get a free-flyer root joint, as in
        example-robot-data's own loaders, and their SRDF reference configurations
        (``half_sitting``): name the ``joints`` to move; everything else, the base
        included, is locked at the reference posture.

        Args:
            name: the robot's name, see :data:`gb_pin.robot.models.DESCRIPTIONS`.
            frame: operational frame.
            joints: joints the learner moves.
            home: home posture over ``joints`` or a reference configuration name.
            axes: task axes, default ``"xyz"``.
            targets: default target set (see the class).
            label: the target's name for messages; default ``name``.
            task: what x is (see the class).
            orientation_scale: s [m/rad] of ``"pose"`` and ``"pointing"`` (see the class).
            pointing_axis: the frame axis of ``"pointing"`` (see the class).

        Raises:
            UnknownRobotError: unknown robot, frame or joint (closest names listed).
            InvalidArgumentError: any other constructor error.
        """
        from gb_pin.robot.models import load_example_robot

        model, _, urdf = load_example_robot(name)
        target = cls(
            model,
            frame,
            joints,
            home,
            axes,
            targets=targets,
            name=label if label is not None else name,
            task=task,
            orientation_scale=orientation_scale,
            pointing_axis=pointing_axis,
        )
        target._urdf = str(urdf)
        return target

    # -- public API ---------------------------------------------------------------
    @property
    def n_joints(self) -> int:
        """Number of joints m the learner moves (posture dimension)."""
        return len(self.joints)

    @property
    def n_task(self) -> int:
        """Task dimension n (number of task axes, or rows of the stacked task)."""
        return self.chain.n_task

    @property
    def component_labels(self) -> tuple[str, ...]:
        """One label per task component (e.g. ``"orientation gripper_left_base_link"``)."""
        if self.task is None:
            return (f"position {self.frame}",)
        return tuple(component_label(spec) for spec in self.task)

    @property
    def home_position(self) -> NDArray[np.float64]:
        """f(q_home) on the task axes [m]."""
        return self.forward(self.home)

    def to_pinocchio(self, q: ArrayLike) -> NDArray[np.float64]:
        """Configuration vector of the reduced Pinocchio model for posture ``q`` (m,)."""
        q = np.asarray(q, dtype=float)
        return to_configuration(q, self.model, self._table.order, self._table.continuous, self._q_ref)

    def full_configuration(self, q: ArrayLike) -> NDArray[np.float64]:
        """Configuration of the *full* model: posture ``q`` (m,) on ``joints``, the rest at the reference.

        This is what a viewer displays, and what checks against the full model use.
        """
        q = check.vector("q", q, self.n_joints)
        return to_configuration(q, self.full_model, self._full_ids, self._table.continuous, self.reference)

    def clip(self, q: ArrayLike) -> NDArray[np.float64]:
        """Posture(s) clipped to the joint limits: what the robot executes."""
        return np.clip(np.asarray(q, dtype=float), self.lower, self.upper)

    def forward(self, q: ArrayLike) -> NDArray[np.float64]:
        """Frame position on the task axes, by the kinematics the learner executes (Eq. 1).

        This is the compiled forward kinematics read from the model (:attr:`chain`), so that a
        robot driven through ``forward`` (ask/tell) sees bit for bit what ``babble()`` computes;
        it equals Pinocchio's (:meth:`forward_pinocchio`) to about 1e-15 m (tested on every preset).

        Args:
            q: posture (m,) or postures (N, m), executed as given (not clipped).

        Returns:
            (n,) or (N, n) positions [m].
        """
        arr2, single = self._postures(q)
        out = np.empty((arr2.shape[0], self.n_task))
        positions(arr2, self.chain.forward_kernel(), out)
        return out[0] if single else out

    def forward_pinocchio(self, q: ArrayLike) -> NDArray[np.float64]:
        """The task vector computed by Pinocchio (``framesForwardKinematics``, ``log3``; for checks).

        Args:
            q: posture (m,) or postures (N, m), executed as given (not clipped).

        Returns:
            (n,) or (N, n) positions [m].
        """
        import pinocchio as pin

        from gb_pin.robot.task_reader import pinocchio_task_vector

        arr2, single = self._postures(q)
        out = np.empty((arr2.shape[0], self.n_task))
        idx = self.chain.task_axes
        for i, qi in enumerate(arr2):
            pin.framesForwardKinematics(self.model, self.data, self.to_pinocchio(qi))
            if self.task is None:
                out[i] = self.data.oMf[self.frame_id].translation[idx]
            else:
                out[i] = pinocchio_task_vector(self.model, self.data, self.chain, self.task)
        return out[0] if single else out

    def _postures(self, q: ArrayLike) -> tuple[NDArray[np.float64], bool]:
        """``q`` as a C-contiguous (N, m) float array of finite numbers, and whether it was one posture."""
        try:
            arr = np.asarray(q, dtype=float)
        except (TypeError, ValueError) as exc:
            raise InvalidArgumentError(
                f"q must be a posture ({self.n_joints},) or postures (N, {self.n_joints}), got {q!r}"
            ) from exc
        single = arr.ndim == 1
        arr2 = np.atleast_2d(arr)
        if arr2.ndim != 2 or arr2.shape[1] != self.n_joints:
            raise InvalidArgumentError(
                f"q must have shape ({self.n_joints},) or (N, {self.n_joints}), got shape {arr.shape}"
            )
        return np.ascontiguousarray(arr2), single

    def auto_targets(self) -> NDArray[np.float64]:
        """The ``"auto"`` target set: the largest reachable 3-per-axis grid around the home position [m].

        Computed once (seeded, so always the same) and cached; see
        :func:`gb_pin.robot.targets_auto.auto_grid` for other shapes and scales. With a stacked
        ``task``: the target frame's position grid at the home orientation (or direction), shrunk
        until every point is reachable (:func:`gb_pin.robot.targets_auto.auto_task_grid`).
        """
        if self._auto is None:
            self._auto = auto_grid(self).targets if self.task is None else auto_task_grid(self)
        return self._auto.copy()

    def check_targets(self, targets: ArrayLike, what: str = "targets") -> NDArray[np.float64]:
        """Validate explicit targets: (N, n) finite points [m]; warn about the ones beyond the arm's reach.

        The reach check is cheap and one-sided: a point farther from the first moved
        joint than the sum of the link lengths (plus the prismatic strokes) is
        certainly unreachable (:class:`~gb_pin.exceptions.UnreachableTargetWarning`);
        a point within that ball may still be unreachable (joint limits, the body).
        Use :func:`gb_pin.robot.reachability.check_reachable` for a full check.

        Raises:
            InvalidArgumentError: wrong shape or non-finite values.
        """
        X = check.points(what, targets, self.n_task)
        far = beyond_reach(self.chain, self.lower, self.upper, X)
        if far.any():
            shown = "; ".join(str(np.round(p, 4).tolist()) for p in X[far][:5])
            more = f" (and {int(far.sum()) - 5} more)" if far.sum() > 5 else ""
            warnings.warn(
                f"{int(far.sum())} of {len(X)} {what} of {self.name!r} lie beyond the arm's reach on axes "
                f"{self.axes!r} and cannot be reached: {shown}{more}",
                UnreachableTargetWarning,
                stacklevel=3,
            )
        return X

    def visual_model(self) -> pin.GeometryModel:
        """The visual geometry (meshes) of :attr:`full_model`, loaded on demand from the URDF (viewers).

        Raises:
            GbPinError: the target was not built from a URDF or example-robot-data, or
                its meshes cannot be loaded.
        """
        if self._urdf is None:
            raise GbPinError(
                f"target {self.name!r} was built from a pin.Model, not a URDF: it has no meshes to load "
                "(use KinematicTarget.from_urdf or from_example_robot_data)"
            )
        from gb_pin.robot.models import build_visual_model

        return build_visual_model(self.full_model, self._urdf, self._package_dirs)

    @property
    def urdf(self) -> str | None:
        """The URDF file the model came from, or None."""
        return self._urdf

    def __repr__(self) -> str:
        task = "" if self.task is None else f", task=[{', '.join(self.component_labels)}]"
        return (
            f"KinematicTarget(name={self.name!r}, frame={self.frame!r}, joints={self.n_joints}, "
            f"axes={self.axes!r}{task})"
        )
