"""The body the learner babbles with: compiled forward kinematics f(q) of one task map.

The babbling loop runs hundreds of millions of steps and cannot call Pinocchio per
step. :class:`KinematicChain` holds what f needs as plain arrays (joint parents,
placements, axes and kinds; the frame and the task axes), filled from a ``pin.Model`` on
the robot side (:mod:`gb_pin.robot.chain_reader`), so that Pinocchio stays the single
source of the robot. :meth:`KinematicChain.kernel` gives the compiled form
(:class:`Body`, evaluated by :func:`body_forward`), tested against
``pin.framesForwardKinematics``; :meth:`KinematicChain.forward_kernel` the closed form of a
chain whose joints turn about parallel axes (:class:`~gb_pin.learn.body.planar.PlanarBody`),
which the babbling loop uses when the chain allows it.

This module imports neither pinocchio nor meshcat: the learner uses it.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from functools import cached_property
from typing import Any, NamedTuple

import numpy as np
from numba import types
from numba.extending import overload
from numpy.typing import NDArray

from gb_pin._jit import NO_REFCOUNT, njit
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.body.components import TaskComponents
from gb_pin.learn.body.joints import PRISMATIC, REVOLUTE, Joints, joints_forward
from gb_pin.learn.body.planar import PlanarBody, parallel_axes, planar_forward
from gb_pin.learn.body.task import (
    FramePosition,
    StackedTask,
    StackedTaskArrays,
    TaskArrays,
    TaskMap,
    task_forward,
)

__all__ = ["PRISMATIC", "REVOLUTE", "Body", "KinematicChain", "PlanarBody", "body_forward"]


class Body(NamedTuple):
    """Compiled forward kinematics with its scratch buffers (what :func:`body_forward` takes).

    Attributes:
        joints: the kinematic tree.
        task: the task map.
        rot_ws: (m, 3, 3) scratch, receives each joint's world rotation.
        pos_ws: (m, 3) scratch, receives each joint's world position.
    """

    joints: Joints
    task: TaskArrays | StackedTaskArrays
    rot_ws: NDArray[np.float64]
    pos_ws: NDArray[np.float64]


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def body_forward(q, body, out):  # type: ignore[no-untyped-def]
    """x = f(q) into ``out`` (n,) for one posture ``q`` (m,) (Eq. 1).

    ``body``: a :class:`Body` (any chain, any task map) or a :class:`PlanarBody` (the closed form
    of a chain about parallel axes); numba compiles the one its class names.
    """
    _forward(q, body, out)


def _forward(q: Any, body: Any, out: Any) -> None:
    raise TypeError("_forward runs inside compiled code (see body_forward)")


@overload(_forward, jit_options={"nogil": True, "error_model": "numpy"}, inline="always")
def _forward_impl(q, body, out):  # type: ignore[no-untyped-def]
    if isinstance(body, types.BaseNamedTuple) and body.instance_class is PlanarBody:
        return lambda q, body, out: planar_forward(q, body, out)
    return lambda q, body, out: _tree_forward(q, body, out)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _tree_forward(q, body, out):  # type: ignore[no-untyped-def]
    joints_forward(q, body.joints, body.rot_ws, body.pos_ws)
    task_forward(body.task, body.rot_ws, body.pos_ws, out)


@dataclass(frozen=True, eq=False)
class KinematicChain:
    """Arrays describing the forward kinematics of one frame's position, or of a stacked task.

    Joints are numbered 0..m-1 so that every joint's parent comes before it;
    ``q_index`` maps them to entries of the learner's posture vector q. Joint i's frame is
    ``oMi = oMparent * placement_i * motion_i(q_i)``.

    Attributes:
        parents: (m,) int64, index of the parent joint, -1 for the world.
        rotations: (m, 3, 3) rotation of each joint placement in its parent.
        translations: (m, 3) translation of each joint placement in its parent [m].
        axes: (m, 3) unit joint axis in the joint frame.
        kinds: (m,) int64, ``REVOLUTE`` (q in [rad]) or ``PRISMATIC`` (q in [m]).
        q_index: (m,) int64, which entry of the posture vector q drives each joint.
        frame_parent: index of the joint carrying the operational frame, -1 for the world.
        frame_translation: (3,) position of the frame in its parent joint [m].
        task_axes: (n,) int64, which world coordinates (0=x, 1=y, 2=z) the learner sees.
        components: None for the frame-position task above; else the stacked task map the
            learner sees (positions, orientations, pointing directions of frames), and then
            ``frame_parent``, ``frame_translation`` and ``task_axes`` describe its first
            component's frame and position axes (for viewers and reach checks only).
    """

    parents: NDArray[np.int64]
    rotations: NDArray[np.float64]
    translations: NDArray[np.float64]
    axes: NDArray[np.float64]
    kinds: NDArray[np.int64]
    q_index: NDArray[np.int64]
    frame_parent: int
    frame_translation: NDArray[np.float64]
    task_axes: NDArray[np.int64]
    components: TaskComponents | None = None

    @property
    def n_joints(self) -> int:
        """Number of joints m (the posture dimension)."""
        return int(self.parents.shape[0])

    @property
    def n_task(self) -> int:
        """Task dimension n."""
        if self.components is not None:
            return self.components.n_task
        return int(self.task_axes.shape[0])

    @property
    def n_components(self) -> int:
        """Task components C of a stacked task (0 for the paper's position task)."""
        return 0 if self.components is None else self.components.count

    @property
    def joints(self) -> Joints:
        """The kinematic tree as arrays."""
        return Joints(self.parents, self.rotations, self.translations, self.axes, self.kinds, self.q_index)

    @property
    def task(self) -> TaskMap:
        """The task map: the frame's position on :attr:`task_axes`, or the stacked components."""
        if self.components is not None:
            return StackedTask(self.components)
        return FramePosition(self.frame_parent, self.frame_translation, self.task_axes)

    def kernel(self) -> Body:
        """The compiled form, with fresh scratch buffers (every joint frame: Jacobians, viewers)."""
        m = self.n_joints
        return Body(self.joints, self.task.arrays(), np.empty((m, 3, 3)), np.empty((m, 3)))

    def forward_kernel(self) -> Body | PlanarBody:
        """The fastest compiled form of f alone (what the babbling loop evaluates).

        The closed form if every joint turns about one direction
        (:func:`~gb_pin.learn.body.planar.parallel_axes`), else :meth:`kernel`.
        """
        planar = self._planar
        return planar if planar is not None else self.kernel()

    @cached_property
    def _planar(self) -> PlanarBody | None:
        return parallel_axes(self)

    def forward(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """Task-space position of the frame for one posture ``q`` of shape (m,)."""
        q = np.ascontiguousarray(q, dtype=np.float64)
        if q.shape != (self.n_joints,):
            raise InvalidArgumentError(f"q must have shape ({self.n_joints},), got shape {q.shape}")
        out = np.empty(self.n_task)
        body_forward(q, self.forward_kernel(), out)
        return out

    # -- as plain arrays (checkpoints) --------------------------------------------
    def to_arrays(self, prefix: str = "chain_") -> dict[str, NDArray[Any]]:
        """Every field as an array, under ``prefix + name`` (components: ``prefix + "component_" + name``)."""
        out = {
            prefix + f.name: np.asarray(getattr(self, f.name)) for f in fields(self) if f.name != "components"
        }
        if self.components is not None:
            out.update(
                {
                    prefix + "component_" + k: np.asarray(getattr(self.components, k))
                    for k in TaskComponents.FIELDS
                }
            )
        return out

    @classmethod
    def from_arrays(cls, arrays: dict[str, Any], prefix: str = "chain_") -> KinematicChain:
        """The chain written by :meth:`to_arrays`, validated.

        Raises:
            InvalidArgumentError: arrays missing, of the wrong dtype, shape or range.
        """
        try:
            raw = {f.name: np.asarray(arrays[prefix + f.name]) for f in fields(cls) if f.name != "components"}
            stacked = {k: np.asarray(arrays[prefix + "component_" + k]) for k in TaskComponents.FIELDS
                       if prefix + "component_kinds" in arrays}  # fmt: skip
        except KeyError as exc:
            raise InvalidArgumentError(f"kinematic chain incomplete (missing {exc})") from exc
        ints = ("parents", "kinds", "q_index", "task_axes")
        values: dict[str, Any] = {}
        for name, arr in raw.items():
            kind = "iu" if name in ints or name == "frame_parent" else "fiu"
            if arr.dtype.kind not in kind:
                raise InvalidArgumentError(f"kinematic chain: {name} has dtype {arr.dtype}")
            dtype = np.int64 if kind == "iu" else np.float64
            values[name] = np.array(arr, dtype=dtype, order="C")
        if values["frame_parent"].shape != ():
            raise InvalidArgumentError("kinematic chain: frame_parent must be one integer")
        values["frame_parent"] = int(values["frame_parent"])
        if stacked:
            for name, arr in stacked.items():
                if arr.dtype.kind not in ("iu" if name in TaskComponents.INTS else "fiu"):
                    raise InvalidArgumentError(f"kinematic chain: component_{name} has dtype {arr.dtype}")
            values["components"] = TaskComponents(**{  # type: ignore[arg-type]
                k: np.array(a, dtype=np.int64 if k in TaskComponents.INTS else np.float64, order="C")
                for k, a in stacked.items()
            })  # fmt: skip
        chain = cls(**values)
        chain.validate()
        return chain

    def validate(self) -> None:
        """Check shapes and index ranges, so that compiled code never reads out of bounds.

        Raises:
            InvalidArgumentError: inconsistent arrays.
        """
        m = self.parents.shape[0] if self.parents.ndim == 1 else -1
        n = self.task_axes.shape[0] if self.task_axes.ndim == 1 else -1  # a 0-d array in a file
        shapes = {
            "parents": (m,), "rotations": (m, 3, 3), "translations": (m, 3), "axes": (m, 3),
            "kinds": (m,), "q_index": (m,), "frame_translation": (3,), "task_axes": (n,),
        }  # fmt: skip
        for name, shape in shapes.items():
            if np.shape(getattr(self, name)) != shape:
                raise InvalidArgumentError(
                    f"kinematic chain: {name} has shape {np.shape(getattr(self, name))}, expected {shape}"
                )
        ok = (
            m >= 1
            and n >= 1
            and all(-1 <= int(p) < i for i, p in enumerate(self.parents))
            and np.all((self.kinds == REVOLUTE) | (self.kinds == PRISMATIC))
            and np.all((self.q_index >= 0) & (self.q_index < m))
            and -1 <= self.frame_parent < m
            and np.all((self.task_axes >= 0) & (self.task_axes < 3))
            and all(np.all(np.isfinite(a)) for a in (self.rotations, self.translations, self.axes))
            and bool(np.all(np.isfinite(self.frame_translation)))
        )
        if not ok:
            raise InvalidArgumentError(
                "kinematic chain: indices out of range (parents, kinds, q_index, frame_parent or "
                "task_axes) or non-finite placements"
            )
        if self.components is not None:
            problem = self.components.validate(m)
            if problem is not None:
                raise InvalidArgumentError(f"kinematic chain: {problem}")
