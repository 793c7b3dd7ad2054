"""Seeing the hand with a camera: trackers, cameras, taught goals (the ``vision`` extra: OpenCV).

>>> from gb_pin.vision import ArucoTracker, CameraSensor, Intrinsics, VideoCamera   # doctest: +SKIP
>>> tracker = ArucoTracker(Intrinsics.load("webcam.yaml"), marker_size=0.025, marker_id=7)  # doctest: +SKIP
>>> sensor = CameraSensor(VideoCamera(0), tracker)                               # doctest: +SKIP
>>> x = sensor.read()        # the marker's centre in the camera frame [m], or None  # doctest: +SKIP

Goal babbling needs no model of the arm or of the camera: goals and readings share the camera's
frame, so no hand-eye calibration (extrinsics) is needed (docs/CAMERA.md). The only part of
gb_pin that imports OpenCV (``cv2``); the names are exported lazily (PEP 562), so ``import
gb_pin.vision`` works without it, and a missing OpenCV is one
:class:`~gb_pin.exceptions.CameraError` naming the extra to install.

Modules, one concept each:

- :mod:`~gb_pin.vision.tracker`: :class:`Tracker`, a picture -> the reading or None;
- :mod:`~gb_pin.vision.aruco`: :class:`ArucoTracker` (detect, refine on a crop, solvePnP);
- :mod:`~gb_pin.vision.intrinsics`: :class:`Intrinsics` (guessed, or OpenCV's calibration files);
- :mod:`~gb_pin.vision.camera`: :class:`VideoCamera` (a webcam, read after the call);
- :mod:`~gb_pin.vision.sensor`: :class:`CameraSensor` (a camera and a tracker: ``read() -> x | None``);
- :mod:`~gb_pin.vision.watched`: :class:`WatchedRobot` (a robot that moves, learnt in the camera's frame);
- :mod:`~gb_pin.vision.taught`: :func:`teach` and :func:`goal_box` (goals shown, not typed);
- :mod:`~gb_pin.vision.dependency`: the OpenCV check.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gb_pin._lazy import lazy_exports

_EXPORTS: dict[str, str | tuple[str, str]] = {
    "ArucoTracker": "gb_pin.vision.aruco",
    "CameraError": "gb_pin.exceptions",
    "CameraSensor": "gb_pin.vision.sensor",
    "Intrinsics": "gb_pin.vision.intrinsics",
    "Tracker": "gb_pin.vision.tracker",
    "VideoCamera": "gb_pin.vision.camera",
    "WatchedRobot": "gb_pin.vision.watched",
    "goal_box": "gb_pin.vision.taught",
    "marker_image": "gb_pin.vision.aruco",
    "require_cv2": "gb_pin.vision.dependency",
    "teach": "gb_pin.vision.taught",
}

__all__ = [
    "ArucoTracker",
    "CameraError",
    "CameraSensor",
    "Intrinsics",
    "Tracker",
    "VideoCamera",
    "WatchedRobot",
    "goal_box",
    "marker_image",
    "require_cv2",
    "teach",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())

if TYPE_CHECKING:
    from gb_pin.exceptions import CameraError
    from gb_pin.vision.aruco import ArucoTracker, marker_image
    from gb_pin.vision.camera import VideoCamera
    from gb_pin.vision.dependency import require_cv2
    from gb_pin.vision.intrinsics import Intrinsics
    from gb_pin.vision.sensor import CameraSensor
    from gb_pin.vision.taught import goal_box, teach
    from gb_pin.vision.tracker import Tracker
    from gb_pin.vision.watched import WatchedRobot
