"""OpenCV (the ``vision`` extra), checked before use: the only module of gb_pin that imports ``cv2``.

``import gb_pin.vision`` works without OpenCV; a tracker, a camera or a marker texture asks for it
through :func:`require_cv2`, so that a missing OpenCV is one :class:`~gb_pin.exceptions.CameraError`
naming the extra to install.
"""

from __future__ import annotations

import os
from types import ModuleType

from gb_pin.exceptions import CameraError

INSTALL_HINT = "pip install 'gb_pin[vision]' (or: pip install opencv-python-headless)"


def require_cv2() -> ModuleType:
    """The ``cv2`` package (OpenCV >= 4.10, with its ArUco module).

    Raises:
        CameraError: OpenCV is not installed or too old; the message says how to install it, in one line.
    """
    # OpenCV's own warnings (a camera index that does not open prints two) would add lines to our one
    os.environ.setdefault("OPENCV_LOG_LEVEL", "ERROR")
    try:
        import cv2
    except ImportError as exc:
        raise CameraError(f"the camera tracker needs OpenCV, which is not installed: {INSTALL_HINT}") from exc
    if not hasattr(cv2, "aruco") or not hasattr(cv2.aruco, "ArucoDetector"):
        raise CameraError(
            f"the camera tracker needs OpenCV >= 4.10 with its ArUco module, found {cv2.__version__}: "
            f"{INSTALL_HINT}"
        )
    return cv2
