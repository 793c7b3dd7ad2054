"""ArucoTracker: an ArUco marker's centre in the camera frame (solvePnP) or in the picture.

Detection is done in two passes (docs/CAMERA.md has the measurement): OpenCV's
``ArucoDetector`` finds the marker on the whole picture without corner refinement (2-6 ms), then
the same detector with AprilTag's corner refinement runs on a crop of about 160 px around it
(7-9 ms, where the whole noisy picture costs 61-92 ms). AprilTag refinement is the accurate one
here: OpenCV's sub-pixel refinement pulls the corners ~0.3 px inwards, +4.9 mm of depth at 50 cm.
The pose comes from ``cv2.solvePnP(..., SOLVEPNP_IPPE_SQUARE)`` on the four corners; the reading
is the marker's centre.

Every doubt gives None, never a wrong reading: no marker, another id, the marker id seen twice,
the marker lost in the refinement pass, a pose behind the camera or not finite.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin._names import suggest
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.vision.dependency import require_cv2
from gb_pin.vision.intrinsics import Intrinsics
from gb_pin.vision.tracker import Tracker

REFINEMENTS = ("apriltag", "subpix", "none")
"""Corner refinements: AprilTag's (accurate), OpenCV's sub-pixel (fast, biased inwards), none."""
MODES = ("xyz", "uv")
"""Readings: the marker's centre (x, y, z) in the camera frame [m], or its pixel (u, v) [px]."""
CROP = 160
"""Side of the crop around a marker found without refinement, where it is refined [px] (at least)."""


class ArucoTracker(Tracker):
    """The centre of one ArUco marker, seen by a calibrated camera.

    Args:
        intrinsics: the camera's :class:`~gb_pin.vision.intrinsics.Intrinsics`.
        marker_size: the side of the marker's black square [m] (e.g. 0.025).
        marker_id: the marker's id; None: the only marker of the dictionary in the picture.
        dictionary: OpenCV's predefined dictionary (``"DICT_4X4_50"``, ...).
        refine: corner refinement in the second pass (:data:`REFINEMENTS`).
        mode: ``"xyz"`` (metres, camera frame: x right, y down, z forward) or ``"uv"`` (pixels
            about the principal point, times ``scale``).
        scale: in ``"uv"`` mode, metres per pixel for the learner (depth / focal length at the work
            volume: then Eq. 5's distances and the radius keep their metric meaning); default 1: pixels.

    Raises:
        InvalidArgumentError: a bad size, id, dictionary, refinement or mode.
        CameraError: OpenCV is not installed.
    """

    def __init__(
        self,
        intrinsics: Intrinsics,
        marker_size: float,
        *,
        marker_id: int | None = None,
        dictionary: str = "DICT_4X4_50",
        refine: str = "apriltag",
        mode: str = "xyz",
        scale: float = 1.0,
    ) -> None:
        cv2 = require_cv2()
        self._cv2 = cv2
        if not isinstance(intrinsics, Intrinsics):
            raise InvalidArgumentError(f"intrinsics must be an Intrinsics, got {intrinsics!r:.80}")
        self.intrinsics = intrinsics
        self.marker_size = check.positive_float("marker_size", marker_size)
        if self.marker_size > 2.0:
            raise InvalidArgumentError(f"marker_size is in metres (e.g. 0.025), got {marker_size!r}")
        names = [n for n in dir(cv2.aruco) if n.startswith("DICT_")]
        if dictionary not in names:
            raise InvalidArgumentError(
                f"unknown ArUco dictionary {dictionary!r}; {suggest(dictionary, names)}"
            )
        self.dictionary = dictionary
        self._dict = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary))
        size = int(self._dict.bytesList.shape[0])
        self.marker_id = (
            None if marker_id is None else check.positive_int("marker_id", marker_id, 0, size - 1)
        )
        if refine not in REFINEMENTS:
            raise InvalidArgumentError(f"refine must be one of {', '.join(REFINEMENTS)}, got {refine!r}")
        if mode not in MODES:
            raise InvalidArgumentError(f"mode must be 'xyz' (metres) or 'uv' (pixels), got {mode!r}")
        self.refine, self.mode = refine, mode
        self.scale = 1.0 if mode == "xyz" else check.positive_float("scale", scale)
        self.n_task = 3 if mode == "xyz" else 2
        self.units = "m" if mode == "xyz" or self.scale != 1.0 else "px"
        self._coarse = self._detector(cv2.aruco.CORNER_REFINE_NONE)
        method = {"apriltag": cv2.aruco.CORNER_REFINE_APRILTAG, "subpix": cv2.aruco.CORNER_REFINE_SUBPIX}
        self._fine = self._detector(method[refine]) if refine != "none" else None
        s = (
            self.marker_size / 2.0
        )  # IPPE_SQUARE's corner order: top-left, top-right, bottom-right, bottom-left
        self._object = np.array([[-s, s, 0], [s, s, 0], [s, -s, 0], [-s, -s, 0]], dtype=np.float64)

    def _detector(self, refinement: int) -> Any:
        params = self._cv2.aruco.DetectorParameters()
        params.cornerRefinementMethod = refinement
        return self._cv2.aruco.ArucoDetector(self._dict, params)

    def corners(self, image: NDArray[np.uint8]) -> NDArray[np.float64] | None:
        """The marker's four corners (4, 2) [px] (refined), or None when it is not seen for sure."""
        gray = _gray(self._cv2, image)
        found = self._find(self._coarse, gray)
        if found is None or self._fine is None:
            return found
        h, w = gray.shape
        centre = found.mean(axis=0)
        half = int(max(CROP / 2, 0.75 * np.ptp(found, axis=0).max() + 16))
        x0, y0 = max(0, int(centre[0]) - half), max(0, int(centre[1]) - half)
        x1, y1 = min(w, int(centre[0]) + half), min(h, int(centre[1]) + half)
        refined = self._find(self._fine, np.ascontiguousarray(gray[y0:y1, x0:x1]))
        if refined is None:
            return None
        return refined + np.array([x0, y0], dtype=np.float64)

    def _find(self, detector: Any, gray: NDArray[np.uint8]) -> NDArray[np.float64] | None:
        corners, ids, _ = detector.detectMarkers(gray)
        if ids is None or len(ids) == 0:
            return None
        ids = np.asarray(ids).ravel()
        if self.marker_id is None:
            if len(ids) != 1:
                return None  # which one? never guess
            k = 0
        else:
            hits = np.flatnonzero(ids == self.marker_id)
            if len(hits) != 1:
                return None
            k = int(hits[0])
        c = np.asarray(corners[k], dtype=np.float64).reshape(4, 2)
        return c if np.all(np.isfinite(c)) else None

    def __call__(self, image: NDArray[np.uint8]) -> NDArray[np.float64] | None:
        """The marker's centre in the camera frame (3,) [m] or its pixel about the centre (2,), or None."""
        c = self.corners(image)
        if c is None:
            return None
        cv2 = self._cv2
        K, D = self.intrinsics.matrix, self.intrinsics.coefficients
        if self.mode == "uv":
            if self.intrinsics.distortion:
                c = cv2.undistortPoints(c.reshape(-1, 1, 2), K, D, P=K).reshape(4, 2)
            p = _diagonals(c)
            if p is None:
                return None
            return (p - np.array([self.intrinsics.cx, self.intrinsics.cy])) * self.scale
        try:
            ok, _, tvec = cv2.solvePnP(self._object, c, K, D, flags=cv2.SOLVEPNP_IPPE_SQUARE)
        except cv2.error:
            return None
        x = np.asarray(tvec, dtype=np.float64).ravel()
        if not ok or x.shape != (3,) or not np.all(np.isfinite(x)) or x[2] <= 0:
            return None
        return x

    def __repr__(self) -> str:
        return (
            f"ArucoTracker({self.dictionary}, id={self.marker_id}, {self.marker_size * 1000:g} mm, "
            f"refine={self.refine}, mode={self.mode})"
        )


