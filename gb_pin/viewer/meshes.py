"""The robot drawn with its visual meshes, loaded by pinocchio's ``MeshcatVisualizer``.

The viewer's only Pinocchio user: meshes hang on the joints of the target's *full*
model (locked joints included), which the learner's chain does not describe, and
pinocchio places them. Loaded only when a robot with meshes is drawn
(:func:`gb_pin.viewer.figure.make_figure`).
"""

from __future__ import annotations

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
