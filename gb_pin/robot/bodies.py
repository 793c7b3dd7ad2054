"""Bodies that change: grown links, a tool in the hand, a joint locked by an injury.

Each helper takes a robot (a :class:`~gb_pin.robot.target.KinematicTarget`, or a body made
by these helpers) and returns a :class:`ChangedBody`: the same joints, limits, home and task
axes, with changed compiled kinematics. A changed body is a robot wherever one is accepted
(``babble(robot=...)``, ``babble(changes={movement: body})``, ``babble_session``), and
changes compose (``with_tool(scaled(arm, 1.15), 0.1)``). Positions are those of the
learner's compiled chain; the Pinocchio model of the original robot is not changed.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.body.chain import PRISMATIC, REVOLUTE, KinematicChain


class ChangedBody:
    """A robot whose kinematics differ from another's: same joints, limits, home and task axes.

    Args:
        base: the robot it derives from (anything with ``chain``, ``home``, ``lower``, ``upper``,
            ``targets`` and ``name``).
        chain: the changed compiled kinematics (validated).
        name: a label; default derived from the base's name.
        targets: its target set (N, n) [m]; default the base's.
    """

    def __init__(self, base: Any, chain: KinematicChain, name: str, targets: ArrayLike | None = None) -> None:
        chain.validate()
        self.base = base
        self.chain = chain
        self.name = str(name)
        self.home: NDArray[np.float64] = np.array(base.home, dtype=float)
        self.lower: NDArray[np.float64] = np.array(base.lower, dtype=float)
        self.upper: NDArray[np.float64] = np.array(base.upper, dtype=float)
        self.axes = getattr(base, "axes", None)
        base_targets = getattr(base, "targets", None)
        chosen = base_targets if targets is None else targets
        self.targets: NDArray[np.float64] | None = (
            None if chosen is None else check.points("targets", chosen, chain.n_task)
        )

    @property
    def n_joints(self) -> int:
        """Number of joints m."""
        return self.chain.n_joints

    @property
    def n_task(self) -> int:
        """Task dimension n."""
        return self.chain.n_task

    @property
    def home_position(self) -> NDArray[np.float64]:
        """f(q_home) [m]."""
        return self.chain.forward(self.home)

    @property
    def frame_id(self) -> int:
        """The base's operational frame in its Pinocchio model (viewers draw the frame's orientation).

        Raises:
            AttributeError: the base has no Pinocchio model (a body of arrays).
        """
        return int(self.base.frame_id)

    @property
    def model(self) -> Any:
        """The base's Pinocchio model (the model's kinematics, not this body's: for drawing only)."""
        return self.base.model

    def forward(self, q: ArrayLike) -> NDArray[np.float64]:
        """Task-space position(s) of the changed body: (m,) -> (n,), (N, m) -> (N, n) [m]."""
        arr = np.asarray(q, dtype=float)
        if arr.ndim == 2:
            return np.array([self.chain.forward(qi) for qi in arr]).reshape(arr.shape[0], self.n_task)
        return self.chain.forward(arr)

    def clip(self, q: ArrayLike) -> NDArray[np.float64]:
        """Posture(s) clipped to the joint limits."""
        return np.clip(np.asarray(q, dtype=float), self.lower, self.upper)

    def check_targets(self, targets: ArrayLike, what: str = "targets") -> NDArray[np.float64]:
        """Validate targets: (N, n) finite points [m]."""
        return check.points(what, targets, self.n_task)

    def auto_targets(self) -> NDArray[np.float64]:
        """The base robot's ``"auto"`` grid.

        Raises:
            InvalidArgumentError: the base has none.
        """
        if not hasattr(self.base, "auto_targets"):
            raise InvalidArgumentError(f"{self.name!r} has no target set: pass targets=")
        return np.asarray(self.base.auto_targets(), dtype=float)

    def __repr__(self) -> str:
        return f"ChangedBody({self.name!r}, {self.n_joints} joints, {self.n_task} task axes)"


def _chain(robot: Any) -> KinematicChain:
    chain = getattr(robot, "chain", None)
    if not isinstance(chain, KinematicChain):
        raise InvalidArgumentError(
            f"robot must have a compiled kinematic chain (a KinematicTarget), got {robot!r}"
        )
    return chain


