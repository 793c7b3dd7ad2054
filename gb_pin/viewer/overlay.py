"""The paper's Fig. 3 overlay: the reached grid f(g(x*)) and the postures g(x*) of a few targets.

Drawn under :data:`~gb_pin.viewer.style.OVERLAY`, so that it can be hidden as one
(a replay hides it: the final model would contradict the early movements replayed).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from gb_pin.viewer import shapes
from gb_pin.viewer.geometry import grid_edges, grid_shape, spread_indices
from gb_pin.viewer.style import OVERLAY, POSTURE_COLOR, REACHED_COLOR

if TYPE_CHECKING:
    from gb_pin.viewer.commands import Window
    from gb_pin.viewer.stick import StickFigure


def draw_overlay(
    window: Window,
    figure: StickFigure,
    targets: NDArray[np.float64],
    targets3: NDArray[np.float64],
    postures: NDArray[np.float64],
    *,
    few: int = 5,
    offset: NDArray[np.float64] | None = None,
    size: float | None = None,
) -> dict[str, NDArray[np.float64]]:
    """Draw the reached grid f(g(x*)) and the postures g(x*) for ``few`` targets spread over X*.

    Args:
        window: where commands go.
        figure: the robot's figure (its forward kinematics and skeleton).
        targets: (N, n) target set X* on the task axes [m].
        targets3: (N, 3) where each target is drawn [m].
        postures: (N, m) estimates g(x*) for the target set.
        few: number of postures drawn.
        offset: (3,) shift of everything drawn (e.g. away from the camera) [m].
        size: the length the points' size is a fraction of [m]; default the robot's size.

    Returns:
        The drawn arrays (``reached`` (N, 3), ``skeletons`` (few, 2S, 3)), without the offset.
    """
    below = np.zeros(3) if offset is None else offset
    postures = np.atleast_2d(postures)
    reached = np.array([figure.effector(q) for q in postures])
    window.send(
        shapes.points(
            f"{OVERLAY}/reached_points", reached + below, REACHED_COLOR, 0.014 * (size or figure.size)
        )
    )
    shape = grid_shape(targets)
    if shape is not None:
        e = grid_edges(shape)
        segs = reached[e.ravel()]
    else:
        # No grid: join each target to where its estimate reaches.
        segs = np.stack([targets3, reached], axis=1).reshape(-1, 3)
    window.send(shapes.segments(f"{OVERLAY}/reached_grid", segs + below, REACHED_COLOR))
    chosen = spread_indices(targets, few)
    skeletons = np.array([figure.skeleton(postures[i]) for i in chosen])
    window.send(shapes.segments(f"{OVERLAY}/postures", skeletons.reshape(-1, 3) + below, POSTURE_COLOR, 0.7))
    return {"reached": reached, "skeletons": skeletons}
