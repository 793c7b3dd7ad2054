"""VideoCamera: a webcam or a video file through ``cv2.VideoCapture``, read *after* the call.

A webcam's driver keeps a few frames in a buffer (V4L2: usually 4): a plain ``read()`` right
after the arm came to rest can return a frame taken while it was still moving, a reading of
another posture. :meth:`VideoCamera.read` first drains the buffer: it grabs frames until one
grab had to wait for the sensor (it took at least 40 % of a frame period), so the frame returned
began after the call.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import CameraError, InvalidArgumentError
from gb_pin.vision.dependency import require_cv2


class VideoCamera:
    """A camera (its index, e.g. 0) or a video file (its path), delivering BGR pictures.

    Args:
        source: the device index or a file path / URL OpenCV opens.
        width, height: ask the driver for this picture size (None: its default).
        fps: the frame rate assumed to recognise a fresh frame (None: the driver's, else 30).
        flush: most frames grabbed to drain the driver's buffer per read (0: none, for files).

    Raises:
        CameraError: the camera or file cannot be opened (one line, before anything moves).
    """

    def __init__(
        self,
        source: int | str = 0,
        *,
        width: int | None = None,
        height: int | None = None,
        fps: float | None = None,
        flush: int | None = None,
    ) -> None:
        cv2 = require_cv2()
        if isinstance(source, bool) or not isinstance(source, int | str):
            raise InvalidArgumentError(f"a camera is a device index or a path, got {source!r:.80}")
        self.source = source
        live = isinstance(source, int)
        self.flush = (5 if live else 0) if flush is None else check.positive_int("flush", flush, 0, 100)
        self._cap = cv2.VideoCapture(source)
        if not self._cap.isOpened():
            what = f"camera {source}" if live else f"video {source!r}"
            raise CameraError(f"cannot open {what}: " + (
                "no such device, or it is busy (ls /dev/video*; close other programs using it)" if live
                else "no such file, or a format OpenCV cannot read"))  # fmt: skip
        if width is not None:
            self._cap.set(cv2.CAP_PROP_FRAME_WIDTH, check.positive_int("width", width, 1, 100_000))
        if height is not None:
            self._cap.set(cv2.CAP_PROP_FRAME_HEIGHT, check.positive_int("height", height, 1, 100_000))
        driver_fps = float(self._cap.get(cv2.CAP_PROP_FPS) or 0.0)
        self.fps = (
            check.positive_float("fps", fps) if fps is not None else (driver_fps if driver_fps > 0 else 30.0)
        )
        self.frames = 0

    def read(self) -> NDArray[np.uint8]:
        """A picture (H, W, 3) uint8 taken after this call (the driver's buffer drained first).

        Raises:
            CameraError: the camera delivered no frame (unplugged, end of the file).
        """
        threshold = 0.4 / self.fps
        for _ in range(self.flush):
            start = time.perf_counter()
            if not self._cap.grab():
                break
            if time.perf_counter() - start >= threshold:
                ok, image = self._cap.retrieve()
                if ok:
                    self.frames += 1
                    return np.asarray(image)
                break
        ok, image = self._cap.read()
        if not ok or image is None:
            raise CameraError(
                f"camera {self.source!r} delivered no frame (unplugged, or the end of the video)"
            )
        self.frames += 1
        return np.asarray(image)

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) of the pictures [px] as the driver reports them."""
        cv2 = require_cv2()
        return int(self._cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(self._cap.get(cv2.CAP_PROP_FRAME_HEIGHT))

    def close(self) -> None:
        """Release the device."""
        self._cap.release()

    def __enter__(self) -> VideoCamera:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"VideoCamera({self.source!r}, {self.fps:g} fps)"
