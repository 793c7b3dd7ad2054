"""Stacked tasks in the scene: orientation triads, pointing arrows and the other frames' targets.

A stacked task vector (docs/TASKS.md) holds more than one frame's position. The scene
embeds its first position component as the target set (:mod:`~gb_pin.viewer.markers`);
this module draws the rest, for the targets X* (pale colours, under
:data:`~gb_pin.viewer.style.TARGET_SET`) and for what the learned model reaches,
f(g(x*)) (full colours, under :data:`~gb_pin.viewer.style.OVERLAY`):

* an orientation component: a small triad (x red, y green, z blue) of the rotation
  R = R_ref exp(x_rows / s), at its frame's position (or the first position's);
* a pointing component: a segment along the direction d = exp((x_0 u + x_1 v) / s) d0;
* another frame's position component (a second hand): its points.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from gb_pin.learn.body.components import ORIENTATION, POINTING, POSITION
from gb_pin.robot.task_targets import exp3
from gb_pin.viewer import shapes
from gb_pin.viewer.geometry import grid_edges, grid_shape
from gb_pin.viewer.style import OVERLAY, REACHED_COLOR, TARGET_SET, TARGET_SET_COLOR

if TYPE_CHECKING:
    from gb_pin.robot.target import KinematicTarget
    from gb_pin.viewer.commands import Window

AXIS_COLORS = (0xE74C3C, 0x27AE60, 0x2E86DE)
"""Colours of a triad's x, y and z axes."""
PALE_AXIS_COLORS = (0xF5B7B1, 0xA9DFBF, 0xAED6F1)
"""The same, pale, for the targets."""
POINTING_COLOR = 0x8E44AD


@dataclass(frozen=True)
class TaskLayout:
    """Where a stacked task's rows are, for drawing.

    Attributes:
        position_rows: rows of x of the first position component (the scene's target set).
        position_axes: its world axes.
        others: rows of the other 3-axis position components (other frames), in x, y, z order.
        rotations: (kind, rows, anchor rows (x, y, z of a position of the same frame, else of the
            first 3-axis position), scale, reference) of each rotational component.
    """

    position_rows: NDArray[np.int64]
    position_axes: NDArray[np.int64]
    others: tuple[NDArray[np.int64], ...]
    rotations: tuple[tuple[int, NDArray[np.int64], NDArray[np.int64], float, NDArray[np.float64]], ...]

    @classmethod
    def of(cls, target: KinematicTarget) -> TaskLayout:
        """The layout of ``target``'s task (a plain position task: all rows, no extras)."""
        chain = target.chain
        if chain is None:  # a robot given as a function: its task coordinates are x, y, z in order
            n = int(target.n_task)
            return cls(np.arange(n), np.arange(n, dtype=np.int64), (), ())
        comps = chain.components
        if comps is None:
            rows = np.arange(chain.n_task)
            return cls(rows, np.asarray(chain.task_axes, dtype=np.int64), (), ())
        frames = [spec.frame for spec in target.task or ()]
        ranges = [np.arange(comps.rows(c).start, comps.rows(c).stop) for c in range(comps.count)]
        positions = [c for c in range(comps.count) if comps.kinds[c] == POSITION]
        # x[xyz[c]] is the world (x, y, z) position of a 3-axis position component c.
        xyz = {c: ranges[c][np.argsort(comps.axes[c])] for c in positions if comps.sizes[c] == 3}
        rotations = []
        for c in range(comps.count):
            same = [p for p in xyz if frames[p] == frames[c]]
            anchor = xyz[same[0]] if same else next(iter(xyz.values()), None)
            if comps.kinds[c] != POSITION and anchor is not None:  # nowhere to draw it otherwise
                kind, scale = int(comps.kinds[c]), float(comps.scales[c])
                rotations.append((kind, ranges[c], anchor, scale, comps.references[c]))
        first = positions[0]
        return cls(
            ranges[first],
            comps.axes[first, : comps.sizes[first]].astype(np.int64),
            tuple(rows for c, rows in xyz.items() if c != first),
            tuple(rotations),
        )

    @property
    def note(self) -> str:
        """What the extra marks mean, for the legend ("" if there are none)."""
        kinds = {kind for kind, *_ in self.rotations}
        notes = []
        if ORIENTATION in kinds:
            notes.append("triads x, y, z (red, green, blue): target orientations pale, reached bright")
        if POINTING in kinds:
            notes.append("purple: pointing directions (targets, reached)")
        if self.others:
            notes.append("the other frames' targets: grey, reached: blue")
        return "".join(f" · {n}" for n in notes)

    @property
    def stacked(self) -> bool:
        """Whether there is anything beyond the first position to draw."""
        return bool(self.others or self.rotations)


