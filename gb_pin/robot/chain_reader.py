"""Reading a ``pin.Model`` into the learner's arrays: joint kinds and axes, limits, the chain.

The learner never calls Pinocchio: it evaluates a
:class:`~gb_pin.learn.body.chain.KinematicChain` (plain arrays, compiled forward
kinematics). This module fills one from the (reduced) Pinocchio model of a
:class:`~gb_pin.robot.target.KinematicTarget`, so that Pinocchio stays the single source
of the robot:

* :func:`joint_kind` maps a 1-DOF Pinocchio joint model to the learner's joint kind
  (revolute, continuous = unbounded revolute, prismatic) and unit axis;
* :func:`read_joints` reads them for the joints the learner moves (a :class:`JointTable`,
  in the order of q);
* :func:`read_limits` reads their position limits;
* :func:`read_chain` reads the joint placements and the frame placement into the chain.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import GbPinError, InvalidArgumentError
from gb_pin.learn.body.chain import PRISMATIC, REVOLUTE, KinematicChain

if TYPE_CHECKING:
    import pinocchio as pin

AXIS_INDEX = {"x": 0, "y": 1, "z": 2}
"""World coordinate of each task-axis letter."""
_UNIT = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
# Pinocchio reports "no limit" as +-max double; anything this large is unbounded.
_UNBOUNDED = 1e300


def joint_kind(joint: Any, name: str) -> tuple[int, tuple[float, float, float], bool]:
    """(kind, axis, continuous) of a 1-DOF joint model, or raise for other joint types.

    Args:
        joint: a Pinocchio joint model (``model.joints[i]``).
        name: the joint's name, for messages.

    Raises:
        InvalidArgumentError: a joint the learner cannot move (free flyer, spherical,
            planar, helical, ...) or a joint axis that is not a unit vector.
    """
    short = joint.shortname()
    suffix = short.removeprefix("JointModel")
    if suffix in ("RX", "RY", "RZ"):
        return REVOLUTE, _UNIT[suffix[1]], False
    if suffix in ("RUBX", "RUBY", "RUBZ"):
        return REVOLUTE, _UNIT[suffix[3]], True
    if suffix in ("PX", "PY", "PZ"):
        return PRISMATIC, _UNIT[suffix[1]], False
    if suffix in ("RevoluteUnaligned", "RevoluteUnboundedUnaligned", "PrismaticUnaligned"):
        axis = _unaligned_axis(joint, suffix.startswith("Prismatic"))
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


def _unaligned_axis(joint: Any, prismatic: bool) -> NDArray[np.float64]:
    """The axis of an unaligned 1-DOF joint, in its frame.

    Pinocchio's Python bindings expose ``axis`` on some unaligned joint models but not on
    ``JointModelRevoluteUnboundedUnaligned`` (a URDF's continuous joint about an axis other than x,
    y or z); its motion subspace S (constant for these joints) holds it: the angular part for a
    revolute joint, the linear part for a prismatic one.
    """
    model = joint.extract()
    if hasattr(model, "axis"):
        return np.asarray(model.axis, dtype=float)
    data = joint.createData()
    joint.calc(data, np.array([1.0, 0.0]) if joint.nq == 2 else np.zeros(joint.nq))  # (cos, sin) = angle 0
    S = np.asarray(data.S, dtype=float).reshape(6)
    return S[:3] if prismatic else S[3:]


def parse_axes(axes: str | None) -> str:
    """The task axes (default ``"xyz"``), checked: distinct letters from ``"xyz"``.

    Raises:
        InvalidArgumentError: anything else.
    """
    axes = "xyz" if axes is None else axes
    if (
        not isinstance(axes, str)
        or not axes
        or len(set(axes)) != len(axes)
        or any(c not in AXIS_INDEX for c in axes)
    ):
        raise InvalidArgumentError(
            f"axes must be distinct letters from 'xyz' (e.g. 'xy', 'xz', 'xyz'), got {axes!r}"
        )
    return axes


@dataclass(frozen=True, eq=False)
class JointTable:
    """The joints the learner moves, in the order of q, as read from a Pinocchio model.

    Attributes:
        order: Pinocchio joint id of each entry of q.
        kinds: ``REVOLUTE`` or ``PRISMATIC`` for each entry of q.
        continuous: whether each joint is continuous (nq = 2 in Pinocchio, one angle for
            the learner).
        axes: (m, 3) unit joint axis of each entry of q, in the joint frame.
    """

    order: tuple[int, ...]
    kinds: tuple[int, ...]
    continuous: tuple[bool, ...]
    axes: NDArray[np.float64]


def read_joints(model: pin.Model, joints: Sequence[str]) -> JointTable:
    """Kinds, continuity and axes of the named joints of ``model``, in the order given.

    Raises:
        InvalidArgumentError: a joint the learner cannot move (see :func:`joint_kind`).
    """
    order = [int(model.getJointId(j)) for j in joints]
    kinds: list[int] = []
    continuous: list[bool] = []
    axes = np.zeros((len(order), 3))
    for a, jid in enumerate(order):
        kind, axis, is_continuous = joint_kind(model.joints[jid], model.names[jid])
        kinds.append(kind)
        continuous.append(is_continuous)
        axes[a] = axis
    return JointTable(order=tuple(order), kinds=tuple(kinds), continuous=tuple(continuous), axes=axes)


def read_limits(model: pin.Model, table: JointTable) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(lower, upper) position limits of the joints of ``table``: +-inf where unbounded or continuous."""
    lower = np.full(len(table.order), -np.inf)
    upper = np.full(len(table.order), np.inf)
    for a, jid in enumerate(table.order):
        if table.continuous[a]:
            continue
        iq = model.joints[jid].idx_q
        lo, hi = model.lowerPositionLimit[iq], model.upperPositionLimit[iq]
        lower[a] = lo if lo > -_UNBOUNDED else -np.inf
        upper[a] = hi if hi < _UNBOUNDED else np.inf
    return lower, upper