def scaled(robot: Any, factor: float | ArrayLike, *, targets: ArrayLike | None = None) -> ChangedBody:
    """Growth: every link (the placements between moved joints, and the frame's offset) times ``factor``.

    The first joint's placement (where the arm is mounted) is kept.

    Args:
        robot: the robot.
        factor: > 0, one number or one per link (m: joints 1..m-1 and the frame).
        targets: the grown body's target set [m]; default the robot's.

    Raises:
        InvalidArgumentError: a factor <= 0, of the wrong length, or a robot without a chain.
    """
    chain = _chain(robot)
    m = chain.n_joints
    try:
        f = np.array(np.broadcast_to(np.asarray(factor, dtype=float), (m,)))
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(
            f"factor must be a number or {m} numbers (one per link), got {factor!r}"
        ) from exc
    if not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise InvalidArgumentError(f"factor must be > 0, got {f.tolist()}")
    translations = chain.translations.copy()
    translations[1:] *= f[:-1, None]
    new = dataclasses.replace(
        chain, translations=translations, frame_translation=chain.frame_translation * f[-1]
    )
    label = f"{float(f[0]):g}" if np.all(f == f[0]) else "links"
    return ChangedBody(robot, new, f"{robot.name} scaled x{label}", targets)


def with_tool(robot: Any, offset: float | ArrayLike, *, targets: ArrayLike | None = None) -> ChangedBody:
    """A tool: the operational frame moved by ``offset`` in its parent joint's frame [m].

    Args:
        robot: the robot.
        offset: a (3,) vector [m], or a length [m] along the frame's own offset (for a planar
            arm: the last link lengthened by that much).
        targets: the body's target set [m]; default the robot's.

    Raises:
        InvalidArgumentError: a bad offset, or a scalar offset where the frame has none.
    """
    chain = _chain(robot)
    arr = np.asarray(offset, dtype=float)
    if arr.ndim == 0:
        t = chain.frame_translation
        norm = float(np.linalg.norm(t))
        if norm == 0.0:
            raise InvalidArgumentError("a tool length needs a frame with an offset: give a (3,) offset")
        vec = t / norm * float(arr)
    else:
        vec = check.vector("offset", arr, 3)
    if not np.all(np.isfinite(vec)):
        raise InvalidArgumentError(f"offset must be finite, got {offset!r}")
    new = dataclasses.replace(chain, frame_translation=chain.frame_translation + vec)
    return ChangedBody(robot, new, f"{robot.name} with tool", targets)


def locked(robot: Any, joint: int, value: float, *, targets: ArrayLike | None = None) -> ChangedBody:
    """An injury: joint ``joint`` (index into q) stuck at ``value`` ([rad] or [m]); q's entry is ignored.

    Raises:
        InvalidArgumentError: a bad joint index or a non-finite value.
    """
    chain = _chain(robot)
    j = check.positive_int("joint", joint, minimum=0)
    if j >= chain.n_joints:
        raise InvalidArgumentError(f"joint must be in 0..{chain.n_joints - 1}, got {joint!r}")
    v = float(value)
    if not math.isfinite(v):
        raise InvalidArgumentError(f"value must be finite, got {value!r}")
    rows = np.flatnonzero(chain.q_index == j)
    rotations, translations = chain.rotations.copy(), chain.translations.copy()
    axes, kinds = chain.axes.copy(), chain.kinds.copy()
    for i in rows:
        a = axes[i]
        if kinds[i] == REVOLUTE:
            rotations[i] = rotations[i] @ _rotation(a, v)
        else:
            translations[i] = translations[i] + rotations[i] @ (a * v)
        axes[i] = 0.0  # a prismatic joint along no axis: q has no effect
        kinds[i] = PRISMATIC
    new = dataclasses.replace(chain, rotations=rotations, translations=translations, axes=axes, kinds=kinds)
    return ChangedBody(robot, new, f"{robot.name} joint {j} locked", targets)


def _rotation(axis: NDArray[np.float64], angle: float) -> NDArray[np.float64]:
    """Rodrigues' rotation about a unit axis, as the compiled joints compute it."""
    x, y, z = axis
    s, c = math.sin(angle), math.cos(angle)
    v = 1.0 - c
    return np.array([
        [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
        [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
        [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
    ])  # fmt: skip
