"""KinematicTarget: forward kinematics of one operational frame of a Pinocchio model.

This is the robot side of goal babbling: a posture q of the joints the learner
moves goes in, the position of one frame on the chosen task axes comes out. It
also carries the home posture, the joint limits and a target set. The learner never
sees this class's robot-specific parts, only :attr:`KinematicTarget.chain` (plain
arrays for compiled forward kinematics), :attr:`home` and the limits.

A target is built from any ``pin.Model`` (:class:`KinematicTarget`), a URDF file
(:meth:`KinematicTarget.from_urdf`) or an example-robot-data robot
(:meth:`KinematicTarget.from_example_robot_data`). Positions are always world
coordinates of the full model (locked joints at the reference posture) on the
chosen axes [m].
"""

from __future__ import annotations

import difflib
import os
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import GbPinError, InvalidArgumentError, UnknownRobotError, UnreachableTargetWarning
from gb_pin.learn.body.chain import PRISMATIC, REVOLUTE, KinematicChain
from gb_pin.robot.models import build_visual_model, load_example_robot, load_urdf_model
from gb_pin.robot.targets_auto import auto_grid, beyond_reach, resolve_targets

_AXIS_INDEX = {"x": 0, "y": 1, "z": 2}
_UNIT = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
# Pinocchio reports "no limit" as +-max double; anything this large is unbounded.
_UNBOUNDED = 1e300


def _closest(name: str, valid: Sequence[str]) -> str:
    close = difflib.get_close_matches(name, valid, n=5, cutoff=0.5)
    if close:
        return "closest: " + ", ".join(close)
    shown = ", ".join(list(valid)[:20])
    return f"valid: {shown}" + (", ..." if len(valid) > 20 else "")


def _reference_configurations(model: pin.Model) -> dict[str, NDArray[np.float64]]:
    """The model's named reference configurations (e.g. ``half_sitting`` from an SRDF)."""
    return {e.key(): np.array(e.data(), dtype=float) for e in model.referenceConfigurations}


def _joint_kind(joint: Any, name: str) -> tuple[int, tuple[float, float, float], bool]:
    """(kind, axis, continuous) of a 1-DOF joint model, or raise for other joint types."""
    short = joint.shortname()
    suffix = short.removeprefix("JointModel")
    if suffix in ("RX", "RY", "RZ"):
        return REVOLUTE, _UNIT[suffix[1]], False
    if suffix in ("RUBX", "RUBY", "RUBZ"):
        return REVOLUTE, _UNIT[suffix[3]], True
    if suffix in ("PX", "PY", "PZ"):
        return PRISMATIC, _UNIT[suffix[1]], False
    if suffix in ("RevoluteUnaligned", "RevoluteUnboundedUnaligned", "PrismaticUnaligned"):
        axis = np.asarray(joint.extract().axis, dtype=float)
        if abs(np.linalg.norm(axis) - 1.0) > 1e-9:
            raise InvalidArgumentError(
                f"joint {name!r} has axis {axis.tolist()} of norm {np.linalg.norm(axis):.6g}; "
                "gb_pin needs unit joint axes (normalise it in the model)"
            )
        kind = PRISMATIC if suffix.startswith("Prismatic") else REVOLUTE
        return kind, (float(axis[0]), float(axis[1]), float(axis[2])), "Unbounded" in suffix
    if suffix == "FreeFlyer":
        raise InvalidArgumentError(
            f"joint {name!r} is a free floating base ({short}); the learner moves only revolute, "
            "continuous and prismatic joints: leave it out of `joints` so that it is locked at the "
            "reference posture"
        )
    raise InvalidArgumentError(
        f"joint {name!r} is a {short}; the learner moves only revolute, continuous and "
        "prismatic joints: lock it (leave it out of `joints`)"
    )


TargetSpec = ArrayLike | str | Mapping[str, Any] | None
"""A target set: an (N, n) array [m], ``"auto"``, a grid spec or an explicit-points spec (see
:func:`gb_pin.robot.targets_auto.resolve_targets`)."""


