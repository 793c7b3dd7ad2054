"""Robots as data: presets read from the TOML files of ``robots/`` and procedural planar chains.

``load_robot("planar20")`` builds a 20-joint planar chain as a real ``pin.Model``;
``load_robot("talos_left_arm")`` loads the full TALOS model from example-robot-data
and locks every joint but the seven of the left arm. Either way the result is a
:class:`~gb_pin.robot.target.KinematicTarget` with the preset's home posture and target
set; :func:`robots` lists the presets, and each preset's ``[learner]`` table holds
its learner defaults (read by :func:`gb_pin.babble`).

A preset file (one per robot, installed as the package ``gb_pin.presets``)::

    name = "talos_left_arm"
    description = "..."
    kind = "humanoid arm"                  # a label for listings
    source = "example-robot-data"          # or "planar", or "urdf" (with urdf = "path")
    robot = "talos"                        # the example-robot-data name
    frame = "gripper_left_base_link"
    joints = ["arm_left_1_joint", ...]     # moved by the learner; the rest is locked
    home = [-0.4, 0.6, ...]                # over joints, or a reference configuration name
    axes = "xyz"
    [targets]                              # a grid, explicit points, or auto = true
    lower = [...]
    upper = [...]
    shape = [3, 3, 3]
    [learner]                              # defaults where the paper's do not fit
    sigma = 0.05

A stacked task (docs/TASKS.md) adds ``task = "pose"`` (or ``"pointing"``, with
``pointing_axis``, and ``orientation_scale``), or ``[[task]]`` tables (``kind = "position"``,
``frame``, ``axes``; ``kind = "orientation"``, ``scale``; ``kind = "pointing"``, ``axis``,
``scale``); its ``[targets]`` grid is the first position component's, with ``turn`` [deg],
``seed`` and ``mirror`` (:func:`gb_pin.robot.task_targets.task_grid`).
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin._names import closest
from gb_pin._reading import read_bytes
from gb_pin.exceptions import InvalidArgumentError, UnknownRobotError
from gb_pin.learn.config import NAMES, check_values
from gb_pin.robot.grids import grid_targets
from gb_pin.robot.planar import planar_chain, planar_home, planar_target
from gb_pin.robot.target import KinematicTarget

__all__ = [
    "RobotPreset",
    "format_presets",
    "get_preset",
    "grid_targets",
    "load_robot",
    "planar_chain",
    "planar_home",
    "robots",
]

MAX_PRESET_BYTES = 1 << 20
"""The largest preset file read (the packaged ones are under 2 kB)."""
MAX_PLANAR_JOINTS = 500
"""The longest planar chain ``planarN`` builds (the paper's go up to 50 joints)."""

_SOURCES = ("planar", "example-robot-data", "urdf")
_TASK_KEYS = ("task", "orientation_scale", "pointing_axis")
_COMMON_KEYS = (
    "name",
    "source",
    "description",
    "kind",
    "frame",
    "axes",
    "home",
    "targets",
    "learner",
    "safety",
    *_TASK_KEYS,
)
_SAFETY_KEYS = ("obstacles", "self_collision", "collision_geometry", "clearance", "slide")
_SOURCE_KEYS = {
    "planar": ("total_length", "min_joints"),
    "example-robot-data": ("robot", "joints"),
    "urdf": ("urdf", "srdf", "joints", "floating_base", "package_dirs"),
}


@dataclass(frozen=True)
class RobotPreset:
    """One robot (or family of robots) described by a TOML file in ``robots/``.

    Attributes:
        name: the preset name (``"planar"`` stands for the family ``planarN``).
        source: ``"planar"`` (procedural chains), ``"example-robot-data"`` or ``"urdf"``.
        description: one line for listings.
        frame: operational frame.
        axes: task axes seen by the learner.
        targets: the target set (N, n) [m] where the file gives a grid or points;
            None for ``auto`` targets (computed when the robot loads).
        learner: per-robot learner defaults, validated (keys among
            :data:`gb_pin.learn.config.NAMES`: ``learning_rate``, ``sigma``, ``sigma_delta``,
            ``radius``, ``path_length``, ``p_home``).
        options: the remaining entries of the file (e.g. ``total_length``).
        joints: the joints the learner moves (empty for the planar family).
        home: the home posture over ``joints``, a reference configuration name, or
            ``"paper"`` (planar family).
        robot: the example-robot-data name, or the URDF path, the model comes from.
        kind: a label for listings (``"planar arm"``, ``"arm"``, ``"humanoid arm"``).
        target_spec: the ``[targets]`` table as written.
        task: ``task``, ``orientation_scale`` and ``pointing_axis`` as written (empty for the
            plain position task): the :class:`~gb_pin.robot.target.KinematicTarget` arguments.
        safety: the ``[safety]`` table (``obstacles = [{kind = "table", height = 0.0}, ...]``,
            ``self_collision``, ``collision_geometry``, ``clearance``, ``slide``): a run of this preset checks
            every ask against them unless the run gives its own (:mod:`gb_pin.safety`).
    """

    name: str
    source: str
    description: str
    frame: str
    axes: str
    targets: NDArray[np.float64] | None
    learner: dict[str, Any] = field(default_factory=dict)
    options: dict[str, Any] = field(default_factory=dict)
    joints: tuple[str, ...] = ()
    home: tuple[float, ...] | str | None = None
    robot: str = ""
    kind: str = ""
    target_spec: dict[str, Any] = field(default_factory=dict)
    task: dict[str, Any] = field(default_factory=dict)
    safety: dict[str, Any] = field(default_factory=dict)

    @property
    def pattern(self) -> str:
        """The name users type (``planarN`` for the planar family)."""
        return f"{self.name}N" if self.source == "planar" else self.name

    @property
    def dof(self) -> str:
        """Number of joints the learner moves (``"N"`` for the planar family)."""
        return "N" if self.source == "planar" else str(len(self.joints))

    @property
    def n_targets(self) -> int:
        """Number of targets (for ``auto`` targets: the grid's point count)."""
        if self.targets is not None:
            return int(self.targets.shape[0])
        shape = self.target_spec.get("shape") or [3] * len(self.axes)
        return int(np.prod(shape))

    @property
    def origin(self) -> str:
        """Where the model comes from, for listings (``planar``, ``erd:talos``, ``urdf:file.urdf``)."""
        if self.source == "example-robot-data":
            return f"erd:{self.robot}"
        if self.source == "urdf":
            return f"urdf:{Path(self.robot).name}"
        return self.source


def _read_safety(table: Any) -> dict[str, Any]:
    """The ``[safety]`` table's keys checked (the obstacles are checked when a run uses them)."""
    if not isinstance(table, dict) or set(table) - set(_SAFETY_KEYS):
        raise InvalidArgumentError(
            f"[safety] must be a table of {', '.join(_SAFETY_KEYS)}, got {table!r:.200}"
        )
    obstacles = table.get("obstacles", [])
    if not isinstance(obstacles, list) or not all(isinstance(o, dict) for o in obstacles):
        raise InvalidArgumentError(
            '[safety] obstacles must be a list of tables like {kind = "table", height = 0.0}, '
            f"got {obstacles!r:.200}"
        )
    return dict(table)


def _read_learner(table: Any) -> dict[str, Any]:
    """The ``[learner]`` table, checked by :func:`gb_pin.learn.config.check_values` (names and values)."""
    if not isinstance(table, dict):
        raise InvalidArgumentError(f"[learner] must be a table of {', '.join(NAMES)}, got {table!r}")
    try:
        return check_values({str(k): v for k, v in table.items()}, what="learner keys")
    except InvalidArgumentError as exc:
        raise InvalidArgumentError(f"[learner] {exc}") from exc


def _read_preset(text: str | bytes, filename: str) -> RobotPreset:
    try:
        if isinstance(text, bytes):
            if len(text) > MAX_PRESET_BYTES:
                raise InvalidArgumentError(f"{len(text)} bytes; a preset has at most {MAX_PRESET_BYTES}")
            text = text.decode("utf-8")
        raw = tomllib.loads(text)
        source = raw.get("source")
        if source not in _SOURCES:
            raise InvalidArgumentError(f"source must be one of {list(_SOURCES)}, got {source!r}")
        unknown = set(raw) - set(_COMMON_KEYS) - set(_SOURCE_KEYS[source])
        if unknown:
            raise InvalidArgumentError(
                f"unknown keys {sorted(unknown)} for source {source!r}; valid: "
                f"{[*_COMMON_KEYS, *_SOURCE_KEYS[source]]}"
            )
        spec = dict(raw.pop("targets"))
        task = {k: raw.pop(k) for k in _TASK_KEYS if k in raw}
        if task and "task" not in task:
            raise InvalidArgumentError(f"{sorted(task)} need a task (e.g. task = 'pose')")
        if spec.get("auto") or task:  # stacked-task targets need the robot: resolved when it loads
            targets = None
        elif "points" in spec:
            targets = check.points("targets.points", spec["points"], len(str(raw.get("axes", "xyz"))))
        else:
            if set(spec) != {"lower", "upper", "shape"}:
                raise InvalidArgumentError(
                    "[targets] must be a grid (lower, upper, shape), points, or auto = true; "
                    f"got {sorted(spec)}"
                )
            targets = grid_targets(spec["lower"], spec["upper"], spec["shape"])
        learner = _read_learner(raw.pop("learner", {}))
        safety = _read_safety(raw.pop("safety", {}))
        name = str(raw.pop("name"))
        frame = str(raw.pop("frame"))
        axes = str(raw.pop("axes", "xyz"))
        if targets is not None and targets.shape[1] != len(axes):
            raise InvalidArgumentError(
                f"targets have {targets.shape[1]} coordinates, axes {axes!r} need {len(axes)}"
            )
        home = raw.pop("home", None)
        kind = str(raw.pop("kind", ""))
        source = str(raw.pop("source"))
        description = str(raw.pop("description", ""))
        joints: tuple[str, ...] = ()
        robot = ""
        if source != "planar":
            joints = tuple(str(j) for j in raw.pop("joints"))
            robot = str(raw.pop("robot" if source == "example-robot-data" else "urdf"))
            if isinstance(home, list):
                if len(home) != len(joints):
                    raise InvalidArgumentError(f"home has {len(home)} values for {len(joints)} joints")
                home = tuple(float(v) for v in home)
        return RobotPreset(
            name=name,
            source=source,
            description=description,
            frame=frame,
            axes=axes,
            targets=targets,
            learner=learner,
            options=raw,
            joints=joints,
            home=home,
            robot=robot,
            kind=kind,
            target_spec=spec,
            task=task,
            safety=safety,
        )
    except (tomllib.TOMLDecodeError, KeyError, TypeError, ValueError, OverflowError, RecursionError) as exc:
        raise InvalidArgumentError(f"malformed robot preset {filename}: {str(exc)[:200]}") from exc


_PRESETS: dict[str, RobotPreset] | None = None


def _presets() -> dict[str, RobotPreset]:
    global _PRESETS
    if _PRESETS is None:
        found = {}
        for entry in sorted(resources.files("gb_pin.presets").iterdir(), key=lambda e: e.name):
            if entry.name.endswith(".toml"):
                preset = _read_preset(_preset_bytes(entry), entry.name)
                if preset.name in found:
                    raise InvalidArgumentError(f"two robot presets are named {preset.name!r}")
                found[preset.name] = preset
        _PRESETS = found
    return _PRESETS


def _preset_bytes(entry: Any) -> bytes:
    """A preset file's bytes: a regular file of at most :data:`MAX_PRESET_BYTES` (read in bounds)."""
    if isinstance(entry, Path):
        return read_bytes(
            entry, f"robot preset {entry.name}", "preset file", MAX_PRESET_BYTES, InvalidArgumentError
        )
    return bytes(entry.read_bytes())


def robots() -> list[RobotPreset]:
    """All presets, sorted by name (the planar family appears once, as ``planarN``)."""
    return sorted(_presets().values(), key=lambda p: p.name)


def get_preset(name: str) -> tuple[RobotPreset, int | None]:
    """Find the preset for a robot name; for a family (``planarN``) also return N.

    Raises:
        UnknownRobotError: no preset of that name (the message lists the closest ones).
    """
    presets = _presets()
    valid = [p.pattern for p in robots()]
    if not isinstance(name, str):
        raise UnknownRobotError(
            f"robot name must be a string, got {name!r}; valid presets: {', '.join(valid)}"
        )
    for preset in presets.values():
        if preset.source != "planar":
            continue
        match = re.fullmatch(re.escape(preset.name) + r"(\d+)", name)
        if match:
            digits = match.group(1)
            m = int(digits) if len(digits) <= 9 else MAX_PLANAR_JOINTS + 1
            minimum = int(preset.options.get("min_joints", 2))
            if not minimum <= m <= MAX_PLANAR_JOINTS:
                raise UnknownRobotError(
                    f"robot {name[:40]!r}: {preset.name}N needs {minimum} <= N <= {MAX_PLANAR_JOINTS} "
                    f"(gb_pin.robot.presets.MAX_PLANAR_JOINTS), got N = {digits[:20]}"
                    + ("..." if len(digits) > 20 else "")
                )
            return preset, m
    if name in presets and presets[name].source != "planar":
        return presets[name], None
    candidates = [p.name if p.source != "planar" else f"{p.name}5" for p in presets.values()]
    close = list(dict.fromkeys(closest(name, [*valid, *candidates], n=3))) if len(name) <= 100 else []
    hint = f"; did you mean {', '.join(close)}?" if close else ";"
    planar = f"(2 <= N <= {MAX_PLANAR_JOINTS})"
    raise UnknownRobotError(f"unknown robot {name[:100]!r}{hint} valid presets: {', '.join(valid)} {planar}")


def _preset_path(path: str) -> str:
    """A URDF/SRDF path of a preset: absolute, or relative to the presets' directory."""
    p = Path(path)
    if p.is_absolute():
        return str(p)
    return str(Path(str(resources.files("gb_pin.presets"))) / p)


def load_robot(name: str) -> KinematicTarget:
    """Load a preset robot as a :class:`KinematicTarget` with its home posture and targets.

    Args:
        name: a preset name, e.g. ``"planar5"``, ``"planar20"`` (any 2 <= N <= 500,
            :data:`MAX_PLANAR_JOINTS`),
            ``"talos_left_arm"``, ``"panda"`` (see :func:`robots`).

    Raises:
        UnknownRobotError: unknown name (the message suggests the closest).
    """
    preset, m = get_preset(name)
    return _load_preset(preset, m, name)


def _load_preset(preset: RobotPreset, m: int | None, name: str) -> KinematicTarget:
    """Build the KinematicTarget a preset describes (``m`` joints for the planar family)."""
    if preset.source == "planar":
        if m is None:
            raise InvalidArgumentError(f"preset {preset.name!r} is a family: give its number of joints")
        length = float(preset.options.get("total_length", 1.0))
        if preset.frame == "tip":  # the arrays directly, pinocchio only when asked for
            return planar_target(m, length, axes=preset.axes, targets=preset.targets, name=name)
        return KinematicTarget(
            planar_chain(m, length), preset.frame, home=planar_home(m), axes=preset.axes,
            targets=preset.targets, name=name,
        )  # fmt: skip
    spec: Any = preset.targets if preset.targets is not None else preset.target_spec
    home_arg: Any = list(preset.home) if isinstance(preset.home, tuple) else preset.home
    if preset.source == "example-robot-data":
        return KinematicTarget.from_example_robot_data(
            preset.robot,
            preset.frame,
            list(preset.joints),
            home_arg,
            preset.axes,
            targets=spec,
            label=name,
            onboard=False,  # a preset's file states its home, joints and targets: nothing is measured
            **preset.task,
        )
    options = preset.options
    srdf = options.get("srdf")
    dirs = options.get("package_dirs")
    return KinematicTarget.from_urdf(
        _preset_path(preset.robot),
        preset.frame,
        list(preset.joints),
        home_arg,
        preset.axes,
        package_dirs=None if dirs is None else [_preset_path(str(d)) for d in dirs],
        srdf=None if srdf is None else _preset_path(str(srdf)),
        floating_base=bool(options.get("floating_base", False)),
        targets=spec,
        name=name,
        onboard=False,
        **preset.task,
    )


def format_presets() -> str:
    """The presets as a text table: name, DOF, task axes, frame, source, number of targets, kind."""
    rows = [("name", "DOF", "axes", "frame", "source", "targets", "kind")]
    for p in robots():
        axes = p.axes if not p.task else task_label(p.task["task"], p.axes)
        rows.append((p.pattern, p.dof, axes, p.frame, p.origin, str(p.n_targets), p.kind))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    right = {1, 5}
    lines = [
        "  ".join(c.rjust(widths[i]) if i in right else c.ljust(widths[i]) for i, c in enumerate(r)).rstrip()
        for r in rows
    ]
    return "\n".join(lines)


def task_label(task: Any, axes: str) -> str:
    """A short label of a stacked task for listings: ``xyz+R`` (pose), ``xyz+d`` (pointing), ``xyz+xyz``."""
    if task == "pose":
        return f"{axes}+R"
    if task == "pointing":
        return f"{axes}+d"
    if isinstance(task, list):
        marks = {"orientation": "R", "pointing": "d"}
        kinds = [(str(t.get("kind")), str(t.get("axes", "xyz"))) for t in task if isinstance(t, dict)]
        return "+".join(axes if kind == "position" else marks.get(kind, "?") for kind, axes in kinds)
    return str(task)
