"""What the learner's task vector x is: small frozen specs of its components, checked.

A :class:`~gb_pin.robot.target.KinematicTarget` learns ``task=``:

* ``None`` or ``"position"``: the frame's position on ``axes`` [m] (the paper's task);
* ``"pose"``: ``(Position(frame, axes), Orientation(frame, orientation_scale))``;
* ``"pointing"``: ``(Position(frame, axes), Pointing(frame, pointing_axis, orientation_scale))``;
* a sequence of :class:`Position`, :class:`Orientation` and :class:`Pointing` specs, of one
  or several frames (e.g. both hands' positions), stacked in that order.

Units: position rows in [m]; rotational rows are ``scale`` [m/rad] times an angle [rad]
(see :mod:`gb_pin.learn.body.components`), so that the learner's radius and E^X weigh one
radian like ``scale`` metres.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import InvalidArgumentError

DEFAULT_ORIENTATION_SCALE = 0.2
"""Default s [m/rad] of rotational components: 1 rad counts like 0.2 m (docs/TASKS.md)."""
TASK_NAMES = ("position", "pose", "pointing")
_AXIS_LETTERS = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


def check_scale(scale: Any, what: str = "scale") -> float:
    """A finite scale > 0 [m/rad].

    Raises:
        InvalidArgumentError: anything else.
    """
    if isinstance(scale, bool) or not isinstance(scale, (int, float, np.integer, np.floating)):
        raise InvalidArgumentError(f"{what} must be a number > 0 [m/rad], got {scale!r}")
    if not (math.isfinite(float(scale)) and float(scale) > 0.0):
        raise InvalidArgumentError(f"{what} must be finite and > 0 [m/rad], got {scale!r}")
    return float(scale)


def check_axis(axis: Any) -> NDArray[np.float64]:
    """A unit pointing axis from ``"x"``, ``"y"``, ``"z"`` (``"-z"`` ...) or a nonzero finite 3-vector.

    Raises:
        InvalidArgumentError: anything else.
    """
    if isinstance(axis, str):
        sign, letter = (-1.0, axis[1:]) if axis.startswith("-") else (1.0, axis)
        if letter not in _AXIS_LETTERS:
            raise InvalidArgumentError(
                f"pointing axis must be 'x', 'y', 'z' (or '-x', ...) or a 3-vector, got {axis!r}"
            )
        return sign * np.array(_AXIS_LETTERS[letter])
    try:
        v = np.asarray(axis, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(f"pointing axis must be a letter or a 3-vector, got {axis!r}") from exc
    norm = float(np.linalg.norm(v)) if v.shape == (3,) and np.all(np.isfinite(v)) else 0.0
    if norm < 1e-9:
        raise InvalidArgumentError(
            f"pointing axis must be a finite nonzero 3-vector or 'x', 'y', 'z', got {axis!r}"
        )
    return v / norm


def _check_reference(reference: Any, shape: tuple[int, ...], what: str) -> NDArray[np.float64] | None:
    if reference is None:
        return None
    try:
        r = np.asarray(reference, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(f"{what} must be an array of shape {shape}, got {reference!r}") from exc
    if r.shape != shape or not np.all(np.isfinite(r)):
        raise InvalidArgumentError(f"{what} must be a finite array of shape {shape}, got {reference!r}")
    if shape == (3, 3) and (not np.allclose(r.T @ r, np.eye(3), atol=1e-6) or np.linalg.det(r) < 0):
        raise InvalidArgumentError(
            f"{what} must be a rotation matrix (orthonormal, det +1), got {r.tolist()}"
        )
    if shape == (3,):
        norm = float(np.linalg.norm(r))
        if norm < 1e-9:
            raise InvalidArgumentError(f"{what} must be a nonzero direction, got {r.tolist()}")
        r = r / norm
    return r


@dataclass(frozen=True)
class Position:
    """The position of a frame on world axes [m].

    Attributes:
        frame: the frame's name; None for the target's ``frame``.
        axes: the world coordinates, distinct letters of ``"xyz"``.
    """

    frame: str | None = None
    axes: str = "xyz"

    def __post_init__(self) -> None:
        axes = self.axes
        if not isinstance(axes, str) or not axes or len(set(axes)) != len(axes) or set(axes) - set("xyz"):
            raise InvalidArgumentError(
                f"Position axes must be distinct letters from 'xyz' (e.g. 'xy', 'xyz'), got {axes!r}"
            )


@dataclass(frozen=True)
class Orientation:
    """The full orientation of a frame: ``scale * log(R_ref^T R)`` (3 rows, [m]).

    Attributes:
        frame: the frame's name; None for the target's ``frame``.
        scale: s [m/rad], finite and > 0.
        reference: R_ref (3, 3) in the world; None for the frame's rotation at home.
    """

    frame: str | None = None
    scale: float = DEFAULT_ORIENTATION_SCALE
    reference: Any = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "scale", check_scale(self.scale, "Orientation scale"))
        object.__setattr__(
            self, "reference", _check_reference(self.reference, (3, 3), "Orientation reference")
        )


@dataclass(frozen=True)
class Pointing:
    """The world direction of one axis of a frame, in 2 tangent coordinates (2 rows, [m]).

    Attributes:
        frame: the frame's name; None for the target's ``frame``.
        axis: the axis in the frame (``"x"``, ``"y"``, ``"z"``, ``"-z"`` or a 3-vector).
        scale: s [m/rad], finite and > 0.
        reference: the reference world direction d0 (3,); None for the axis at home.
    """

    frame: str | None = None
    axis: Any = "z"
    scale: float = DEFAULT_ORIENTATION_SCALE
    reference: Any = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "axis", check_axis(self.axis))
        object.__setattr__(self, "scale", check_scale(self.scale, "Pointing scale"))
        object.__setattr__(self, "reference", _check_reference(self.reference, (3,), "Pointing reference"))


TaskComponentSpec = Position | Orientation | Pointing
TaskSpec = str | Sequence[TaskComponentSpec | Mapping[str, Any]] | None
"""What ``KinematicTarget(task=...)`` takes (see the module docstring)."""
_KINDS = {"position": Position, "orientation": Orientation, "pointing": Pointing}


def from_mapping(table: Mapping[str, Any]) -> TaskComponentSpec:
    """A spec from a table (a preset's ``[[task]]`` entry): ``{"kind": "orientation", "scale": 0.2, ...}``.

    Raises:
        InvalidArgumentError: unknown kind or keys.
    """
    entries = dict(table)
    kind = entries.pop("kind", None)
    if kind not in _KINDS:
        raise InvalidArgumentError(f"task component kind must be one of {list(_KINDS)}, got {kind!r}")
    cls: Any = _KINDS[kind]
    valid = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(entries) - valid)
    if unknown:
        raise InvalidArgumentError(
            f"unknown keys {unknown} of a {kind} task component; valid: {sorted(valid)}"
        )
    spec: TaskComponentSpec = cls(**entries)
    return spec


def resolve_task(
    task: TaskSpec, frame: str, axes: str, orientation_scale: float | None, pointing_axis: Any = None
) -> tuple[TaskComponentSpec, ...] | None:
    """The components of ``task`` (frames resolved to ``frame``), None for the plain position task.

    ``orientation_scale`` goes with the names ``"pose"`` and ``"pointing"`` only, and
    ``pointing_axis`` (default ``"z"``) with ``"pointing"`` only: given with another task they
    would be ignored, so they are refused (a list of specs carries its own).

    Raises:
        InvalidArgumentError: an unknown task name, a bad scale or axis, an argument the task
            does not use, an empty or malformed sequence, or the same component twice.
    """
    uses = {"orientation_scale": ("pose", "pointing"), "pointing_axis": ("pointing",)}
    for name, value in (("orientation_scale", orientation_scale), ("pointing_axis", pointing_axis)):
        if value is not None and not (isinstance(task, str) and task in uses[name]):
            raise InvalidArgumentError(
                f"{name}={value!r} goes with task={' or '.join(map(repr, uses[name]))} only; "
                f"task={task!r} would ignore it (a list of specs gives it in each spec)"
            )
    scale = (
        DEFAULT_ORIENTATION_SCALE
        if orientation_scale is None
        else check_scale(orientation_scale, "orientation_scale")
    )
    if task is None or task == "position":
        return None
    if isinstance(task, str):
        if task == "pose":
            specs: list[Any] = [Position(frame, axes), Orientation(frame, scale)]
        elif task == "pointing":
            axis = "z" if pointing_axis is None else pointing_axis
            specs = [Position(frame, axes), Pointing(frame, axis, scale)]
        else:
            raise InvalidArgumentError(
                f"task must be one of {list(TASK_NAMES)} or a sequence of Position, Orientation and "
                f"Pointing specs, got {task!r}"
            )
    elif isinstance(task, Sequence) and len(task) > 0:
        specs = [from_mapping(t) if isinstance(t, Mapping) else t for t in task]
    else:
        raise InvalidArgumentError(f"task must be a name or a nonempty sequence of specs, got {task!r}")
    out = []
    for spec in specs:
        if not isinstance(spec, (Position, Orientation, Pointing)):
            raise InvalidArgumentError(
                f"task components must be Position, Orientation or Pointing specs, got {spec!r}"
            )
        if spec.frame is None:
            spec = type(spec)(**{**spec.__dict__, "frame": frame})
        if not isinstance(spec.frame, str):
            raise InvalidArgumentError(f"task component frame must be a frame name, got {spec.frame!r}")
        out.append(spec)
    keys = [(type(s).__name__, s.frame) for s in out]
    if len(set(keys)) != len(keys):
        raise InvalidArgumentError(f"task lists a component twice: {keys}")
    return tuple(out)


def component_label(spec: TaskComponentSpec) -> str:
    """A short label, e.g. ``"position gripper_left_base_link"``."""
    return f"{type(spec).__name__.lower()} {spec.frame}"
