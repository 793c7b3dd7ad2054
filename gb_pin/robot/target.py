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

import warnings
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import (
    GbPinError,
    InvalidArgumentError,
    OnboardingBudgetError,
    UnreachableTargetWarning,
)
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.robot.chain_reader import JointTable, parse_axes, read_chain, read_joints, read_limits
from gb_pin.robot.loaders import ModelLoaders
from gb_pin.robot.onboarding import Onboarding, choose_home, goal_grid, moving_joints, path_joints, record
from gb_pin.robot.pinocchio_models import PinocchioModels
from gb_pin.robot.postures import from_configuration, home_posture, reference_posture, to_configuration
from gb_pin.robot.reachability import beyond_reach, positions
from gb_pin.robot.reduction import find_frame, lock_joints, select_joints
from gb_pin.robot.targets_auto import AutoGrid, TargetSpec, auto_grid, auto_task_grid, resolve_targets
from gb_pin.robot.task_spec import TaskComponentSpec, TaskSpec, component_label, resolve_task

if TYPE_CHECKING:
    import pinocchio as pin

# Pinocchio (and the modules that load models with it) is imported where a model is built or
# read: a planar preset builds its arrays directly (:func:`gb_pin.robot.planar.planar_target`)
# and its pin.Model only when something asks for it (a viewer, Pinocchio checks), which keeps
# the first 0.1 s of pinocchio's import out of a planar run.


