"""The environment as simple shapes in the world frame [m]: a table, boxes and spheres.

>>> obstacles = [Table(0.0), Box(center=(0.21, 0, 0.045), half_extents=(0.02, 0.02, 0.045))]

They are given to ``babble(obstacles=...)``, ``babble_session``, trials, a preset's ``[safety]``
table and the command line (:func:`parse_obstacle`: ``table:0.0``,
``box:center=0.21,0,0.045,half=0.02,0.02,0.045``, ``sphere:center=0.3,0,0.2,radius=0.05``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError

MAX_OBSTACLES = 1000
"""The most obstacles a run takes (each is checked against every link at every ask)."""
MAX_COORDINATE = 1e3
"""Obstacle coordinates and sizes beyond this [m] are refused (a typo, not a workspace)."""


def _real(name: str, value: Any) -> float:
    if not check._is_real(value) or not math.isfinite(float(value)) or abs(float(value)) > MAX_COORDINATE:
        raise InvalidArgumentError(f"{name} must be a finite number of metres (|v| <= 1000), got {value!r}")
    return float(value)


def _triple(name: str, value: Any, positive: bool = False) -> tuple[float, float, float]:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(f"{name} must be 3 numbers [m], got {value!r:.100}") from exc
    if arr.shape != (3,) or not np.isfinite(arr).all() or (np.abs(arr) > MAX_COORDINATE).any():
        raise InvalidArgumentError(f"{name} must be 3 finite numbers [m] (|v| <= 1000), got {value!r:.100}")
    if positive and not (arr > 0).all():
        raise InvalidArgumentError(f"{name} must be 3 numbers > 0 [m], got {arr.tolist()}")
    return (float(arr[0]), float(arr[1]), float(arr[2]))


@dataclass(frozen=True)
class Table:
    """Everything below ``height`` [m] (world z) is solid: the half-space z <= height."""

    height: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "height", _real("Table height", self.height))

    def contains(self, points: NDArray[np.float64], margin: float = 0.0) -> NDArray[np.bool_]:
        """Which points (N, 3) lie within ``margin`` of the solid."""
        return np.asarray(points)[:, 2] <= self.height + margin


@dataclass(frozen=True)
class Box:
    """An axis-aligned box: ``center`` (3,) [m] and ``half_extents`` (3,) [m], world frame."""

    center: ArrayLike
    half_extents: ArrayLike

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", _triple("Box center", self.center))
        object.__setattr__(self, "half_extents", _triple("Box half_extents", self.half_extents, True))

    def contains(self, points: NDArray[np.float64], margin: float = 0.0) -> NDArray[np.bool_]:
        """Which points (N, 3) lie within ``margin`` of the box (its faces pushed out by the margin)."""
        d = np.abs(np.asarray(points) - np.asarray(self.center)) - np.asarray(self.half_extents)
        outside = np.linalg.norm(np.maximum(d, 0.0), axis=1)
        return outside <= margin


@dataclass(frozen=True)
class Sphere:
    """A ball: ``center`` (3,) [m] and ``radius`` [m], world frame."""

    center: ArrayLike
    radius: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "center", _triple("Sphere center", self.center))
        object.__setattr__(self, "radius", check.positive_float("Sphere radius", self.radius))
        _real("Sphere radius", self.radius)

    def contains(self, points: NDArray[np.float64], margin: float = 0.0) -> NDArray[np.bool_]:
        """Which points (N, 3) lie within ``margin`` of the ball."""
        return np.linalg.norm(np.asarray(points) - np.asarray(self.center), axis=1) <= self.radius + margin


Obstacle = Table | Box | Sphere
KINDS = ("table", "box", "sphere")


def check_obstacles(obstacles: Any) -> tuple[Obstacle, ...]:
    """A sequence of obstacles checked (each a Table, Box or Sphere, or a dict as a preset writes it).

    Raises:
        InvalidArgumentError: anything else, or more than :data:`MAX_OBSTACLES`.
    """
    if obstacles is None:
        return ()
    if isinstance(obstacles, Table | Box | Sphere | dict | str):
        obstacles = [obstacles]
    try:
        items = list(obstacles)
    except TypeError as exc:
        raise InvalidArgumentError(
            f"obstacles must be a list of gb_pin.Table, Box or Sphere, got {obstacles!r:.100}"
        ) from exc
    if len(items) > MAX_OBSTACLES:
        raise InvalidArgumentError(f"at most {MAX_OBSTACLES} obstacles, got {len(items)}")
    out: list[Obstacle] = []
    for item in items:
        if isinstance(item, Table | Box | Sphere):
            out.append(item)
        elif isinstance(item, dict):
            out.append(from_dict(item))
        elif isinstance(item, str):
            out.append(parse_obstacle(item))
        else:
            raise InvalidArgumentError(
                f"an obstacle must be a gb_pin.Table, Box or Sphere, got {item!r:.100}"
            )
    return tuple(out)


def plain(obstacle: Obstacle) -> dict[str, Any]:
    """An obstacle as a plain table (JSON, TOML), the inverse of :func:`from_dict`."""
    if isinstance(obstacle, Table):
        return {"kind": "table", "height": obstacle.height}
    if isinstance(obstacle, Box):
        return {"kind": "box", "center": list(obstacle.center), "half_extents": list(obstacle.half_extents)}  # type: ignore[arg-type]
    return {"kind": "sphere", "center": list(obstacle.center), "radius": obstacle.radius}  # type: ignore[arg-type]


def from_dict(table: dict[str, Any]) -> Obstacle:
    """An obstacle from a preset's table: ``{kind = "box", center = [...], half_extents = [...]}``.

    Raises:
        InvalidArgumentError: an unknown kind or field.
    """
    fields = dict(table)
    kind = fields.pop("kind", None)
    allowed = {"table": ("height",), "box": ("center", "half_extents"), "sphere": ("center", "radius")}
    if kind not in allowed:
        raise InvalidArgumentError(f"obstacle kind must be one of {', '.join(KINDS)}, got {kind!r:.50}")
    unknown = sorted(set(fields) - set(allowed[kind]))
    if unknown:
        raise InvalidArgumentError(
            f"unknown field(s) {unknown} of a {kind} obstacle; valid: {', '.join(allowed[kind])}"
        )
    try:
        return {"table": Table, "box": Box, "sphere": Sphere}[kind](**fields)
    except TypeError as exc:
        raise InvalidArgumentError(
            f"a {kind} obstacle needs {', '.join(allowed[kind])}: got {table!r:.100}"
        ) from exc


def parse_obstacle(text: str) -> Obstacle:
    """An obstacle from the command line.

    ``table:0.0``, ``box:center=x,y,z,half=a,b,c``, ``sphere:center=x,y,z,radius=r`` [m].

    Raises:
        InvalidArgumentError: naming what is wrong and the valid forms.
    """
    forms = "table:HEIGHT, box:center=X,Y,Z,half=A,B,C or sphere:center=X,Y,Z,radius=R"
    kind, _, rest = str(text).partition(":")
    kind = kind.strip().lower()
    try:
        if kind == "table":
            return Table(float(rest.replace("height=", "")))
        values: dict[str, list[float]] = {}
        key = None
        for token in rest.split(","):
            if "=" in token:
                key, _, token = token.partition("=")
                key = key.strip()
                values[key] = []
            if key is None:
                raise ValueError(token)
            values[key].append(float(token))
        if kind == "box" and set(values) == {"center", "half"}:
            return Box(values["center"], values["half"])
        if kind == "sphere" and set(values) == {"center", "radius"} and len(values["radius"]) == 1:
            return Sphere(values["center"], values["radius"][0])
    except ValueError as exc:
        if isinstance(exc, InvalidArgumentError):
            raise
        raise InvalidArgumentError(f"cannot read the obstacle {text!r:.100}; write {forms}") from exc
    raise InvalidArgumentError(f"cannot read the obstacle {text!r:.100}; write {forms}")
