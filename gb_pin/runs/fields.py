"""Checks of the fields a result file or a checkpoint declares: each wrong field is a ResultFileError.

A file is untrusted input: its JSON header and arrays are checked here, once, at load, so that a
file that loads is one that ``show``, ``replay`` and ``resume`` can use.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin._validation import MAX_MOVEMENTS
from gb_pin.exceptions import ResultFileError


def _fail(path: str, name: str, value: Any, valid: str) -> ResultFileError:
    return ResultFileError(f"{path}: {name} must be {valid}, got {str(value)[:80]!r}")


def optional_str(path: str, meta: dict[str, Any], name: str) -> str | None:
    """``meta[name]`` if it is a string or None."""
    value = meta.get(name)
    if value is not None and not isinstance(value, str):
        raise _fail(path, name, value, "a string or null")
    return value


def count(path: str, meta: dict[str, Any], name: str) -> int:
    """``meta[name]`` if it is an integer in [0, MAX_MOVEMENTS]."""
    value = meta.get(name)
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= MAX_MOVEMENTS:
        raise _fail(path, name, value, f"an integer in [0, {MAX_MOVEMENTS}]")
    return value


def seed(path: str, meta: dict[str, Any]) -> int | None:
    """``meta["seed"]`` if it is an integer >= 0 or None."""
    value = meta.get("seed")
    if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 0):
        raise _fail(path, "seed", value, "an integer >= 0 or null")
    return value


def seconds(path: str, meta: dict[str, Any], name: str) -> float:
    """``meta[name]`` if it is a finite number >= 0."""
    value = meta.get(name)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) or value < 0:
        raise _fail(path, name, value, "a finite number >= 0")
    return float(value)


def config(path: str, meta: dict[str, Any]) -> dict[str, Any]:
    """``meta["config"]`` if it is a JSON object (BabbleConfig checks its values)."""
    value = meta.get("config")
    if not isinstance(value, dict):
        raise _fail(path, "config", value, "an object of hyperparameters")
    return value


def real_array(path: str, arrays: dict[str, Any], name: str, ndim: int) -> NDArray[np.float64]:
    """``arrays[name]`` as finite floats of ``ndim`` dimensions (ints and floats only, no complex)."""
    arr = arrays[name]
    if arr.dtype.kind not in "iuf" or arr.ndim != ndim:
        raise _fail(
            path, name, f"{arr.dtype} array of shape {arr.shape}", f"a {ndim}-d array of real numbers"
        )
    out = arr.astype(np.float64)
    if not np.all(np.isfinite(out)):
        raise ResultFileError(f"{path}: {name} holds non-finite values")
    return out


def history(
    path: str, arrays: dict[str, Any]
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
    """(movements, error, home_distance): 1-D, one length, movements increasing integers >= 0.

    E^X and D^home may be NaN (not measured) but not infinite nor negative.
    """
    movements = arrays["movements"]
    if movements.dtype.kind not in "iu" or movements.ndim != 1:
        raise _fail(path, "movements", f"{movements.dtype} array of shape {movements.shape}", "1-d integers")
    moves = movements.astype(np.int64)
    if not moves.size:
        raise ResultFileError(f"{path}: the history is empty (a run records E^X at least once)")
    if moves[0] < 0 or np.any(np.diff(moves) <= 0):
        raise ResultFileError(f"{path}: the history's movements must be increasing integers >= 0")
    out = []
    for name in ("error", "home_distance"):
        arr = arrays[name]
        if arr.dtype.kind not in "iuf" or arr.shape != moves.shape:
            raise _fail(
                path, name, f"{arr.dtype} array of shape {arr.shape}", f"real numbers of shape {moves.shape}"
            )
        values = arr.astype(np.float64)
        if np.any(np.isinf(values)) or np.any(values < 0):
            raise ResultFileError(f"{path}: {name} holds infinite or negative values (a distance is >= 0)")
        out.append(values)
    return moves, out[0], out[1]


def components(path: str, arrays: dict[str, Any], count: int) -> NDArray[np.float64] | None:
    """The history's E^X per task component (T, C) of a stacked task, or None (none recorded).

    Raises:
        ResultFileError: not (T, C) real numbers, or infinite values.
    """
    if "history_components" not in arrays:
        return None
    arr = arrays["history_components"]
    if arr.dtype.kind not in "iuf" or arr.ndim != 2 or arr.shape[0] != count or not 1 <= arr.shape[1] <= 64:
        raise _fail(
            path,
            "history_components",
            f"{arr.dtype} array of shape {arr.shape}",
            f"real numbers of shape ({count}, C)",
        )
    values = arr.astype(np.float64)
    if np.any(np.isinf(values) | (values < 0)):
        raise ResultFileError(f"{path}: history_components holds infinite or negative values")
    return values


def reach(path: str, arrays: dict[str, Any], count: int) -> NDArray[np.float64] | None:
    """The history's reach medians (T,) [m] (NaN before the first), or None (files written before them).

    Raises:
        ResultFileError: not (T,) real numbers, or negative or infinite values.
    """
    if "history_reach" not in arrays:
        return None
    arr = arrays["history_reach"]
    if arr.dtype.kind not in "iuf" or arr.shape != (count,):
        raise _fail(
            path,
            "history_reach",
            f"{arr.dtype} array of shape {arr.shape}",
            f"real numbers of shape ({count},)",
        )
    values = arr.astype(np.float64)
    if np.any(np.isinf(values)) or np.any(values < 0):
        raise ResultFileError(f"{path}: history_reach holds negative or infinite values")
    return values


def targets(path: str, arrays: dict[str, Any], n_task: int, key: str = "targets") -> NDArray[np.float64]:
    """``arrays[key]``: finite, of shape (N, n_task) with N >= 1."""
    arr = real_array(path, arrays, key, 2)
    if arr.shape[0] < 1 or arr.shape[1] != n_task:
        raise _fail(path, key, f"shape {arr.shape}", f"of shape (N >= 1, {n_task})")
    return arr


def goals(path: str, meta: dict[str, Any]) -> str | None:
    """``meta["goals"]``: the goal generator's description (printable, <= 200 characters), or None."""
    value = meta.get("goals")
    if value is None:
        return None
    if not isinstance(value, str) or len(value) > 200 or not value.isprintable():
        raise ResultFileError(f"{path}: goals must be a short text, got {str(value)[:80]!r}")
    return value