def _axes_of(
    kind: int, rows: NDArray[np.float64], scale: float, reference: NDArray[np.float64]
) -> NDArray[np.float64]:
    """(3, 3) columns to draw: a rotation's axes, or (3 times) the direction of a pointing component."""
    if kind == ORIENTATION:
        return reference @ exp3(rows / scale)
    d0, u, v = reference
    d = exp3((rows[0] * u + rows[1] * v) / scale) @ d0
    return np.stack([d, d, d], axis=1)


def task_segments(
    layout: TaskLayout, X: NDArray[np.float64], length: float
) -> dict[str, NDArray[np.float64]]:
    """Segments (2S, 3) for task vectors X (N, n): ``"x"``, ``"y"``, ``"z"`` (triad axes), ``"pointing"``."""
    out: dict[str, list[NDArray[np.float64]]] = {"x": [], "y": [], "z": [], "pointing": []}
    for kind, rows, anchor, scale, reference in layout.rotations:
        for x in np.atleast_2d(X):
            p = x[anchor]
            axes = _axes_of(kind, x[rows], scale, reference)
            if kind == ORIENTATION:
                for a, key in enumerate("xyz"):
                    out[key].extend([p, p + length * axes[:, a]])
            else:
                out["pointing"].extend([p, p + 1.5 * length * axes[:, 0]])
    return {k: np.array(v).reshape(-1, 3) for k, v in out.items() if v}


def draw_task(
    window: Window,
    layout: TaskLayout,
    X: NDArray[np.float64],
    size: float,
    *,
    reached: bool,
    offset: NDArray[np.float64],
) -> dict[str, NDArray[np.float64]]:
    """Draw the triads, pointing segments and other frames' points of task vectors X (N, n).

    Args:
        window: where commands go.
        layout: the task's rows.
        X: the targets X* (``reached=False``) or the reached f(g(x*)) (``reached=True``).
        size: the robot's scale [m] (triads are a fraction of it).
        reached: which of the two (colours and paths differ).
        offset: (3,) shift of everything drawn [m].

    Returns:
        The segments drawn and the other frames' points (``"others"``, (N * k, 3)), without the offset.
    """
    root = f"{OVERLAY}/task" if reached else f"{TARGET_SET}/task"
    colors = AXIS_COLORS if reached else PALE_AXIS_COLORS
    drawn = task_segments(layout, X, 0.035 * size)
    for key, segs in drawn.items():
        color = POINTING_COLOR if key == "pointing" else colors["xyz".index(key)]
        window.send(shapes.segments(f"{root}/{key}", segs + offset, color, 1.0 if reached else 0.8))
    if layout.others:
        X = np.atleast_2d(X)
        points = np.vstack([X[:, rows] for rows in layout.others])
        color = REACHED_COLOR if reached else TARGET_SET_COLOR
        window.send(shapes.points(f"{root}/others", points + offset, color, 0.008 * size))
        shape = grid_shape(X[:, layout.position_rows])  # the other frames' sets follow the first's grid
        if shape is not None:
            edges = grid_edges(shape).ravel()
            segs = np.vstack([X[:, rows][edges] for rows in layout.others])
            window.send(shapes.segments(f"{root}/others_grid", segs + offset, color, 0.6))
        drawn["others"] = points
    return drawn
