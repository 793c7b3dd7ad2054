"""Target sets of a robot: the ``"auto"`` grid and target specs (arrays, grids, points, auto).

The ``"auto"`` target set is the largest regular grid (``shape``, default 3 per task
axis) centred on the home effector position whose points all pass
:func:`~gb_pin.robot.reachability.check_reachable`. :func:`resolve_targets` turns a
target spec (a constructor argument or a preset file's ``[targets]`` table) into points.

This module imports neither pinocchio nor meshcat, nor the robot class: it works on
anything with a chain, a home posture and joint limits
(:class:`~gb_pin.robot.reachability.Robot`); :func:`resolve_targets` also needs the
robot's target checks (:class:`TargetRobot`). The reachability checks are re-exported
here (``check_reachable``, ``beyond_reach``, ...), where they used to live.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.robot.grids import grid_shape, grid_targets, regular_grid
from gb_pin.robot.reachability import (
    SAMPLES,
    TOLERANCE,
    Reachability,
    Robot,
    beyond_reach,
    check_reachable,
    sample_positions,
    sampling_bounds,
)
from gb_pin.robot.task_targets import task_grid

__all__ = [
    "SAMPLES",
    "TOLERANCE",
    "AutoGrid",
    "Reachability",
    "Robot",
    "TargetRobot",
    "TargetSpec",
    "auto_grid",
    "auto_task_grid",
    "beyond_reach",
    "check_reachable",
    "grid_targets",
    "regular_grid",
    "resolve_targets",
    "sample_positions",
    "sampling_bounds",
]


TargetSpec = ArrayLike | str | Mapping[str, Any] | None
"""A target set: an (N, n) array [m], ``"auto"``, a grid spec or an explicit-points spec (see
:func:`resolve_targets`)."""


class TargetRobot(Robot, Protocol):
    """What :func:`resolve_targets` needs of a robot (a :class:`~gb_pin.robot.target.KinematicTarget`)."""

    @property
    def n_task(self) -> int:
        """Task dimension n."""

    @property
    def axes(self) -> str:
        """The task axes, e.g. ``"xyz"``."""

    def auto_targets(self) -> NDArray[np.float64]:
        """The ``"auto"`` target set (N, n) [m] (:func:`auto_grid` with its defaults, cached)."""

    def check_targets(self, targets: ArrayLike, what: str = "targets") -> NDArray[np.float64]:
        """Explicit targets (N, n) [m] validated; a warning for those beyond the arm's reach."""


@dataclass(frozen=True, eq=False)
class AutoGrid:
    """The ``"auto"`` target set and how it was found.

    Attributes:
        targets: (N, n) grid points [m], all reachable.
        center: (n,) the home effector position [m].
        half_width: half the grid's edge [m].
        shape: points per task axis.
        largest_half_width: the largest reachable half-width found [m] (``half_width`` is a
            ``scale`` of it).
    """

    targets: NDArray[np.float64]
    center: NDArray[np.float64]
    half_width: float
    shape: tuple[int, ...]
    largest_half_width: float = math.nan

    @property
    def lower(self) -> NDArray[np.float64]:
        """Lower corner of the grid [m]."""
        return self.center - self.half_width

    @property
    def upper(self) -> NDArray[np.float64]:
        """Upper corner of the grid [m]."""
        return self.center + self.half_width


