"""The robot drawn with its visual meshes, loaded by pinocchio's ``MeshcatVisualizer``.

The viewer's only Pinocchio user: meshes hang on the joints of the target's *full*
model (locked joints included), which the learner's chain does not describe, and
pinocchio places them. Loaded only when a robot with meshes is drawn
(:func:`gb_pin.viewer.figure.make_figure`).
"""

from __future__ import annotations

import itertools
import warnings
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from gb_pin.viewer.geometry import Transforms
from gb_pin.viewer.stick import StickFigure
from gb_pin.viewer.style import ROBOT

with warnings.catch_warnings():
    # meshcat 0.3.2 imports its zmq server, which imports a module pyzmq deprecated.
    warnings.simplefilter("ignore", DeprecationWarning)
    import meshcat

if TYPE_CHECKING:
    from gb_pin.robot.target import KinematicTarget
    from gb_pin.viewer.commands import Window


def _local_box(geometry: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """(min, max) corners of a geometry's bounding box in its own frame [m], or None if it has none."""
    try:
        geometry.computeLocalAABB()
        box = geometry.aabb_local
        lo, hi = np.asarray(box.min_, dtype=float), np.asarray(box.max_, dtype=float)
    except (AttributeError, RuntimeError, TypeError):
        return None
    return (lo, hi) if np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(hi >= lo) else None


class MeshFigure(StickFigure):
    """A robot drawn with its visual meshes, loaded by pinocchio's ``MeshcatVisualizer``.

    The meshes belong to the target's full model (``target.full_model`` where the
    target has one: locked joints stay at the reference posture), else to
    ``target.model``. Their placements come from ``pinocchio.updateGeometryPlacements``,
    so live frames and replay keyframes are computed alike. The operational frame
    keeps its sphere marker.

    Args:
        target: the robot.
        visual_model: the ``pin.GeometryModel`` of visual meshes of that model.
        root: meshcat path of the figure.
    """

    def __init__(self, target: KinematicTarget, visual_model: Any, root: str = ROBOT) -> None:
        super().__init__(target, root)
        self.mesh_model = getattr(target, "full_model", target.model)
        self.mesh_data = self.mesh_model.createData()
        configure = getattr(target, "full_configuration", None)
        self._configure = configure if callable(configure) else target.to_pinocchio
        self.visual_model = visual_model
        self.visual_data = visual_model.createData()

    def load(self, window: Window) -> None:
        """Load the meshes through pinocchio's MeshcatVisualizer (its camera helpers are not used)."""
        from pinocchio.visualize import MeshcatVisualizer

        viz = MeshcatVisualizer(self.mesh_model, None, self.visual_model)
        viz.initViewer(viewer=meshcat.Visualizer(window=window))
        viz.loadViewerModel(rootNodeName=self.root.removeprefix("/meshcat/"))
        window.send(self.effector_marker())

    def outline(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """(P, 3) points the camera frames: the links' endpoints and every mesh's bounding-box corners.

        The learner's chain holds the moved joints only (a humanoid's arm); the meshes hang on the
        full model, head and feet included, which the camera must show whole.
        """
        points = [self.skeleton(q)]
        unit = np.array(list(itertools.product((0.0, 1.0), repeat=3)))
        for (_, T), obj in zip(self.transforms(q), self.visual_model.geometryObjects, strict=False):
            box = _local_box(obj.geometry)
            if box is None:  # a geometry without a bounding box: its origin
                points.append(T[None, :3, 3])
                continue
            corners = box[0] + unit * (box[1] - box[0])
            points.append(corners @ T[:3, :3].T + T[:3, 3])
        return np.vstack(points)

    def transforms(self, q: NDArray[np.float64]) -> Transforms:
        """(path, world transform) of each visual mesh and of the frame marker at ``q``."""
        pin.forwardKinematics(self.mesh_model, self.mesh_data, self._configure(q))
        pin.updateGeometryPlacements(self.mesh_model, self.mesh_data, self.visual_model, self.visual_data)
        out: Transforms = []
        for gid, obj in enumerate(self.visual_model.geometryObjects):
            T = self.visual_data.oMg[gid].homogeneous.copy()
            T[:3, :3] = T[:3, :3] * np.asarray(obj.meshScale, dtype=float)[None, :]
            out.append((f"{self.root}/visuals/{obj.name}", T))
        out.append(self.effector_transform(q))
        return out
