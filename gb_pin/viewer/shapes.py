"""The meshcat objects the scene draws itself: spheres, cylinders, point clouds, line segments.

Each helper returns a meshcat command for a path given as a string (e.g.
``"/meshcat/gb_pin/robot/j1/joint"``), ready for ``window.send``. (A robot's meshes
are loaded by pinocchio's ``MeshcatVisualizer`` instead: :mod:`gb_pin.viewer.meshes`.)
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
from numpy.typing import NDArray

with warnings.catch_warnings():
    # meshcat 0.3.2 imports its zmq server, which imports a module pyzmq deprecated.
    warnings.simplefilter("ignore", DeprecationWarning)
    import meshcat.geometry as mg
    from meshcat.commands import Delete, SetObject, SetTransform
    from meshcat.path import Path


def node(path: str) -> Any:
    """meshcat Path of an absolute path string."""
    return Path(tuple(s for s in path.split("/") if s))


def delete(path: str) -> Any:
    """Command deleting ``path`` and everything under it."""
    return Delete(node(path))


def place(path: str, T: NDArray[np.float64]) -> Any:
    """Command setting the transform of ``path`` (relative to its parent)."""
    return SetTransform(T, node(path))


def lambert(color: int, opacity: float | None = None) -> Any:
    """A shaded material; ``opacity``: transparent with that opacity, None: opaque.

    One material may be shared by several objects (a figure's joints share one).
    """
    if opacity is None:
        return mg.MeshLambertMaterial(color=color)
    return mg.MeshLambertMaterial(color=color, opacity=opacity, transparent=True)


def sphere(path: str, radius: float, material: Any) -> Any:
    """Command drawing a sphere of ``material`` (see :func:`lambert`)."""
    return SetObject(mg.Sphere(radius), material, node(path))


def cylinder(path: str, length: float, radius: float, material: Any) -> Any:
    """Command drawing a cylinder of ``material`` along the y-axis, centred on the origin of ``path``."""
    return SetObject(mg.Cylinder(length, radius), material, node(path))


def segments(path: str, points: NDArray[np.float64], color: int, opacity: float = 1.0) -> Any:
    """Command drawing line segments between consecutive pairs of (2S, 3) endpoints."""
    material = mg.LineBasicMaterial(color=color, opacity=opacity, transparent=opacity < 1.0)
    return SetObject(
        mg.LineSegments(mg.PointsGeometry(points.astype(np.float32).T), material), path=node(path)
    )


def points(path: str, points: NDArray[np.float64], color: int, size: float) -> Any:
    """Command drawing (N, 3) points (meshcat's PointsMaterial always uses vertex colours: each gets one)."""
    rgb = np.array([(color >> 16) & 255, (color >> 8) & 255, color & 255], dtype=np.float32) / 255.0
    colors = np.tile(rgb, (points.shape[0], 1))
    geometry = mg.PointsGeometry(points.astype(np.float32).T, color=colors.T)
    return SetObject(mg.Points(geometry, mg.PointsMaterial(size=size, color=color)), path=node(path))