class KinematicTarget(PinocchioModels, ModelLoaders):
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
            means the joints that move ``frame`` with ``onboard``, else every joint of
            the model (all must be 1-DOF: a model with a free floating base must name its
            joints, so that the base is locked).
        home: the home posture over ``joints`` ([rad] or [m]) or the name of a
            reference configuration of the model; default chosen by measurement with
            ``onboard``, else the reference posture.
        axes: the task coordinates the learner sees, e.g. ``"xy"`` or ``"xyz"``
            (default).
        targets: default target set: an (N, n) array [m] in world coordinates,
            ``"auto"`` (the largest reachable regular grid around the home effector
            position, seeded), or a spec mapping (``lower``/``upper``/``shape`` grid,
            ``points``, or ``auto`` with ``shape``/``scale``). None: the onboarding's goal
            grid with ``onboard``, else no default set (``babble`` then uses ``"auto"``).
        name: a label for messages and saved files.
        task: what x is: None or ``"position"`` (the frame's position on ``axes``),
            ``"pose"`` (position and full orientation of ``frame``), ``"pointing"`` (position
            and the direction of ``pointing_axis``), or a sequence of
            :class:`~gb_pin.robot.task_spec.Position`, :class:`~gb_pin.robot.task_spec.Orientation`
            and :class:`~gb_pin.robot.task_spec.Pointing` specs of one or several frames.
        orientation_scale: s [m/rad] of the rotational rows of ``"pose"`` and ``"pointing"``
            (default 0.2).
        pointing_axis: the frame axis of ``"pointing"`` (``"x"``, ``"y"``, ``"z"``, ``"-z"`` or a 3-vector;
            default ``"z"``); refused with another task, which would ignore it.
        onboard: choose the joints, home and goal grid not given, and the learner's radius, by
            measurement (:mod:`gb_pin.robot.onboarding`; recorded in :attr:`onboarding`). Default
            False here, True in :meth:`from_urdf` and :meth:`from_example_robot_data`.

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
        pointing_axis: str | ArrayLike | None = None,
        onboard: bool = False,
    ) -> None:
        import pinocchio as pin

        if not isinstance(model, pin.Model):
            raise InvalidArgumentError(f"model must be a pinocchio.Model, got {type(model).__name__}")
        self.name: str = name if name is not None else (model.name or "robot")
        self.reference: NDArray[np.float64] = reference_posture(model)
        self.frame: str = frame
        self.chain: KinematicChain
        self._full_model: pin.Model | None = pin.Model(model)
        self._model_source: Callable[[], pin.Model] | None = None
        self.axes: str = parse_axes(axes)
        self.task: tuple[TaskComponentSpec, ...] | None = resolve_task(
            task, frame, self.axes, orientation_scale, pointing_axis
        )
        self._urdf: str | None = None
        self._package_dirs: list[str] | None = None
        self._auto: NDArray[np.float64] | None = None
        pick = onboard and joints is None
        if pick:
            joints = path_joints(model, find_frame(model, frame, self.name), self.name)
        self._reduce(select_joints(model, joints, self.name, frame))
        dropped = self._drop_still_joints() if pick else ()
        choice = None
        if onboard and home is None:
            ref = from_configuration(self.reference, model, self._full_ids, self._table.continuous)
            choice = choose_home(self, ref)
            self.home: NDArray[np.float64] = choice.home
        else:
            limits = (self.lower, self.upper)
            self.home = home_posture(
                home, model, self.reference, self.joints, self._table.continuous, limits, self.name
            )
        if self.task is not None:
            from gb_pin.robot.task_reader import stack_task

            self.chain = stack_task(self.chain, self.model, self.task, self.home, self.name)
        grid = None
        if onboard and targets is None and self.task is None:
            grid = self._onboard_grid(given_home=home is not None)
        self.targets: NDArray[np.float64] | None = (
            grid.targets if grid is not None else None if targets is None else resolve_targets(targets, self)
        )
        self.onboarding: Onboarding | None = record(pick, dropped, choice, grid, self) if onboard else None

    def _onboard_grid(self, given_home: bool) -> AutoGrid | None:
        """The onboarding's goal grid; around a given home, none (with a warning) if none is reachable.

        A robot with fewer moving joints than task axes (two joints, a 3-D position) reaches no 3-D
        grid: it needs ``targets=`` (or other ``axes``), which ``babble`` then says.
        """
        try:
            return goal_grid(self)
        except OnboardingBudgetError:
            raise
        except InvalidArgumentError as exc:
            if not given_home:
                raise
            import warnings

            from gb_pin.exceptions import GbPinWarning

            message = f"{self.name}: no goal grid chosen ({exc}); pass targets="
            warnings.warn(message, GbPinWarning, stacklevel=3)
            return None

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
        self.onboarding = None
        self.home = home_posture(home, None, self.reference, self.joints, table.continuous, limits, name)
        self.targets = None if targets is None else resolve_targets(targets, self, what="targets")
        return self

    def _reduce(self, joints: Sequence[str]) -> None:
        """Lock every joint of the full model but ``joints`` and read the learner's view of the rest."""
        self.joints: tuple[str, ...] = tuple(joints)
        self._model: pin.Model | None = lock_joints(self.full_model, self.joints, self.reference, self.name)
        self._frame_id: int | None = find_frame(self._model, self.frame, self.name)
        self._data: pin.Data | None = None  # created on first use: pinocchio's Data is O(nv^3)
        self._read_kinematics()

    def _drop_still_joints(self) -> tuple[str, ...]:
        """Onboarding: lock the joints that do not move the frame (measured); returns their names."""
        moves = moving_joints(self)
        if moves.all():
            return ()
        if not moves.any():
            raise InvalidArgumentError(f"no joint of {self.name!r} moves frame {self.frame!r}: choose one")
        dropped = tuple(j for j, k in zip(self.joints, moves, strict=True) if not k)
        self._reduce([j for j, k in zip(self.joints, moves, strict=True) if k])
        return dropped

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
    def learner_defaults(self) -> dict[str, float]:
        """Learner defaults: the radius (and sigma) onboarding chose; ``babble`` uses them unless given."""
        record = self.onboarding
        values = {} if record is None else {"radius": record.radius, "sigma": record.sigma}
        return {k: v for k, v in values.items() if v is not None}

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
