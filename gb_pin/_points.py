"""Point files: the one reader of ``--targets`` and ``--eval-targets`` (babble, trials, ``gb-pin ik``).

A point file is an ``.npy`` array of shape (N, n) or a ``.csv`` / ``.txt`` file with one point per
line (comma-separated numbers; blank lines and ``#`` comments skipped, and a first line naming the
task axes, ``x,y,z``, when the axes are known). It is untrusted input, read in bounds: a regular
file only (:func:`gb_pin._reading.open_regular`) of at most :data:`MAX_FILE_BYTES`, an ``.npy``
header checked before its array is allocated, a CSV parsed line by line (each line at most
:data:`MAX_LINE_BYTES`) into one growing buffer of floats, stopped as soon as it holds more than
:data:`MAX_POINTS` points or :data:`MAX_VALUES` numbers. Peak memory is about the points kept
(8 bytes a coordinate), whatever the file.
"""

from __future__ import annotations

import array
import math
import os
from typing import IO

import numpy as np
from numpy.typing import NDArray

from gb_pin._reading import open_regular, read_npy
from gb_pin.exceptions import InvalidArgumentError

MAX_POINTS = 10**6
"""The most points of a point file."""
MAX_VALUES = 10**7
"""The most coordinates of a point file, all points together (80 MB of floats)."""
MAX_FILE_BYTES = 256 * 2**20
"""The largest point file read."""
MAX_LINE_BYTES = 64 * 2**10
"""The longest line of a CSV point file."""


def read_points(
    path: str | os.PathLike[str], what: str = "points", axes: str | None = None
) -> NDArray[np.float64]:
    """An (N, n) point set from a ``.npy`` file, or a ``.csv`` / ``.txt`` file (one point per line).

    Args:
        path: the file.
        what: how messages name it (``"--targets"``).
        axes: the task axes, if known (``"xyz"``): then every point must have ``len(axes)``
            coordinates, and a first line naming the axes (``x,y,z``) is skipped.

    Returns:
        The points, C-contiguous float64, all finite.

    Raises:
        InvalidArgumentError: the file is missing, not a regular file, too large, not numeric,
            not (N, n) with 1 <= N <= :data:`MAX_POINTS`, or holds NaN or infinite values.
    """
    if isinstance(path, bool) or not isinstance(path, str | os.PathLike):
        raise InvalidArgumentError(f"{what} must be a file path, got {path!r}")
    name = os.fspath(path)
    label = f"{what} {name!r}"
    lower = name.lower()
    if not lower.endswith((".npy", ".csv", ".txt")):
        raise InvalidArgumentError(f"{label}: expected a .csv (one point per line), .txt or .npy file")
    fh, size = open_regular(name, label, "point file", MAX_FILE_BYTES, InvalidArgumentError)
    with fh:
        try:
            arr = _npy(fh, size, label) if lower.endswith(".npy") else _csv(fh, name, label, axes)
        except OSError as exc:
            raise InvalidArgumentError(f"{label}: cannot read it ({exc.strerror or exc})") from exc
    if arr.ndim != 2 or not 1 <= arr.shape[0] <= MAX_POINTS or arr.shape[1] < 1:
        got = "no points" if arr.size == 0 else f"an array of shape {arr.shape}"
        raise InvalidArgumentError(
            f"{label}: expected (N, n) numbers, one point a row, with 1 <= N <= {MAX_POINTS}; got {got}"
        )
    if axes is not None and arr.shape[1] != len(axes):
        raise InvalidArgumentError(
            f"{label}: points of {arr.shape[1]} coordinates; the task axes {axes!r} need {len(axes)}"
        )
    out = np.ascontiguousarray(arr, dtype=np.float64)
    if not np.all(np.isfinite(out)):
        raise InvalidArgumentError(f"{label}: holds NaN or infinite values")
    return out


def _npy(fh: IO[bytes], size: int, label: str) -> NDArray[np.float64]:
    """An ``.npy`` point set: numbers only, its declared size checked before it is allocated."""
    arr = read_npy(fh, size, label, 8 * MAX_VALUES, InvalidArgumentError)
    if arr.dtype.kind not in "fiu":
        raise InvalidArgumentError(f"{label}: expected (N, n) real numbers, got {arr.dtype} {arr.shape}")
    return arr


def _csv(fh: IO[bytes], name: str, label: str, axes: str | None) -> NDArray[np.float64]:
    """A CSV point set, parsed line by line into one buffer of floats."""
    values = array.array("d")
    width = None if axes is None else len(axes)
    rows = 0
    number = 0
    while True:
        raw = fh.readline(MAX_LINE_BYTES + 1)
        if not raw:
            break
        number += 1
        if len(raw) > MAX_LINE_BYTES:
            raise InvalidArgumentError(f"{name}:{number}: a line of more than {MAX_LINE_BYTES} bytes")
        try:
            line = raw.decode("utf-8").split("#", 1)[0].strip()
        except UnicodeDecodeError as exc:
            raise InvalidArgumentError(f"{name}:{number}: not UTF-8 text ({exc.reason})") from exc
        if not line:
            continue
        fields = [f.strip() for f in line.split(",")]
        if rows == 0 and axes is not None and [f.lower() for f in fields] == list(axes):
            continue  # a header naming the axes
        if width is None:
            width = len(fields)
        if len(fields) != width:
            expected = f"axes {axes!r}" if axes is not None else "as the first point"
            raise InvalidArgumentError(
                f"{name}:{number}: expected {width} comma-separated coordinates ({expected}), "
                f"got {line[:80]!r}"
            )
        if rows == MAX_POINTS or len(values) + width > MAX_VALUES:
            raise InvalidArgumentError(
                f"{label}: more than {min(MAX_POINTS, MAX_VALUES // width)} points of {width} coordinates; "
                f"gb_pin reads at most {MAX_POINTS} points and {MAX_VALUES} coordinates "
                "(gb_pin._points.MAX_POINTS, MAX_VALUES)"
            )
        for f in fields:
            values.append(finite_number(f, f"{name}:{number}"))
        rows += 1
    if rows == 0:
        raise InvalidArgumentError(
            f"{label}: no points (the file is empty, or holds only blank lines, # comments or a header); "
            "expected one point per line, its coordinates separated by commas, e.g. 0.5,0.1"
        )
    return np.frombuffer(values, dtype=np.float64).reshape(rows, -1)


def finite_number(text: str, where: str) -> float:
    """``text`` as a finite number.

    Raises:
        InvalidArgumentError: naming ``where`` and the text.
    """
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InvalidArgumentError(f"{where}: {text[:40]!r} is not a finite number")
    return value
