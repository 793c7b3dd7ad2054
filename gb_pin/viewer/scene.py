"""A goal-babbling scene: the robot, the target set, the markers, the Fig. 3 overlay, framed by the camera.

:class:`Scene` composes the parts (the robot's figure, :mod:`~gb_pin.viewer.markers`,
:mod:`~gb_pin.viewer.overlay`, :mod:`~gb_pin.viewer.animation`) in task space: it
embeds task-space points in 3-D, shifts the workspace to the camera's orbit centre and
places the camera. Every drawing becomes meshcat commands sent to a *window*
(:class:`~gb_pin.viewer.commands.Window`), so the same scene goes to a live browser or
into a self-contained HTML file.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin.viewer import shapes
from gb_pin.viewer.animation import animation_command
from gb_pin.viewer.commands import encode, property_message, transform_message
from gb_pin.viewer.figure import make_figure
from gb_pin.viewer.geometry import Transforms, grid_step, spread_indices, translation
from gb_pin.viewer.legend import Legend, legend_command, remove_control
from gb_pin.viewer.markers import Markers, draw_target_set
from gb_pin.viewer.overlay import draw_overlay
from gb_pin.viewer.style import BACKGROUND_BOTTOM, BACKGROUND_TOP, CAMERA_FOV, GOAL_SET, GOAL_SET_COLOR, ROOT
from gb_pin.viewer.task_markers import TaskLayout, draw_task

if TYPE_CHECKING:
    from gb_pin.robot.target import KinematicTarget
    from gb_pin.viewer.commands import Window


MARK_SPACINGS = 8.0
"""Points and spheres are sized as for a robot at most this many target-grid steps long."""
LEGEND_SHIFT = 0.4
"""How far a 3-D scene sits right of the view's centre, a fraction of its extent (the legend is top left)."""


