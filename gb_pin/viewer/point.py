"""A robot without a kinematic chain drawn as its effector only: a sphere where ``forward(q)`` puts it.

A :class:`~gb_pin.robot.function.FunctionTarget` (a forward function: a continuum arm, a simulator)
has no joints to draw. Its scenes still show what goal babbling is about, all in task space: the
target set, the current goal, the trail, the reached grid f(g(x*)), and the effector, a sphere at
f(q) on the first task axes (x, y, z: a task of more than three dimensions cannot be drawn).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import ViewerError
from gb_pin.viewer import shapes
from gb_pin.viewer.geometry import Transforms, translation
from gb_pin.viewer.style import EFFECTOR_COLOR, ROBOT


class PointFigure:
    """The effector of a robot given as a function, the only part of it the viewer can draw.

    Args:
        target: a robot with ``forward(q)`` (n <= 3 task coordinates), ``home`` and ``targets``.
        root: meshcat path of the figure.

    Raises:
        ViewerError: a task of more than three coordinates.
    """

    def __init__(self, target: Any, root: str = ROBOT) -> None:
        self.target = target
        self.root = root
        x = np.asarray(target.forward(target.home), dtype=float)
        if x.ndim != 1 or not 1 <= x.shape[0] <= 3:
            raise ViewerError(
                f"{target.name!r} has {x.size} task coordinates: the viewer draws at most 3 (x, y, z)"
            )
        self.n_task = x.shape[0]
        points = [x[None, :]]
        if getattr(target, "targets", None) is not None:
            points.append(np.atleast_2d(np.asarray(target.targets, dtype=float)))
        cloud = np.vstack(points)
        extent = float(np.max(np.ptp(cloud, axis=0))) if cloud.shape[0] > 1 else 0.0
        self.size = extent if extent > 0 else 1.0  # the scale of the scene's points and spheres
        self.effector_radius = 0.02 * self.size
        self.n_joints = 0

    @property
    def effector_path(self) -> str:
        """meshcat path of the effector's sphere."""
        return f"{self.root}/effector"

    def load(self, window: Any) -> None:
        """Send the effector's sphere (once)."""
        window.send(
            shapes.sphere(
                f"{self.effector_path}/sphere", self.effector_radius, shapes.lambert(EFFECTOR_COLOR)
            )
        )

    def effector(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """3-D position of the effector at ``q`` [m] (task coordinates on x, y, z; the others 0)."""
        out = np.zeros(3)
        out[: self.n_task] = np.asarray(self.target.forward(np.asarray(q, dtype=float)), dtype=float)
        return out

    def transforms(self, q: NDArray[np.float64]) -> Transforms:
        """The effector's (path, world transform) at ``q``: the only moving node."""
        return [(self.effector_path, translation(self.effector(q)))]

    def skeleton(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """(2, 3): a zero-length "link" at the effector (a posture has nothing else to draw) [m]."""
        p = self.effector(q)
        return np.stack([p, p])

    def outline(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """(1, 3) points the camera frames at ``q``: the effector [m]."""
        return self.effector(q)[None, :]