def _gray(cv2: Any, image: Any) -> NDArray[np.uint8]:
    arr = np.asarray(image)
    if arr.dtype != np.uint8 or arr.ndim not in (2, 3) or (arr.ndim == 3 and arr.shape[2] not in (3, 4)):
        raise InvalidArgumentError(
            f"a picture must be an (H, W) or (H, W, 3) uint8 array, got {arr.dtype} {arr.shape}"
        )
    if arr.ndim == 2:
        return arr
    return cv2.cvtColor(arr, cv2.COLOR_BGR2GRAY if arr.shape[2] == 3 else cv2.COLOR_BGRA2GRAY)


def _diagonals(c: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """Where the marker's diagonals cross (2,) [px]: its centre's projection (the corners' mean is not)."""
    d1, d2 = c[2] - c[0], c[3] - c[1]
    A = np.array([d1, -d2]).T
    if abs(np.linalg.det(A)) < 1e-9:
        return None
    t = np.linalg.solve(A, c[1] - c[0])
    return c[0] + t[0] * d1


def marker_image(marker_id: int, pixels: int = 200, dictionary: str = "DICT_4X4_50", border: int = 0) -> Any:
    """The picture of a marker (pixels, pixels) uint8, ``border`` white pixels around it (a plate).

    Raises:
        InvalidArgumentError: an unknown dictionary or an id it does not hold.
        CameraError: OpenCV is not installed.
    """
    cv2 = require_cv2()
    names = [n for n in dir(cv2.aruco) if n.startswith("DICT_")]
    if dictionary not in names:
        raise InvalidArgumentError(f"unknown ArUco dictionary {dictionary!r}; {suggest(dictionary, names)}")
    d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary))
    i = check.positive_int("marker_id", marker_id, 0, int(d.bytesList.shape[0]) - 1)
    img = cv2.aruco.generateImageMarker(d, i, check.positive_int("pixels", pixels, 16, 10_000))
    if border:
        img = cv2.copyMakeBorder(img, border, border, border, border, cv2.BORDER_CONSTANT, value=255)
    return img


def marker_png(
    marker_id: int, pixels: int = 200, dictionary: str = "DICT_4X4_50", border: int = 0, mirror: bool = False
) -> bytes:
    """:func:`marker_image` as PNG bytes (``mirror``: flipped left-right, for a texture seen from behind)."""
    cv2 = require_cv2()
    image = marker_image(marker_id, pixels, dictionary, border)
    ok, data = cv2.imencode(".png", np.ascontiguousarray(image[:, ::-1] if mirror else image))
    if not ok:
        raise InvalidArgumentError("OpenCV could not encode the marker as PNG")
    return bytes(data.tobytes())
