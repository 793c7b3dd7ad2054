"""Regular target grids: ``grid_targets(lower, upper, shape)`` and the helpers of the auto grid."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin.exceptions import InvalidArgumentError

MAX_GRID_POINTS = 10**6
"""The most points a target grid may have (10^6 targets of 3 axes are 24 MB)."""


def check_size(counts: Sequence[int], shape: Any) -> None:
    """Raise InvalidArgumentError if a grid of ``counts`` points per axis exceeds :data:`MAX_GRID_POINTS`."""
    if math.prod(counts) > MAX_GRID_POINTS:
        raise InvalidArgumentError(
            f"a target grid of shape {shape!r} has {math.prod(counts)} points; at most {MAX_GRID_POINTS} "
            "(gb_pin.robot.grids.MAX_GRID_POINTS)"
        )


def grid_shape(shape: Sequence[int] | None, n_task: int) -> tuple[int, ...]:
    """A grid shape for ``n_task`` axes: ``None`` gives 3 points per axis."""
    if shape is None:
        return (3,) * n_task
    try:
        counts = tuple(int(c) for c in shape)
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(f"grid shape must be {n_task} point counts, got {shape!r}") from exc
    if (
        len(counts) != n_task
        or min(counts) < 1
        or any(isinstance(c, bool) or c != k for c, k in zip(shape, counts, strict=True))
    ):
        raise InvalidArgumentError(f"grid shape must be {n_task} point counts >= 1, got {shape!r}")
    check_size(counts, shape)
    return counts


def grid_targets(lower: Any, upper: Any, shape: Any) -> NDArray[np.float64]:
    """A regular grid over the box ``[lower, upper]``, the first axis varying slowest, as (N, n) [m].

    An axis with one point sits mid-way between its bounds.

    Raises:
        InvalidArgumentError: bounds not finite or not ordered, or more than :data:`MAX_GRID_POINTS` points.
    """
    try:
        lo = np.asarray(lower, dtype=float)
        hi = np.asarray(upper, dtype=float)
        counts = [int(c) for c in shape]
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(
            f"a target grid needs numeric lower, upper and shape, got {lower!r}, {upper!r}, {shape!r}"
        ) from exc
    if not (lo.shape == hi.shape == (len(counts),)) or not counts or min(counts) < 1:
        raise InvalidArgumentError(
            f"a target grid needs lower, upper and shape of one length, got {lower!r}, {upper!r}, {shape!r}"
        )
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo <= hi)):
        raise InvalidArgumentError(f"a target grid needs finite lower <= upper, got {lower!r}, {upper!r}")
    check_size(counts, shape)
    axes = [
        np.linspace(a, b, c) if c > 1 else np.array([(a + b) / 2])
        for a, b, c in zip(lo, hi, counts, strict=True)
    ]
    mesh = np.meshgrid(*axes, indexing="ij")
    return np.ascontiguousarray(np.stack([g.ravel() for g in mesh], axis=1))


def regular_grid(center: ArrayLike, half_width: float, shape: Sequence[int]) -> NDArray[np.float64]:
    """Grid of ``shape`` points over the cube ``center +- half_width``, the first axis slowest [m]."""
    check_size(shape, shape)
    c = np.asarray(center, dtype=float)
    axes = [
        np.linspace(v - half_width, v + half_width, k) if k > 1 else np.array([v])
        for v, k in zip(c, shape, strict=True)
    ]
    mesh = np.meshgrid(*axes, indexing="ij")
    return np.ascontiguousarray(np.stack([g.ravel() for g in mesh], axis=1))