def auto_grid(
    robot: Robot,
    shape: Sequence[int] | None = None,
    *,
    seed: int = 0,
    samples: int = SAMPLES,
    scale: float = 1.0,
    resolution: float = 0.005,
    deadline: Any = None,
) -> AutoGrid:
    """The largest reachable regular grid centred on the home effector position.

    The half-width is searched by bisection between 0 and the extent of the sampled
    positions, kept to multiples of ``resolution``; every point of the returned grid
    passed :func:`check_reachable`. ``scale`` < 1 shrinks the largest grid (after the
    search, in steps of ``resolution``) to keep the targets away from the workspace's
    border.

    Args:
        robot: anything with chain, home, lower and upper, e.g. a
            :class:`~gb_pin.robot.target.KinematicTarget`.
        shape: points per task axis; default 3 per axis (27 points in 3-D).
        seed: seed of the posture sampling.
        samples: postures sampled.
        scale: fraction of the largest reachable half-width to use, in (0, 1].
        resolution: the half-width is a multiple of this [m].
        deadline: an object whose ``check()`` raises once the time is spent (onboarding's
            :class:`~gb_pin.robot.onboarding.Budget`), called before each grid is measured.

    Raises:
        InvalidArgumentError: bad arguments, or no grid of at least ``resolution``
            half-width is reachable (the home sits at the workspace's border).
    """
    counts = grid_shape(shape, robot.chain.n_task)
    scale = check.positive_float("scale", scale)
    if scale > 1.0:
        raise InvalidArgumentError(f"scale must be in (0, 1], got {scale!r}")
    resolution = check.positive_float("resolution", resolution)
    sampled = sample_positions(robot, samples, seed)
    center = robot.chain.forward(np.ascontiguousarray(robot.home, dtype=float))

    def ok(h: float) -> bool:
        if deadline is not None:
            deadline.check()
        grid = regular_grid(center, h, counts)
        return bool(np.all(check_reachable(robot, grid, sampled=sampled).reachable))

    hi = int(np.max(np.abs(sampled[1] - center)) / resolution) + 1  # in units of resolution
    lo = 0  # largest known-good half-width (0: the home itself)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if ok(mid * resolution):
            lo = mid
        else:
            hi = mid
    chosen = math.floor(lo * scale)
    while chosen > 0 and not ok(chosen * resolution):
        chosen -= 1
    if chosen == 0:
        raise InvalidArgumentError(
            f"no reachable grid of half-width >= {resolution} m around the home effector position "
            f"{center.round(4).tolist()}: the home is at the border of the workspace; choose a home inside it"
        )
    h = chosen * resolution
    return AutoGrid(
        targets=regular_grid(center, h, counts),
        center=center,
        half_width=h,
        shape=counts,
        largest_half_width=lo * resolution,
    )


_SPEC_KEYS = ("lower", "upper", "shape", "points", "auto", "scale", "seed", "turn", "mirror")
_TASK_GRID_KEYS = {"lower", "upper", "shape", "turn", "seed", "mirror"}


