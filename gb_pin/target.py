"""KinematicTarget: forward kinematics of one operational frame of a Pinocchio model.

This is the robot side of goal babbling: a posture q of the joints the learner
moves goes in, the position of one frame on the chosen task axes comes out. It
also carries the home posture and the joint limits. The learner never sees this
class's robot-specific parts, only :attr:`KinematicTarget.chain` (plain arrays
for compiled forward kinematics), :attr:`home` and the limits.
"""

from __future__ import annotations

import difflib
from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.chain import PRISMATIC, REVOLUTE, KinematicChain
from gb_pin.exceptions import InvalidArgumentError, UnknownRobotError

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
    raise InvalidArgumentError(
        f"joint {name!r} is a {short}; the learner moves only revolute, continuous and "
        "prismatic joints: lock it (leave it out of `joints`)"
    )


class KinematicTarget:
    """Forward kinematics of one frame of a Pinocchio model, over the joints the learner moves.

    Joints not in ``joints`` are locked at the reference posture with
    ``pinocchio.buildReducedModel``. The reference posture is the model's
    ``half_sitting`` (or its only named reference configuration) where there is
    one, else ``pinocchio.neutral``.

    Joint limits: a posture is executed clipped to the model's position limits, and
    the learner learns from the executed posture (what a real robot does).

    Args:
        model: the Pinocchio model (not modified).
        frame: name of the operational frame whose position is the task variable.
        joints: names of the joints the learner moves, in the order of q. ``None``
            means every joint of the model (all must be 1-DOF).
        home: the home posture over ``joints`` ([rad] or [m]) or the name of a
            reference configuration of the model; default the reference posture.
        axes: the task coordinates the learner sees, e.g. ``"xy"`` or ``"xyz"``
            (default).
        targets: optional default target set, shape (N, n) [m], world coordinates.
        name: a label for messages and saved files.

    Raises:
        UnknownRobotError: unknown frame or joint name.
        InvalidArgumentError: unsupported joint type, bad home, bad axes or targets.
    """

    def __init__(
        self,
        model: pin.Model,
        frame: str,
        joints: Sequence[str] | None = None,
        home: ArrayLike | str | None = None,
        axes: str | None = None,
        *,
        targets: ArrayLike | None = None,
        name: str | None = None,
    ) -> None:
        if not isinstance(model, pin.Model):
            raise InvalidArgumentError(f"model must be a pinocchio.Model, got {type(model).__name__}")
        self.name = name if name is not None else (model.name or "robot")
        full_names = list(model.names)[1:]
        reference = self._reference_posture(model)

        if joints is None:
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
        self.frame = frame
        self.frame_id = int(reduced.getFrameId(frame))
        self.joints: tuple[str, ...] = tuple(joints)
        self.axes = self._parse_axes(axes)

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
            None if targets is None else check.points("targets", targets, self.n_task)
        )

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
        return KinematicChain(
            parents=parents,
            rotations=rotations,
            translations=translations,
            axes=axes,
            kinds=kinds,
            q_index=q_index,
            frame_parent=frame_parent,
            frame_translation=np.array(frame.placement.translation, dtype=float),
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
            q = check.vector("home", home, self.n_joints)
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

    def __repr__(self) -> str:
        return (
            f"KinematicTarget(name={self.name!r}, frame={self.frame!r}, joints={self.n_joints}, "
            f"axes={self.axes!r})"
        )