class Scene:
    """A goal-babbling scene: the robot, target set X*, current target, trail, Fig. 3 overlay, camera.

    Args:
        window: where commands go.
        target: the robot.
        targets: (N, n) target set X* on the task axes [m].
        trail: number of trail spheres (past reached positions).
        visual_model: optional ``pin.GeometryModel`` to draw meshes (see
            :func:`~gb_pin.viewer.figure.make_figure`).
        goal_targets: (M, n) the goal set, when it is not ``targets`` (drawn in pink).
    """

    def __init__(
        self,
        window: Window,
        target: KinematicTarget,
        targets: ArrayLike,
        *,
        trail: int = 16,
        visual_model: Any | None = None,
        goal_targets: ArrayLike | None = None,
    ) -> None:
        self.window = window
        # The goal set, drawn when the goals come from another set than ``targets`` (the test set).
        self.goal_targets = (
            None if goal_targets is None else np.atleast_2d(np.asarray(goal_targets, dtype=float))
        )
        self.target = target
        self.targets = np.atleast_2d(np.asarray(targets, dtype=float))
        self.figure = make_figure(target, visual_model)
        self.trail = trail
        # A stacked task (docs/TASKS.md): its first position is embedded, the rest drawn by task_markers.
        self.layout = TaskLayout.of(target)
        self.task_axes = self.layout.position_axes
        self.home3 = self.figure.effector(target.home)
        # Points and spheres are a fraction of the robot's size, but never so big that they hide a
        # grid small for the robot (e.g. 1 cm across a 1 m arm): at most MARK_SPACINGS steps of it.
        step = grid_step(self.embed(self.targets))
        self.mark_size = float(min(self.figure.size, MARK_SPACINGS * step))
        self.figure.effector_radius = min(self.figure.effector_radius, 0.02 * self.mark_size)
        self.marker_radius = self.figure.effector_radius
        self.static = False  # a learned model shown (no current goal, no trail), not a run
        self.markers = Markers(window, self.marker_radius, trail)
        self.center, self.extent = self._bounds()

    # -- geometry ----------------------------------------------------------------------------
    def embed(self, X: ArrayLike) -> NDArray[np.float64]:
        """Task-space points (N, n) as 3-D points: other coordinates from the home effector position.

        For a stacked task, the rows of its first position component.
        """
        X = np.atleast_2d(np.asarray(X, dtype=float))
        out = np.tile(self.home3, (X.shape[0], 1))
        out[:, self.task_axes] = X[:, self.layout.position_rows]
        return out

    def embed_rows(self, X: ArrayLike) -> NDArray[np.float64]:
        """The rows of task vectors (N, n) that :meth:`embed` draws (its grid structure)."""
        return np.atleast_2d(np.asarray(X, dtype=float))[:, self.layout.position_rows]

    def _bounds(self) -> tuple[NDArray[np.float64], float]:
        others = [self.targets[:, rows] for rows in self.layout.others]
        goals = [] if self.goal_targets is None else [self.embed(self.goal_targets)]
        pts = np.vstack(
            [
                self.figure.outline(self.target.home),
                self.embed(self.targets),
                *others,
                *goals,
                np.zeros((1, 3)),
            ]
        )
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        return (lo + hi) / 2.0, float(max(np.max(hi - lo) / 2.0, 0.1 * self.figure.size))

    @property
    def planar_normal(self) -> int | None:
        """The world axis normal to a 2-D task (e.g. 2 = z for ``axes="xy"``), else None."""
        if len(self.task_axes) == 2:
            return int(({0, 1, 2} - set(self.task_axes.tolist())).pop())
        return None

    def _below(self) -> NDArray[np.float64]:
        """A small offset away from the camera, so that flat overlays never hide the robot."""
        off = np.zeros(3)
        normal = self.planar_normal
        off[2 if normal is None else normal] = -0.01 * self.figure.size
        return off

    # -- static scene ----------------------------------------------------------------------------
    def draw_static(self) -> None:
        """Background, camera, robot geometry, target set X* and markers (sent once)."""
        w = self.window
        w.send(shapes.delete(ROOT))  # a viewer reused for another run starts from a clean scene
        w.send_encoded(*property_message("/Background", "top_color", BACKGROUND_TOP))
        w.send_encoded(*property_message("/Background", "bottom_color", BACKGROUND_BOTTOM))
        # Everything is shifted so that the workspace centre sits at the camera's orbit centre (the
        # origin), in 3-D a little to the right of it: the legend box covers the view's top left.
        shift = translation(-self.center + self._beside_legend())
        for p in (ROOT, "/Grid", "/Axes"):
            w.send_encoded(*transform_message(p, shift))
        self._camera()
        if self.planar_normal is None:
            # meshcat's floor grid lies in the world's z = 0 plane, through a humanoid's pelvis (its
            # root frame), not under its feet: seen from the side it crosses the scene. Hidden in 3-D.
            w.send_encoded(*property_message("/Grid", "visible", False))
        self.figure.load(w)
        self.markers.load()
        draw_target_set(
            w, self.embed_rows(self.targets), self.embed(self.targets) + self._below(), self.mark_size
        )
        if self.layout.stacked:
            draw_task(w, self.layout, self.targets, self.figure.size, reached=False, offset=self._below())
        if self.goal_targets is not None:
            self.draw_goal_set(self.goal_targets)
        self.pose(self.target.home, None, None)
        self.label()

    def draw_goal_set(self, goal_targets: ArrayLike) -> None:
        """Draw the goal set (pink points) beside the test set ``targets`` (grey)."""
        self.goal_targets = np.atleast_2d(np.asarray(goal_targets, dtype=float))
        points = self.embed(self.goal_targets) + self._below()
        self.window.send(shapes.points(f"{GOAL_SET}/points", points, GOAL_SET_COLOR, 0.012 * self.mark_size))

    def label(self, status: str = "", overlay_note: str = "") -> None:
        """Draw the legend box over the view: robot, ``status`` (movement, E^X, D^home), colours.

        Args:
            status: the run's state, e.g. :func:`gb_pin.viewer.legend.status_line`.
            overlay_note: a line about the learned model's overlay (shown, hidden, of which movement).
        """
        axes = "".join("xyz"[int(a)] for a in self.task_axes)
        details = f"{self.target.n_joints} joints, task axes {axes}"
        if self.layout.stacked:
            details = f"{self.target.n_joints} joints, task: {'; '.join(self.target.component_labels)}"
            details += self.layout.note
        kind = type(self.figure).__name__
        legend = Legend(
            self.target.name,
            details,
            status,
            overlay_note,
            kind == "MeshFigure",
            self.goal_targets is not None,
            moving=not self.static,
            effector_only=kind == "PointFigure",
        )
        self.window.send(legend_command(legend))
        self.window.send(remove_control())

    def _view_direction(self) -> NDArray[np.float64]:
        """Unit vector from the orbit centre to the camera."""
        normal = self.planar_normal
        if normal is None:
            view = np.array([1.0, -1.2, 0.9])
        else:
            view = np.zeros(3)
            view[normal] = 1.0
            # A hair off-axis: OrbitControls cannot look exactly along its up vector.
            view[1 if normal == 2 else 2] = -1e-3
        return view / np.linalg.norm(view)

    def _beside_legend(self) -> NDArray[np.float64]:
        """The 3-D scene's offset to the screen's right (world z up): :data:`LEGEND_SHIFT` of its extent."""
        if self.planar_normal is not None:
            return np.zeros(3)
        right = np.cross(-self._view_direction(), [0.0, 0.0, 1.0])
        return LEGEND_SHIFT * self.extent * right / np.linalg.norm(right)

    def _camera(self) -> None:
        """Place meshcat's default camera (properties set directly: pinocchio's helpers raise on 0.3.2)."""
        # The arm explores beyond the targets and its home posture: leave a margin around them (and
        # room for the shift beside the legend).
        half = self.extent * (1.5 + LEGEND_SHIFT / 2)
        # Distance at which the vertical field of view spans the workspace (4:3 window or wider).
        dist = half / math.tan(math.radians(CAMERA_FOV / 2.0))
        offset = self._view_direction() * dist
        # meshcat's camera sits in a frame rotated +90 deg about x (three.js is y-up):
        # world (a, b, c) is (a, c, -b) there.
        rotated = [float(offset[0]), float(offset[2]), float(-offset[1])]
        cam = "/Cameras/default/rotated/<object>"
        self.window.send_encoded(*property_message(cam, "position", rotated))
        self.window.send_encoded(*property_message(cam, "near", 0.01 * dist))
        self.window.send_encoded(*property_message(cam, "far", 100.0 * dist))
        self.camera_distance = dist

    # -- frames -------------------------------------------------------------------------------------
    def frame_transforms(
        self, q: NDArray[np.float64], target: NDArray[np.float64] | None
    ) -> tuple[Transforms, NDArray[np.float64]]:
        """Transforms of the robot and the current-target marker, and the 3-D effector position."""
        tf = self.figure.transforms(q)
        effector = tf[-1][1][:3, 3].copy()
        if target is not None and np.all(np.isfinite(target)):
            tf.append(self.markers.target_transform(self.embed(target)[0]))
        return tf, effector

    def pose(
        self, q: NDArray[np.float64], target: NDArray[np.float64] | None, reached: NDArray[np.float64] | None
    ) -> None:
        """Draw one live frame: posture ``q``, target x* (hidden if None or NaN), the trail of reached points.

        The frame's commands go to the window in one batch (one wake-up of the server thread).
        """
        tf, _ = self.frame_transforms(q, target)
        batch = [transform_message(p, T) for p, T in tf]
        batch.extend(self.markers.visibility(target is not None and bool(np.all(np.isfinite(target)))))
        if reached is not None:
            batch.extend(self.markers.reach(self.embed(reached)[0]))
        self.window.send_batch(batch)

    def hide(self, path: str, hidden: bool = True) -> None:
        """Hide (or show) a part of the scene, e.g. :data:`~gb_pin.viewer.style.OVERLAY`."""
        self.window.send_encoded(*property_message(path, "visible", not hidden))

    # -- the learned model ---------------------------------------------------------------------------
    def overlay(self, postures: NDArray[np.float64], few: int = 5) -> dict[str, NDArray[np.float64]]:
        """Draw the paper's Fig. 3: target grid X*, reached grid f(g(x*)), postures g(x*) for ``few`` targets.

        Args:
            postures: (N, m) estimates g(x*) for the target set.
            few: number of postures drawn.

        Returns:
            The drawn arrays (``reached`` (N, 3), ``skeletons`` (few, 2S, 3)), for tests.
        """
        drawn = draw_overlay(
            self.window,
            self.figure,
            self.embed_rows(self.targets),
            self.embed(self.targets),
            postures,
            few=few,
            offset=self._below(),
            size=self.mark_size,
        )
        if self.layout.stacked:  # the reached orientations, directions and other frames' positions
            X = np.array([self.target.chain.forward(q) for q in self.target.clip(np.atleast_2d(postures))])
            task = draw_task(
                self.window, self.layout, X, self.figure.size, reached=True, offset=self._below()
            )
            drawn.update({f"task_{k}": v for k, v in task.items()})
        return drawn

    def show_model(self, postures: NDArray[np.float64], few: int = 5) -> None:
        """Draw a learned model: its Fig. 3 overlay, and the robot at g of the target nearest the centre.

        A model is no run: no current goal, no trail (the legend then lists neither).
        """
        self.static = True
        self.overlay(postures, few=few)
        centre = spread_indices(self.embed_rows(self.targets), 1)[0]
        self.pose(postures[centre], None, None)

    # -- replay animation ----------------------------------------------------------------------------
    def animation(
        self,
        postures: NDArray[np.float64],
        targets: NDArray[np.float64],
        positions: NDArray[np.float64],
        times: NDArray[np.float64],
        fps: float,
        trail_stride: int = 1,
    ) -> dict[str, Any]:
        """A ``set_animation`` command replaying recorded steps (looping forever).

        Args:
            postures: (R, m) executed postures.
            targets: (R, n) targets x*_t, NaN during home returns [m].
            positions: (R, n) reached positions [m].
            times: (R,) keyframe times in frames (e.g. time steps since the first recorded).
            fps: frames per second of playback.
            trail_stride: recorded steps between trail spheres.
        """
        finite = np.all(np.isfinite(targets), axis=1)
        return animation_command(
            self.figure,
            postures,
            self.embed(np.where(finite[:, None], targets, 0.0)),
            finite,
            self.embed(positions),
            times,
            fps,
            trail=self.trail,
            trail_stride=trail_stride,
        )

    def send_animation(self, command: dict[str, Any]) -> None:
        """Send an animation built by :meth:`animation` (floats packed as float32)."""
        self.window.send_encoded(*encode(command, single=True))