def resolve_targets(spec: Any, robot: TargetRobot, what: str = "targets") -> NDArray[np.float64]:
    """A target set from its description (constructor argument or preset file).

    Args:
        spec: an (N, n) array of points [m]; ``"auto"``; or a mapping: a grid
            ``{"lower": [...], "upper": [...], "shape": [...]}``, explicit points
            ``{"points": [[...], ...]}``, or ``{"auto": True}`` with optional
            ``shape`` (points per axis), ``scale`` and ``seed`` (see :func:`auto_grid`). For a
            robot with a stacked task (orientations, several frames), a grid spec is the grid of
            its first position component, with optional ``turn`` [deg], ``seed`` and ``mirror``
            (see :func:`gb_pin.robot.task_targets.task_grid`).
        robot: the robot the targets are for (:class:`TargetRobot`), e.g. a
            :class:`~gb_pin.robot.target.KinematicTarget`.
        what: the argument's name in messages.

    Returns:
        (N, n) targets [m], world coordinates on the robot's task axes.

    Raises:
        InvalidArgumentError: malformed spec, wrong dimension, non-finite values.
    """
    if isinstance(spec, str):
        if spec != "auto":
            raise InvalidArgumentError(
                f"{what} must be an (N, {robot.n_task}) array, 'auto', or a grid/points spec, got {spec!r}"
            )
        return robot.auto_targets()
    if isinstance(spec, Mapping):
        unknown = sorted(set(spec) - set(_SPEC_KEYS))
        if unknown:
            raise InvalidArgumentError(f"unknown keys {unknown} in {what} spec; valid: {list(_SPEC_KEYS)}")
        if (
            getattr(robot.chain, "components", None) is not None
            and "points" not in spec
            and not spec.get("auto")
        ):
            if not {"lower", "upper", "shape"} <= set(spec) <= _TASK_GRID_KEYS:
                raise InvalidArgumentError(
                    f"{what} spec of a stacked task must be a grid (lower, upper, shape) with optional "
                    f"turn, seed, mirror; got keys {sorted(spec)}"
                )
            return task_grid(
                robot, spec["lower"], spec["upper"], spec["shape"], turn=spec.get("turn", 0.0),
                seed=spec.get("seed", 0), mirror=spec.get("mirror"),
            )  # fmt: skip
        if spec.get("auto"):
            extra = sorted(set(spec) - {"auto", "shape", "scale", "seed"})
            if extra:
                raise InvalidArgumentError(
                    f"{what} spec with auto takes shape, scale, seed; got also {extra}"
                )
            seed = spec.get("seed", 0)
            if isinstance(seed, bool) or not isinstance(seed, int):
                raise InvalidArgumentError(f"{what} seed must be an integer, got {seed!r}")
            if getattr(robot.chain, "components", None) is not None:
                if "scale" in spec:
                    raise InvalidArgumentError(f"{what} spec with auto of a stacked task takes shape, seed")
                return auto_task_grid(robot, spec.get("shape"), seed=seed)
            return auto_grid(robot, spec.get("shape"), seed=seed, scale=spec.get("scale", 1.0)).targets
        if "points" in spec:
            if set(spec) != {"points"}:
                raise InvalidArgumentError(f"{what} spec with points takes nothing else, got {sorted(spec)}")
            return robot.check_targets(spec["points"], what)
        if {"lower", "upper", "shape"} == set(spec):
            if len(spec["shape"]) != robot.n_task if hasattr(spec["shape"], "__len__") else True:
                raise InvalidArgumentError(
                    f"{what} grid shape must have {robot.n_task} entries (axes {robot.axes!r}), "
                    f"got {spec['shape']!r}"
                )
            return robot.check_targets(grid_targets(spec["lower"], spec["upper"], spec["shape"]), what)
        raise InvalidArgumentError(
            f"{what} spec must be a grid (lower, upper, shape), points, or auto; got keys {sorted(spec)}"
        )
    return robot.check_targets(spec, what)


class _PositionView:
    """A robot's target frame seen as a plain position task (the position grid of :func:`auto_task_grid`)."""

    def __init__(self, robot: Robot):
        self.chain = dataclasses.replace(robot.chain, components=None)
        self.home, self.lower, self.upper = robot.home, robot.lower, robot.upper


def auto_task_grid(
    robot: Robot, shape: Sequence[int] | None = None, *, turn: float = 0.0, seed: int = 0, step: float = 0.01
) -> NDArray[np.float64]:
    """The ``"auto"`` target set of a stacked task whose first component is the target frame's position.

    The largest reachable position grid of the frame (:func:`auto_grid`), shrunk (by bisection,
    to multiples of ``step`` [m]) until :func:`~gb_pin.robot.task_targets.task_grid` (with
    ``turn``) reaches every point.

    Raises:
        InvalidArgumentError: no such grid of half-width >= ``step``.
    """
    view = _PositionView(robot)
    grid = auto_grid(view, shape, seed=seed)

    def points(units: int) -> NDArray[np.float64] | None:
        h = units * step
        try:
            return task_grid(robot, grid.center - h, grid.center + h, grid.shape, turn=turn, seed=seed)
        except InvalidArgumentError:
            return None

    lo, hi = 0, int(grid.half_width / step) + 1  # bisection on the half-width, in units of step
    best = None
    while hi - lo > 1:
        mid = (lo + hi) // 2
        found = points(mid)
        if found is None:
            hi = mid
        else:
            lo, best = mid, found
    if best is not None:
        return best
    raise InvalidArgumentError(
        f"no reachable task grid of half-width >= {step} m around the home position "
        f"{grid.center.round(4).tolist()}"
    )
