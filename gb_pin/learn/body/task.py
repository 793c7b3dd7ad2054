"""Task maps: from the joint frames of a posture to the task vector x the learner sees.

The paper's x is "the effector pose" in general; gb_pin's first task map is the position
of one frame on chosen world axes (:class:`FramePosition`); :class:`StackedTask` stacks
positions, orientations and pointing directions of one or several frames into one x
(:mod:`gb_pin.learn.body.components`). A task map is a small Python object
(:class:`TaskMap`) that describes itself as plain arrays for the compiled
:func:`task_forward`: :class:`TaskArrays` for the paper's position task,
:class:`StackedTaskArrays` for stacked ones. Each array type gets its own compiled
specialisation (numba types ``task_forward`` by the class of its argument), so that a run of
the paper's task compiles none of the stacked code; a new kind of task adds its arrays and
an implementation here, and nothing in the babbling loop.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, NamedTuple

import numpy as np
from numba import types
from numba.extending import overload
from numpy.typing import NDArray

from gb_pin._jit import OVERLOAD_OPTIONS, njit
from gb_pin.learn.body.components import TaskComponents, component_errors_into, components_forward

FRAME_POSITION = 0
STACKED = 1


class TaskArrays(NamedTuple):
    """The paper's task map, one frame's position on world axes, as arrays for :func:`task_forward`.

    Attributes:
        kind: ``FRAME_POSITION``.
        frame_parent: index of the joint carrying the frame, -1 for the world.
        frame_translation: (3,) position of the frame in its parent joint [m].
        axes: (n,) int64, the world coordinates (0=x, 1=y, 2=z) of x.
    """

    kind: int
    frame_parent: int
    frame_translation: NDArray[np.float64]
    axes: NDArray[np.int64]


class StackedTaskArrays(NamedTuple):
    """A stacked task map as arrays for :func:`task_forward`.

    Attributes:
        kind: ``STACKED``.
        component_*: the fields of :class:`~gb_pin.learn.body.components.TaskComponents`.
    """

    kind: int
    component_kinds: NDArray[np.int64]
    component_parents: NDArray[np.int64]
    component_translations: NDArray[np.float64]
    component_rotations: NDArray[np.float64]
    component_references: NDArray[np.float64]
    component_directions: NDArray[np.float64]
    component_axes: NDArray[np.int64]
    component_sizes: NDArray[np.int64]
    component_scales: NDArray[np.float64]


def _component_arrays(components: TaskComponents) -> tuple[Any, ...]:
    return tuple(getattr(components, name) for name in TaskComponents.FIELDS)


class TaskMap(ABC):
    """What the learner's task vector x is, as a function of the joint frames."""

    @property
    @abstractmethod
    def n_task(self) -> int:
        """The task dimension n."""

    @abstractmethod
    def arrays(self) -> TaskArrays | StackedTaskArrays:
        """The map as arrays for the compiled :func:`task_forward`."""


class FramePosition(TaskMap):
    """The position of one frame on chosen world axes [m] (the paper's task).

    Args:
        frame_parent: index of the joint carrying the frame, -1 for the world.
        frame_translation: (3,) position of the frame in that joint's frame [m].
        axes: the world coordinates (0=x, 1=y, 2=z) the learner sees, in order.
    """

    def __init__(self, frame_parent: int, frame_translation: NDArray[np.float64], axes: NDArray[np.int64]):
        self.frame_parent = int(frame_parent)
        self.frame_translation = np.ascontiguousarray(frame_translation, dtype=np.float64)
        self.axes = np.ascontiguousarray(axes, dtype=np.int64)

    @property
    def n_task(self) -> int:
        """The number of axes."""
        return int(self.axes.shape[0])

    def arrays(self) -> TaskArrays:
        """``TaskArrays(FRAME_POSITION, ...)``."""
        return TaskArrays(FRAME_POSITION, self.frame_parent, self.frame_translation, self.axes)


class StackedTask(TaskMap):
    """Positions, orientations and pointing directions of frames, stacked into one x.

    Units: [m] for position rows, [m] = s [m/rad] x [rad] for rotational rows (see
    :mod:`gb_pin.learn.body.components`).

    Args:
        components: the components as arrays.
    """

    def __init__(self, components: TaskComponents):
        self.components = components

    @property
    def n_task(self) -> int:
        """The rows of all components."""
        return self.components.n_task

    def arrays(self) -> StackedTaskArrays:
        """``StackedTaskArrays(STACKED, ...)``."""
        return StackedTaskArrays(STACKED, *_component_arrays(self.components))


def task_forward(task: Any, rot_ws: Any, pos_ws: Any, out: Any) -> None:
    """The task vector x into ``out`` (n,) from the joint frames of :func:`joints_forward` (Eq. 1).

    Called from compiled code only: numba picks the implementation by the class of ``task``
    (:class:`TaskArrays` or :class:`StackedTaskArrays`) when it compiles the caller.
    """
    raise TypeError("task_forward runs inside compiled code (see body_forward)")


@overload(task_forward, jit_options={"nogil": True, "error_model": "numpy"}, inline="always")
def _task_forward(task, rot_ws, pos_ws, out):  # type: ignore[no-untyped-def]
    if isinstance(task, types.BaseNamedTuple) and task.instance_class is StackedTaskArrays:
        return lambda task, rot_ws, pos_ws, out: components_forward(task, rot_ws, pos_ws, out)
    return lambda task, rot_ws, pos_ws, out: _frame_position(task, rot_ws, pos_ws, out)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _frame_position(task, rot_ws, pos_ws, out):  # type: ignore[no-untyped-def]
    f = task.frame_parent
    axes = task.axes
    t = task.frame_translation
    if f >= 0:
        r = rot_ws[f]
        for a in range(axes.shape[0]):
            k = axes[a]
            out[a] = pos_ws[f, k] + r[k, 0] * t[0] + r[k, 1] * t[1] + r[k, 2] * t[2]
    else:
        for a in range(axes.shape[0]):
            out[a] = t[axes[a]]


def add_component_errors(task: Any, target: Any, reached: Any, acc: Any) -> None:
    """Add each component's error ||x*[r_c] - x[r_c]|| / s_c to ``acc`` (C,): [m], or [deg] for rotations.

    A no-op for the paper's position task (its one component is E^X itself). Compiled code only.
    """
    raise TypeError("add_component_errors runs inside compiled code")


@overload(add_component_errors, jit_options=OVERLOAD_OPTIONS)
def _add_component_errors(task, target, reached, acc):  # type: ignore[no-untyped-def]
    if isinstance(task, types.BaseNamedTuple) and task.instance_class is StackedTaskArrays:
        return lambda task, target, reached, acc: component_errors_into(task, target, reached, acc)
    return lambda task, target, reached, acc: None
