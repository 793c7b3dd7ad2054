"""Task maps: from the joint frames of a posture to the task vector x the learner sees.

The paper's x is "the effector pose" in general; gb_pin's first task map is the position
of one frame on chosen world axes (:class:`FramePosition`). A task map is a small Python
object (:class:`TaskMap`) that describes itself as plain arrays (:class:`TaskArrays`) for
the compiled :func:`task_forward`, which dispatches on ``TaskArrays.kind``; a new kind of
task (an orientation, several frames) adds a kind code, its arrays and a branch here, and
nothing in the babbling loop.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import NamedTuple

import numpy as np
from numba import njit
from numpy.typing import NDArray

FRAME_POSITION = 0


class TaskArrays(NamedTuple):
    """A task map as arrays for :func:`task_forward`.

    Attributes:
        kind: which task map (``FRAME_POSITION``).
        frame_parent: index of the joint carrying the frame, -1 for the world.
        frame_translation: (3,) position of the frame in its parent joint [m].
        axes: (n,) int64, the world coordinates (0=x, 1=y, 2=z) of the task vector.
    """

    kind: int
    frame_parent: int
    frame_translation: NDArray[np.float64]
    axes: NDArray[np.int64]


class TaskMap(ABC):
    """What the learner's task vector x is, as a function of the joint frames."""

    @property
    @abstractmethod
    def n_task(self) -> int:
        """The task dimension n."""

    @abstractmethod
    def arrays(self) -> TaskArrays:
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


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def task_forward(task, rot_ws, pos_ws, out):  # type: ignore[no-untyped-def]
    """The task vector x into ``out`` (n,) from the joint frames of :func:`joints_forward` (Eq. 1)."""
    if task.kind == FRAME_POSITION:
        _frame_position(task, rot_ws, pos_ws, out)


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