def read_chain(model: pin.Model, table: JointTable, frame_id: int, axes: str) -> KinematicChain:
    """The learner's chain: joint placements, axes and the frame placement of ``model``.

    Args:
        model: the reduced model, whose every joint is one of ``table``'s.
        table: the moved joints (see :func:`read_joints`).
        frame_id: the operational frame's id in ``model``.
        axes: the task axes, e.g. ``"xyz"``.
    """
    position_in_q = {jid: a for a, jid in enumerate(table.order)}
    by_model_order = sorted(table.order)  # Pinocchio numbers parents before children
    index = {jid: i for i, jid in enumerate(by_model_order)}
    m = len(by_model_order)
    parents = np.full(m, -1, dtype=np.int64)
    rotations = np.zeros((m, 3, 3))
    translations = np.zeros((m, 3))
    joint_axes = np.zeros((m, 3))
    kinds = np.zeros(m, dtype=np.int64)
    q_index = np.zeros(m, dtype=np.int64)
    for i, jid in enumerate(by_model_order):
        parents[i] = index.get(model.parents[jid], -1)
        placement = model.jointPlacements[jid]
        rotations[i] = placement.rotation
        translations[i] = placement.translation
        a = position_in_q[jid]
        joint_axes[i] = table.axes[a]
        kinds[i] = table.kinds[a]
        q_index[i] = a
    frame = model.frames[frame_id]
    frame_parent = index.get(frame.parentJoint, -1)
    if frame_parent < 0 and frame.parentJoint != 0:
        # Cannot happen after buildReducedModel (every kept joint is moved), but keep the chain honest.
        raise GbPinError(f"frame {frame.name!r} hangs on a joint that is neither moved nor the world")
    return KinematicChain(
        parents=parents,
        rotations=rotations,
        translations=translations,
        axes=joint_axes,
        kinds=kinds,
        q_index=q_index,
        frame_parent=frame_parent,
        frame_translation=np.array(frame.placement.translation, dtype=float),
        task_axes=np.array([AXIS_INDEX[c] for c in axes], dtype=np.int64),
    )
