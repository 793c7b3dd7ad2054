"""Goals without typing coordinates: show the arm a place, read it; a goal box from taught corners.

In the camera's frame nobody knows the coordinates of "the middle of the table"; the arm can be
shown it. :func:`teach` averages a few readings of the hand held at a place (lost readings
skipped); :func:`goal_box` spans a grid over taught corners: two opposite corners give a box
along the camera's axes, eight corners (a box shown corner by corner, in the order of
:data:`CORNERS`) a grid that follows the box the arm was shown, however the camera is turned.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError

CORNERS = tuple((i, j, k) for k in (0, 1) for j in (0, 1) for i in (0, 1))
"""The order of eight taught corners: (0,0,0), (1,0,0), (0,1,0), (1,1,0), (0,0,1), ... (x fastest)."""


def teach(read: Callable[[], Any], readings: int = 10, *, tries: int | None = None) -> NDArray[np.float64]:
    """The mean of ``readings`` readings of the hand held still (lost readings are read again).

    Args:
        read: the sensor, ``read() -> x (n,) or None`` (e.g. ``CameraSensor.read``).
        readings: readings averaged.
        tries: most reads in all (default 3 x readings).

    Raises:
        InvalidArgumentError: the marker was seen fewer than ``readings`` times in ``tries`` reads.
    """
    k = check.positive_int("readings", readings, 1, 10**6)
    limit = 3 * k if tries is None else check.positive_int("tries", tries, k, 10**7)
    seen: list[NDArray[np.float64]] = []
    for _ in range(limit):
        x = read()
        if x is not None:
            seen.append(np.asarray(x, dtype=np.float64).ravel())
            if len(seen) == k:
                break
    if len(seen) < k:
        raise InvalidArgumentError(
            f"the marker was seen {len(seen)} times in {limit} reads (wanted {k}): is it in view and lit?"
        )
    return np.mean(np.array(seen), axis=0)


def goal_box(
    corners: ArrayLike, per_axis: int | tuple[int, ...] = 4, shrink: float = 1.0
) -> NDArray[np.float64]:
    """A goal grid (N, n) over taught corners.

    Args:
        corners: two opposite corners (2, n) (a box along the frame's axes), or the 8 corners
            (8, 3) of a box shown corner by corner in the order of :data:`CORNERS` (a grid along
            its edges, by trilinear interpolation), or any other set of points (their bounding box).
        per_axis: points per axis (one number or one per axis).
        shrink: the grid over this fraction of the box about its centre (e.g. 0.75 for test points
            inside the goal box).

    Raises:
        InvalidArgumentError: another number of corners, non-finite corners, a bad count or shrink.
    """
    C = np.asarray(corners, dtype=np.float64)
    if C.ndim != 2 or C.shape[0] < 2 or not np.all(np.isfinite(C)):
        raise InvalidArgumentError(f"corners must be at least 2 finite points (k, n), got shape {C.shape}")
    n = C.shape[1]
    if C.shape[0] != 2 and (n != 3 or C.shape[0] != 8):  # any other set: its bounding box
        C = np.array([C.min(axis=0), C.max(axis=0)])
    if np.any(np.ptp(C, axis=0) <= 0):
        raise InvalidArgumentError(f"the taught corners span no box (flat or repeated): {C.tolist()}")
    counts = (per_axis,) * n if isinstance(per_axis, int) else tuple(per_axis)
    if len(counts) != n:
        raise InvalidArgumentError(f"per_axis needs {n} counts, got {per_axis!r}")
    counts = tuple(check.positive_int("per_axis", c, 1, 1000) for c in counts)
    s = float(shrink)
    if not 0.0 < s <= 1.0:
        raise InvalidArgumentError(f"shrink must be in (0, 1], got {shrink!r}")
    axes = [0.5 + s * (np.linspace(0.0, 1.0, c) - 0.5) if c > 1 else np.array([0.5]) for c in counts]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, n)  # (N, n) in [0, 1]^n
    if C.shape[0] == 2:
        return C[0] + grid * (C[1] - C[0])
    out = np.zeros((grid.shape[0], n))
    for corner, (i, j, k) in zip(C, CORNERS, strict=True):
        w = (grid[:, 0] if i else 1 - grid[:, 0]) * (grid[:, 1] if j else 1 - grid[:, 1])
        w = w * (grid[:, 2] if k else 1 - grid[:, 2])
        out += w[:, None] * corner
    return out