class KinematicTarget:
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

    Raises:
        UnknownRobotError: unknown frame or joint name.
        InvalidArgumentError: unsupported joint type, an unlocked floating base, bad
            home, bad axes or targets.
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
    ) -> None:
        if not isinstance(model, pin.Model):
            raise InvalidArgumentError(f"model must be a pinocchio.Model, got {type(model).__name__}")
        self.name = name if name is not None else (model.name or "robot")
        full_names = list(model.names)[1:]
        reference = self._reference_posture(model)

        if joints is None:
            floating = [
                n
                for n in full_names
                if model.joints[model.getJointId(n)].shortname() == "JointModelFreeFlyer"
            ]
            if floating:
                movable = [n for n in full_names if model.joints[model.getJointId(n)].nv == 1]
                raise InvalidArgumentError(
                    f"model {self.name!r} has a free floating base {floating[0]!r}, which joints=None would "
                    "leave unlocked: name the joints the learner moves (the base is then locked at the "
                    f"reference posture), e.g. joints={movable[:7]!r}"
                )
            joints = full_names
        if isinstance(joints, str) or not all(isinstance(j, str) for j in joints):
            raise InvalidArgumentError(f"joints must be a sequence of joint names, got {joints!r}")
        joints = list(joints)
        if not joints:
            raise InvalidArgumentError("joints must name at least one joint, got []")
        if len(set(joints)) != len(joints):
            raise InvalidArgumentError(f"joints must not repeat a name, got {joints!r}")
        for j in joints:
            if j not in full_names:
                raise UnknownRobotError(
                    f"unknown joint {j!r} in model {self.name!r}; {_closest(j, full_names)}"
                )
        for j in joints:  # a clear error before buildReducedModel sees an odd joint
            _joint_kind(model.joints[model.getJointId(j)], j)
        locked = [model.getJointId(n) for n in full_names if n not in joints]
        if locked:
            # buildReducedModel needs a JOINT frame on every joint; hand-built models may lack them.
            source = pin.Model(model)
            framed = {f.parentJoint for f in source.frames if f.type == pin.FrameType.JOINT}
            for jid in range(1, source.njoints):
                if jid not in framed:
                    source.addJointFrame(jid)
            try:
                reduced = pin.buildReducedModel(source, locked, reference)
            except (ValueError, RuntimeError) as exc:
                raise InvalidArgumentError(
                    f"cannot lock joints {[n for n in full_names if n not in joints]} of {self.name!r}: "
                    f"pinocchio.buildReducedModel failed ({exc}); give every joint its frame "
                    "(Model.addJointFrame) before adding other frames"
                ) from exc
        else:
            reduced = pin.Model(model)

        if not isinstance(frame, str) or not reduced.existFrame(frame):
            frame_names = [f.name for f in reduced.frames]
            raise UnknownRobotError(
                f"unknown frame {frame!r} in model {self.name!r}; {_closest(str(frame), frame_names)}"
            )
        self.model = reduced
        self.data = reduced.createData()
        self.full_model = pin.Model(model)
        self.reference: NDArray[np.float64] = reference
        self.frame = frame
        self.frame_id = int(reduced.getFrameId(frame))
        self.joints: tuple[str, ...] = tuple(joints)
        self.axes = self._parse_axes(axes)
        self._urdf: str | None = None
        self._package_dirs: list[str] | None = None
        self._auto: NDArray[np.float64] | None = None

        self._kinds: list[int] = []
        self._continuous: list[bool] = []
        order = [reduced.getJointId(j) for j in joints]  # Pinocchio joint ids in q order
        axes_arr = np.zeros((len(joints), 3))
        for a, jid in enumerate(order):
            kind, axis, continuous = _joint_kind(reduced.joints[jid], reduced.names[jid])
            self._kinds.append(kind)
            self._continuous.append(continuous)
            axes_arr[a] = axis
        self._order = order
        self._axes_arr = axes_arr
        lower = np.full(len(joints), -np.inf)
        upper = np.full(len(joints), np.inf)
        for a, jid in enumerate(order):
            if self._continuous[a]:
                continue
            iq = reduced.joints[jid].idx_q
            lo, hi = reduced.lowerPositionLimit[iq], reduced.upperPositionLimit[iq]
            lower[a] = lo if lo > -_UNBOUNDED else -np.inf
            upper[a] = hi if hi < _UNBOUNDED else np.inf
        self.lower: NDArray[np.float64] = lower
        self.upper: NDArray[np.float64] = upper
        self._q_ref = pin.neutral(reduced)
        self.chain = self._build_chain()
        self.home: NDArray[np.float64] = self._parse_home(home, model, reference)
        self.targets: NDArray[np.float64] | None = (
            None if targets is None else resolve_targets(targets, self, what="targets")
        )

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

        Raises:
            InvalidArgumentError: missing or malformed URDF/SRDF, or any constructor error.
        """
        model = load_urdf_model(path, srdf=srdf, floating_base=floating_base)
        target = cls(
            model,
            frame,
            joints,
            home,
            axes,
            targets=targets,
            name=name if name is not None else Path(os.fspath(path)).stem,
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

        Raises:
            UnknownRobotError: unknown robot, frame or joint (closest names listed).
            InvalidArgumentError: any other constructor error.
        """
        model, _, urdf = load_example_robot(name)
        target = cls(
            model, frame, joints, home, axes, targets=targets, name=label if label is not None else name
        )
        target._urdf = str(urdf)
        return target

    # -- construction helpers -------------------------------------------------
    @staticmethod
    def _reference_posture(model: pin.Model) -> NDArray[np.float64]:
        refs = _reference_configurations(model)
        if "half_sitting" in refs:
            return np.array(refs["half_sitting"], dtype=float)
        if len(refs) == 1:
            return np.array(next(iter(refs.values())), dtype=float)
        return np.array(pin.neutral(model), dtype=float)

    @staticmethod
    def _parse_axes(axes: str | None) -> str:
        axes = "xyz" if axes is None else axes
        if (
            not isinstance(axes, str)
            or not axes
            or len(set(axes)) != len(axes)
            or any(c not in _AXIS_INDEX for c in axes)
        ):
            raise InvalidArgumentError(
                f"axes must be distinct letters from 'xyz' (e.g. 'xy', 'xz', 'xyz'), got {axes!r}"
            )
        return axes

    def _build_chain(self) -> KinematicChain:
        """Read joint placements, axes and the frame placement from the reduced model."""
        model = self.model
        position_in_q = {jid: a for a, jid in enumerate(self._order)}
        by_model_order = sorted(self._order)  # Pinocchio numbers parents before children
        index = {jid: i for i, jid in enumerate(by_model_order)}
        m = len(by_model_order)
        parents = np.full(m, -1, dtype=np.int64)
        rotations = np.zeros((m, 3, 3))
        translations = np.zeros((m, 3))
        axes = np.zeros((m, 3))
        kinds = np.zeros(m, dtype=np.int64)
        q_index = np.zeros(m, dtype=np.int64)
        for i, jid in enumerate(by_model_order):
            parent = model.parents[jid]
            parents[i] = index.get(parent, -1)
            placement = model.jointPlacements[jid]
            rotations[i] = placement.rotation
            translations[i] = placement.translation
            a = position_in_q[jid]
            axes[i] = self._axes_arr[a]
            kinds[i] = self._kinds[a]
            q_index[i] = a
        frame = model.frames[self.frame_id]
        frame_parent = index.get(frame.parentJoint, -1)
        frame_translation = np.array(frame.placement.translation, dtype=float)
        if frame_parent < 0 and frame.parentJoint != 0:
            # Cannot happen after buildReducedModel (every kept joint is moved), but keep the chain honest.
            raise GbPinError(f"frame {self.frame!r} hangs on a joint that is neither moved nor the world")
        return KinematicChain(
            parents=parents,
            rotations=rotations,
            translations=translations,
            axes=axes,
            kinds=kinds,
            q_index=q_index,
            frame_parent=frame_parent,
            frame_translation=frame_translation,
            task_axes=np.array([_AXIS_INDEX[c] for c in self.axes], dtype=np.int64),
        )

    def _parse_home(
        self, home: ArrayLike | str | None, full_model: pin.Model, reference: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        if home is None:
            q_full = reference
        elif isinstance(home, str):
            refs = _reference_configurations(full_model)
            if home not in refs:
                raise InvalidArgumentError(
                    f"home {home!r} is not a reference configuration of {self.name!r}; "
                    f"valid: {sorted(refs) or 'none (give an array)'}"
                )
            q_full = np.array(refs[home], dtype=float)
        else:
            try:
                q = check.vector("home", home, self.n_joints)
            except InvalidArgumentError as exc:
                raise InvalidArgumentError(
                    f"{exc}: one value per joint of `joints` ({', '.join(self.joints)})"
                ) from exc
            self._check_within_limits(q)
            return q
        q = np.empty(self.n_joints)
        for a, name in enumerate(self.joints):
            jid = full_model.getJointId(name)
            iq = full_model.joints[jid].idx_q
            if self._continuous[a]:
                q[a] = np.arctan2(q_full[iq + 1], q_full[iq])
            else:
                q[a] = q_full[iq]
        self._check_within_limits(q)
        return q

    def _check_within_limits(self, q: NDArray[np.float64]) -> None:
        bad = np.flatnonzero((q < self.lower) | (q > self.upper))
        if bad.size:
            detail = ", ".join(
                f"{self.joints[i]}={q[i]:.4g} not in [{self.lower[i]:.4g}, {self.upper[i]:.4g}]" for i in bad
            )
            raise InvalidArgumentError(f"home posture outside the joint limits: {detail}")

    # -- public API ---------------------------------------------------------------
    @property
    def n_joints(self) -> int:
        """Number of joints m the learner moves (posture dimension)."""
        return len(self.joints)

    @property
    def n_task(self) -> int:
        """Task dimension n (number of task axes)."""
        return len(self.axes)

    @property
    def home_position(self) -> NDArray[np.float64]:
        """f(q_home) on the task axes [m]."""
        return self.forward(self.home)

    def to_pinocchio(self, q: ArrayLike) -> NDArray[np.float64]:
        """Configuration vector of the reduced Pinocchio model for posture ``q`` (m,)."""
        q = np.asarray(q, dtype=float)
        q_pin = self._q_ref.copy()
        for a, jid in enumerate(self._order):
            iq = self.model.joints[jid].idx_q
            if self._continuous[a]:
                q_pin[iq], q_pin[iq + 1] = np.cos(q[a]), np.sin(q[a])
            else:
                q_pin[iq] = q[a]
        return q_pin

    def full_configuration(self, q: ArrayLike) -> NDArray[np.float64]:
        """Configuration of the *full* model: posture ``q`` (m,) on ``joints``, the rest at the reference.

        This is what a viewer displays, and what checks against the full model use.
        """
        q = check.vector("q", q, self.n_joints)
        q_full = self.reference.copy()
        for a, name in enumerate(self.joints):
            iq = self.full_model.joints[self.full_model.getJointId(name)].idx_q
            if self._continuous[a]:
                q_full[iq], q_full[iq + 1] = np.cos(q[a]), np.sin(q[a])
            else:
                q_full[iq] = q[a]
        return q_full

    def clip(self, q: ArrayLike) -> NDArray[np.float64]:
        """Posture(s) clipped to the joint limits: what the robot executes."""
        return np.clip(np.asarray(q, dtype=float), self.lower, self.upper)

    def forward(self, q: ArrayLike) -> NDArray[np.float64]:
        """Frame position on the task axes, computed by Pinocchio.

        Args:
            q: posture (m,) or postures (N, m), executed as given (not clipped).

        Returns:
            (n,) or (N, n) positions [m].
        """
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
        out = np.empty((arr2.shape[0], self.n_task))
        idx = self.chain.task_axes
        for i, qi in enumerate(arr2):
            pin.framesForwardKinematics(self.model, self.data, self.to_pinocchio(qi))
            out[i] = self.data.oMf[self.frame_id].translation[idx]
        return out[0] if single else out

    def auto_targets(self) -> NDArray[np.float64]:
        """The ``"auto"`` target set: the largest reachable 3-per-axis grid around the home position [m].

        Computed once (seeded, so always the same) and cached; see
        :func:`gb_pin.robot.targets_auto.auto_grid` for other shapes and scales.
        """
        if self._auto is None:
            self._auto = auto_grid(self).targets
        return self._auto.copy()

    def check_targets(self, targets: ArrayLike, what: str = "targets") -> NDArray[np.float64]:
        """Validate explicit targets: (N, n) finite points [m]; warn about the ones beyond the arm's reach.

        The reach check is cheap and one-sided: a point farther from the first moved
        joint than the sum of the link lengths (plus the prismatic strokes) is
        certainly unreachable (:class:`~gb_pin.exceptions.UnreachableTargetWarning`);
        a point within that ball may still be unreachable (joint limits, the body).
        Use :func:`gb_pin.robot.targets_auto.check_reachable` for a full check.

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
        return build_visual_model(self.full_model, self._urdf, self._package_dirs)

    @property
    def urdf(self) -> str | None:
        """The URDF file the model came from, or None."""
        return self._urdf

    def __repr__(self) -> str:
        return (
            f"KinematicTarget(name={self.name!r}, frame={self.frame!r}, joints={self.n_joints}, "
            f"axes={self.axes!r})"
        )
