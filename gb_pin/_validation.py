"""Argument checks shared by the public API: each raises InvalidArgumentError naming the value."""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import InvalidArgumentError


def _is_real(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _float(value: Any) -> float:
    """``float(value)``, with integers beyond a float's range (``10**400``) as +-inf, not OverflowError."""
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def positive_float(name: str, value: Any) -> float:
    """Return ``value`` as a float if it is a finite number > 0, else raise."""
    if not _is_real(value) or not math.isfinite(_float(value)) or float(value) <= 0.0:
        raise InvalidArgumentError(f"{name} must be a positive finite number, got {value!r}")
    return float(value)


def nonnegative_float(name: str, value: Any) -> float:
    """Return ``value`` as a float if it is a finite number >= 0, else raise."""
    if not _is_real(value) or not math.isfinite(_float(value)) or float(value) < 0.0:
        raise InvalidArgumentError(f"{name} must be a finite number >= 0, got {value!r}")
    return float(value)


def probability(name: str, value: Any) -> float:
    """Return ``value`` as a float if it lies in [0, 1), else raise."""
    if not _is_real(value) or not (0.0 <= _float(value) < 1.0):
        raise InvalidArgumentError(f"{name} must be a probability in [0, 1), got {value!r}")
    return float(value)


INT64_MAX = 2**63 - 1
"""The largest integer an argument may be by default: what compiled code and int64 arrays hold."""


def positive_int(name: str, value: Any, minimum: int = 1, maximum: int = INT64_MAX) -> int:
    """Return ``value`` as an int if it is an integer in [``minimum``, ``maximum``], else raise.

    numpy integers are accepted (and returned as Python ints); bools, floats and strings are not.
    The default ``maximum`` is :data:`INT64_MAX`: every integer checked here fits the 64-bit
    integers of compiled code and of int64 arrays (a Python int does not need to).
    """
    number = int(value) if isinstance(value, numbers.Integral) and not isinstance(value, bool) else None
    if number is None or not minimum <= number <= maximum:
        bound = (
            f"an integer >= {minimum}" if maximum == INT64_MAX else f"an integer in [{minimum}, {maximum}]"
        )
        if maximum == INT64_MAX and number is not None and number > maximum:
            bound = f"an integer in [{minimum}, 2**63 - 1] (64-bit)"
        raise InvalidArgumentError(f"{name} must be {bound}, got {_short(value)}")
    return number


def _short(value: Any) -> str:
    """``repr(value)``, cut to 100 characters (a huge int or list stays readable)."""
    text = repr(value)
    return text if len(text) <= 100 else f"{text[:60]}... ({len(text)} characters)"


MAX_MOVEMENTS = 10**12
"""The largest number of movements a run accepts (about 10^5 years of compute at 3 us a step)."""


def movements(name: str, value: Any, minimum: int = 0) -> int:
    """Return a number of movements as an int in [``minimum``, :data:`MAX_MOVEMENTS`], else raise."""
    return positive_int(name, value, minimum, MAX_MOVEMENTS)


def is_complex(value: Any) -> bool:
    """Whether ``value`` holds complex numbers (a float conversion would drop their imaginary part)."""
    try:
        return bool(np.asarray(value).dtype.kind == "c")
    except (TypeError, ValueError):
        return False


def _refuse_complex(name: str, value: Any) -> None:
    if is_complex(value):
        raise InvalidArgumentError(f"{name} must be real numbers, got complex values {value!r:.200}")


def points(
    name: str, value: Any, dim: int, *, min_rows: int = 1, allow_single: bool = False
) -> NDArray[np.float64]:
    """Return ``value`` as a C-contiguous float array of shape (N, dim) with finite entries.

    With ``allow_single``, one point of shape (dim,) is accepted too (returned as (1, dim)).
    Complex values are refused (never cast with their imaginary part dropped).
    """
    _refuse_complex(name, value)
    try:
        arr = np.array(value, dtype=np.float64, ndmin=2)
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(
            f"{name} must be an array of shape (N, {dim}) of finite numbers, got {value!r}"
        ) from exc
    ndim_ok = arr.ndim == 2 and (np.ndim(value) == 2 or (allow_single and np.ndim(value) == 1))
    if not ndim_ok or arr.shape[1] != dim or arr.shape[0] < min_rows:
        raise InvalidArgumentError(
            f"{name} must have shape (N, {dim}) with N >= {min_rows}, got shape {np.shape(value)}"
        )
    if not np.all(np.isfinite(arr)):
        raise InvalidArgumentError(f"{name} must contain only finite values, got {arr.tolist()!r}")
    return np.ascontiguousarray(arr)


def vector(name: str, value: Any, dim: int) -> NDArray[np.float64]:
    """Return ``value`` as a finite float vector of length ``dim`` (complex values refused)."""
    _refuse_complex(name, value)
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(f"{name} must be a vector of {dim} finite numbers, got {value!r}") from exc
    if arr.shape != (dim,):
        raise InvalidArgumentError(f"{name} must have shape ({dim},), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InvalidArgumentError(f"{name} must contain only finite values, got {arr.tolist()!r}")
    return np.ascontiguousarray(arr)


def generator(seed: Any) -> np.random.Generator:
    """Return a numpy Generator from a seed (int >= 0) or a Generator; never global state."""
    if isinstance(seed, np.random.Generator):
        return seed
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
        raise InvalidArgumentError(
            f"seed must be a non-negative integer or a numpy.random.Generator, got {seed!r}"
        )
    return np.random.default_rng(int(seed))
