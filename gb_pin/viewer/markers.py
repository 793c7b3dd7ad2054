"""Markers in task space: the target set X*, the current target x*_t, the fading trail of reached points.

The target set is drawn once (points, and the grid's edges where X* is a regular
grid). The current target and the trail move at every frame: :class:`Markers` keeps
their state and turns a frame into encoded commands, sending a visibility change only
when it changes.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from gb_pin.viewer import shapes
from gb_pin.viewer.commands import Encoded, property_message, transform_message
from gb_pin.viewer.geometry import grid_edges, grid_shape, translation
from gb_pin.viewer.style import EFFECTOR_COLOR, TARGET, TARGET_COLOR, TARGET_SET, TARGET_SET_COLOR, TRAIL

if TYPE_CHECKING:
    from gb_pin.viewer.commands import Window


def draw_target_set(
    window: Window, targets: NDArray[np.float64], points3: NDArray[np.float64], size: float
) -> None:
    """Draw the target set X*: its points, and the edges between neighbours where it is a regular grid.

    Args:
        window: where commands go.
        targets: (N, n) target set on the task axes [m] (its grid structure).
        points3: (N, 3) where each target is drawn [m].
        size: a length of the robot's scale (the points' size is a fraction of it) [m].
    """
    window.send(shapes.points(f"{TARGET_SET}/points", points3, TARGET_SET_COLOR, 0.012 * size))
    shape = grid_shape(targets)
    if shape is not None:
        e = grid_edges(shape)
        window.send(shapes.segments(f"{TARGET_SET}/grid", points3[e.ravel()], TARGET_SET_COLOR, 0.6))


class Markers:
    """The current target x*_t (a sphere, hidden while there is none) and the trail of reached points.

    Args:
        window: where commands go.
        radius: radius of the target sphere [m]; trail spheres are smaller and fade.
        trail: number of trail spheres (past reached positions).
    """

    def __init__(self, window: Window, radius: float, trail: int) -> None:
        self.window = window
        self.radius = radius
        self.trail = trail
        self._trail: list[NDArray[np.float64]] = []
        self._trail_shown = 0
        self._target_shown: bool | None = None

    def load(self) -> None:
        """Send the spheres (once); the trail's stay hidden until they have a position."""
        w = self.window
        w.send(shapes.sphere(f"{TARGET}/sphere", self.radius, shapes.lambert(TARGET_COLOR)))
        for k in range(self.trail):
            fade = 1.0 - k / max(self.trail, 1)
            radius = self.radius * (0.35 + 0.35 * fade)
            material = shapes.lambert(EFFECTOR_COLOR, opacity=0.15 + 0.6 * fade)
            w.send(shapes.sphere(f"{TRAIL}/t{k}/sphere", radius, material))
            w.send_encoded(*property_message(f"{TRAIL}/t{k}", "visible", False))

    @staticmethod
    def target_transform(target3: NDArray[np.float64]) -> tuple[str, NDArray[np.float64]]:
        """(path, transform) placing the current-target sphere at ``target3`` [m]."""
        return TARGET, translation(target3)

    def visibility(self, show_target: bool) -> list[Encoded]:
        """The command showing or hiding the current target, if that changes."""
        if show_target == self._target_shown:
            return []
        self._target_shown = show_target
        return [property_message(TARGET, "visible", show_target)]

    def reach(self, reached3: NDArray[np.float64]) -> list[Encoded]:
        """Commands moving the trail one step: ``reached3`` [m] first, the older points behind it."""
        if self.trail <= 0:
            return []
        self._trail.insert(0, reached3)
        del self._trail[self.trail :]
        batch = [transform_message(f"{TRAIL}/t{k}", translation(p3)) for k, p3 in enumerate(self._trail)]
        # Each sphere is shown once, when it first has a position.
        while self._trail_shown < len(self._trail):
            batch.append(property_message(f"{TRAIL}/t{self._trail_shown}", "visible", True))
            self._trail_shown += 1
        return batch
