"""How a robot is drawn: its meshes where it has some (:mod:`gb_pin.viewer.meshes`), else a stick figure.

The mesh module, and with it Pinocchio, is loaded only when meshes are drawn.
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Any

from gb_pin.exceptions import GbPinError, ViewerWarning
from gb_pin.viewer.stick import StickFigure

if TYPE_CHECKING:
    from gb_pin.robot.target import KinematicTarget


def make_figure(target: KinematicTarget, visual_model: Any | None = None) -> StickFigure:
    """How to draw ``target``: its meshes where there are some, else a stick figure.

    A robot without a kinematic chain (a forward function) is drawn as its effector only
    (:class:`~gb_pin.viewer.point.PointFigure`).

    Args:
        target: the robot.
        visual_model: a ``pin.GeometryModel``; None: the target's own meshes
            (``target.visual_model()``) if it has any; False: always a stick figure.

    Warns:
        ViewerWarning: the target's meshes cannot be loaded (it is drawn as a stick figure).
    """
    if getattr(target, "chain", None) is None:
        from gb_pin.viewer.point import PointFigure

        return PointFigure(target)  # type: ignore[return-value]  # the same interface, duck-typed
    if visual_model is False:
        return StickFigure(target)
    if visual_model is None:
        loader = getattr(target, "visual_model", None)
        if callable(loader) and getattr(target, "urdf", None) is not None:
            try:
                visual_model = loader()
            except GbPinError as exc:
                warnings.warn(
                    f"{exc}; drawing {target.name!r} as a stick figure", ViewerWarning, stacklevel=3
                )
        elif loader is not None and not callable(loader):
            visual_model = loader
        # else: built from a pin.Model (e.g. a planar chain): no meshes to load
    if visual_model is not None and len(visual_model.geometryObjects) > 0:
        from gb_pin.viewer.meshes import MeshFigure

        return MeshFigure(target, visual_model)
    return StickFigure(target)
