"""A camera's intrinsics: focal lengths, principal point, distortion, picture size.

Guessed from the field of view (:meth:`Intrinsics.guess`; a webcam's data sheet gives it) or
loaded from OpenCV's calibration files (:meth:`Intrinsics.load`: the YAML/JSON that
``cv2.FileStorage`` writes, as OpenCV's ``calibrateCamera`` samples and ROS' camera_calibration
save them). A focal length off by 5 % scales depth by 5 %: harmless for goals taught through the
same camera (docs/CAMERA.md), not for absolute targets.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError

_MATRIX_KEYS = ("camera_matrix", "cameraMatrix", "K", "intrinsics", "mtx")
_DISTORTION_KEYS = ("distortion_coefficients", "dist_coeffs", "distCoeffs", "dist", "D")
_WIDTH_KEYS = ("image_width", "width")
_HEIGHT_KEYS = ("image_height", "height")


@dataclass(frozen=True)
class Intrinsics:
    """The pinhole model of a camera (OpenCV's).

    Args:
        fx, fy: focal lengths [px].
        cx, cy: principal point [px].
        width, height: picture size [px].
        distortion: OpenCV's distortion coefficients (k1, k2, p1, p2[, k3, ...]); empty: none.

    Raises:
        InvalidArgumentError: a focal length not > 0, a principal point outside the picture, a
            non-finite coefficient, a distortion of a length OpenCV does not take.
    """

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int
    distortion: tuple[float, ...] = field(default=())

    def __post_init__(self) -> None:
        for name in ("fx", "fy"):
            check.positive_float(name, getattr(self, name))
        check.positive_int("width", self.width, 1, 100_000)
        check.positive_int("height", self.height, 1, 100_000)
        for name, size in (("cx", self.width), ("cy", self.height)):
            value = getattr(self, name)
            if not check._is_real(value) or not 0.0 <= float(value) <= size:
                raise InvalidArgumentError(
                    f"{name} (the principal point) must lie in the picture [0, {size}] px, got {value!r}"
                )
        d = tuple(float(v) for v in self.distortion)
        if len(d) not in (0, 4, 5, 8, 12, 14) or not all(math.isfinite(v) for v in d):
            raise InvalidArgumentError(
                "distortion must be 0, 4, 5, 8, 12 or 14 finite coefficients (OpenCV's), "
                f"got {self.distortion!r:.120}"
            )
        object.__setattr__(self, "distortion", d)

    @classmethod
    def guess(cls, width: int, height: int, fov: float = 60.0) -> Intrinsics:
        """A camera of ``fov`` degrees horizontal field of view, centred, square pixels, no distortion.

        Raises:
            InvalidArgumentError: a size not > 0, a field of view outside (0, 180) degrees.
        """
        if not check._is_real(fov) or not 0.0 < float(fov) < 180.0:
            raise InvalidArgumentError(f"fov must be in (0, 180) degrees (horizontal), got {fov!r}")
        w = check.positive_int("width", width, 1, 100_000)
        h = check.positive_int("height", height, 1, 100_000)
        f = 0.5 * w / math.tan(math.radians(float(fov)) / 2.0)
        return cls(f, f, w / 2.0, h / 2.0, w, h)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Intrinsics:
        """Intrinsics from an OpenCV calibration file (YAML, YML, XML or JSON of ``cv2.FileStorage``).

        The camera matrix is read from ``camera_matrix`` (or cameraMatrix, K, mtx), the
        distortion from ``distortion_coefficients`` (or dist_coeffs, D), the size from
        ``image_width`` / ``image_height`` (else twice the principal point).

        Raises:
            InvalidArgumentError: no such file, a file OpenCV cannot parse, no camera matrix, a
                matrix that is not 3 x 3 and finite, or values :class:`Intrinsics` refuses.
        """
        from gb_pin.vision.dependency import require_cv2

        cv2 = require_cv2()
        file = Path(path)
        if not file.is_file():
            raise InvalidArgumentError(f"no calibration file at {str(file)!r}")
        try:
            store = cv2.FileStorage(str(file), cv2.FILE_STORAGE_READ)
        except cv2.error as exc:
            raise InvalidArgumentError(f"cannot parse the calibration file {str(file)!r}: not "
                                       "OpenCV's YAML/XML/JSON") from exc  # fmt: skip
        try:
            if not store.isOpened():
                raise InvalidArgumentError(f"cannot open the calibration file {str(file)!r}")
            K = _array(store, _MATRIX_KEYS)
            if K is None:
                raise InvalidArgumentError(
                    f"{str(file)!r} has no camera matrix (looked for {', '.join(_MATRIX_KEYS)})"
                )
            D = _array(store, _DISTORTION_KEYS)
            width, height = _number(store, _WIDTH_KEYS), _number(store, _HEIGHT_KEYS)
        finally:
            store.release()
        return cls.from_matrix(K, D, width, height, what=str(file))

    @classmethod
    def from_matrix(
        cls,
        matrix: Any,
        distortion: Any = None,
        width: float | None = None,
        height: float | None = None,
        *,
        what: str = "camera matrix",
    ) -> Intrinsics:
        """Intrinsics from a 3 x 3 camera matrix K (and distortion, size).

        Raises:
            InvalidArgumentError: K not 3 x 3, not finite, or not [[fx, s, cx], [0, fy, cy], [0, 0, 1]].
        """
        try:
            K = np.asarray(matrix, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InvalidArgumentError(f"{what}: the camera matrix is not numeric") from exc
        if K.size == 9:
            K = K.reshape(3, 3)
        if K.shape != (3, 3) or not np.all(np.isfinite(K)):
            raise InvalidArgumentError(
                f"{what}: the camera matrix must be 3 x 3 and finite, got {K.tolist()!r:.120}"
            )
        if abs(K[2, 2] - 1.0) > 1e-9 or K[1, 0] != 0 or K[2, 0] != 0 or K[2, 1] != 0:
            raise InvalidArgumentError(
                f"{what}: the camera matrix must be [[fx, s, cx], [0, fy, cy], [0, 0, 1]], "
                f"got {K.tolist()!r:.160}"
            )
        D = () if distortion is None else tuple(np.asarray(distortion, dtype=np.float64).ravel().tolist())
        w = round(2 * K[0, 2]) if width is None else width
        h = round(2 * K[1, 2]) if height is None else height
        if not float(w).is_integer() or not float(h).is_integer():
            raise InvalidArgumentError(f"{what}: the picture size must be whole pixels, got {w!r} x {h!r}")
        return cls(float(K[0, 0]), float(K[1, 1]), float(K[0, 2]), float(K[1, 2]), int(w), int(h), D)

    @property
    def matrix(self) -> NDArray[np.float64]:
        """The camera matrix K (3, 3)."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def coefficients(self) -> NDArray[np.float64]:
        """The distortion coefficients as OpenCV takes them (k,) (zeros(4) for none)."""
        return np.array(self.distortion) if self.distortion else np.zeros(4)

    @property
    def fov(self) -> float:
        """The horizontal field of view [deg]."""
        return math.degrees(2.0 * math.atan(0.5 * self.width / self.fx))

    def scaled(self, factor: float) -> Intrinsics:
        """The same camera with both focal lengths times ``factor`` (a mis-calibrated focal)."""
        f = check.positive_float("factor", factor)
        return Intrinsics(
            self.fx * f, self.fy * f, self.cx, self.cy, self.width, self.height, self.distortion
        )


def _array(store: Any, keys: tuple[str, ...]) -> NDArray[np.float64] | None:
    """The first of ``keys`` in an open FileStorage as an array (an OpenCV matrix or a list), or None."""
    for key in keys:
        node = store.getNode(key)
        if node.empty():
            continue
        if node.isSeq():
            values = [node.at(i).real() for i in range(node.size())]
            return np.asarray(values, dtype=np.float64)
        mat = node.mat()
        if mat is not None:
            return np.asarray(mat, dtype=np.float64)
        if node.isMap() and not node.getNode("data").empty():  # a map without type_id: rows/cols/data
            data = node.getNode("data")
            return np.asarray([data.at(i).real() for i in range(data.size())], dtype=np.float64)
    return None


def _number(store: Any, keys: tuple[str, ...]) -> float | None:
    for key in keys:
        node = store.getNode(key)
        if not node.empty() and (node.isInt() or node.isReal()):
            return float(node.real())
    return None
