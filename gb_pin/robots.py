"""Robots as data: presets read from the TOML files of ``robots/`` and procedural planar chains.

``load_robot("planar20")`` builds a 20-joint planar chain as a real ``pin.Model``
and wraps it in a :class:`~gb_pin.target.KinematicTarget` with the preset's home
posture and target set. :func:`robots` lists the presets.
"""

from __future__ import annotations

import difflib
import math
import re
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError, UnknownRobotError
from gb_pin.target import KinematicTarget

_LEARNER_KEYS = ("learning_rate", "sigma", "sigma_delta", "radius", "path_length", "p_home")


def planar_chain(m: int, total_length: float = 1.0) -> pin.Model:
    """A planar chain of ``m`` revolute z-joints and ``m`` equal segments (paper, Sec. III).

    Joint 1 sits at the world origin; joint i+1 sits at the end of segment i; the
    operational frame ``"tip"`` sits at the end of the last segment. Each segment
    carries a thin-rod inertia (mass 1 kg) so that the model is a valid dynamic
    model too.

    Args:
        m: number of joints (>= 1).
        total_length: length of the whole arm [m].

    Returns:
        The Pinocchio model, joints named ``joint1`` .. ``joint{m}``.
    """
    m = check.positive_int("m", m)
    total_length = check.positive_float("total_length", total_length)
    segment = total_length / m
    model = pin.Model()
    model.name = f"planar{m}"
    parent = 0
    offset = pin.SE3.Identity()
    rod = pin.Inertia.FromCylinder(1.0, 0.01 * segment, segment)
    # FromCylinder is about the z-axis; the rod lies along x from the joint.
    rod_inertia = pin.Inertia(
        1.0,
        np.array([segment / 2.0, 0.0, 0.0]),
        np.diag([rod.inertia[2, 2], rod.inertia[0, 0], rod.inertia[0, 0]]),
    )
    for i in range(m):
        parent = model.addJoint(parent, pin.JointModelRZ(), offset, f"joint{i + 1}")
        model.appendBodyToJoint(parent, rod_inertia, pin.SE3.Identity())
        model.addFrame(pin.Frame(f"joint{i + 1}", parent, 0, pin.SE3.Identity(), pin.FrameType.JOINT))
        offset = pin.SE3(np.eye(3), np.array([segment, 0.0, 0.0]))
    model.addFrame(pin.Frame("tip", parent, 0, offset, pin.FrameType.OP_FRAME))
    return model


def planar_home(m: int) -> NDArray[np.float64]:
    """The paper's home posture: q_1 = -pi/3, q_i = 2 pi / (3 (m - 1)) for i > 1 [rad]."""
    home = np.full(m, 2.0 * math.pi / (3.0 * (m - 1)) if m > 1 else 0.0)
    home[0] = -math.pi / 3.0
    return home


def grid_targets(lower: Any, upper: Any, shape: Any) -> NDArray[np.float64]:
    """A regular grid, the first axis varying slowest, as an (N, n) array [m]."""
    lo = np.asarray(lower, dtype=float)
    hi = np.asarray(upper, dtype=float)
    counts = [int(c) for c in shape]
    if not (lo.shape == hi.shape == (len(counts),)) or min(counts) < 1:
        raise InvalidArgumentError(
            f"a target grid needs lower, upper and shape of one length, got {lower!r}, {upper!r}, {shape!r}"
        )
    axes = [
        np.linspace(a, b, c) if c > 1 else np.array([(a + b) / 2])
        for a, b, c in zip(lo, hi, counts, strict=True)
    ]
    mesh = np.meshgrid(*axes, indexing="ij")
    return np.ascontiguousarray(np.stack([g.ravel() for g in mesh], axis=1))


@dataclass(frozen=True)
class RobotPreset:
    """One robot (or family of robots) described by a TOML file in ``robots/``.

    Attributes:
        name: the preset name (``"planar"`` stands for the family ``planarN``).
        source: ``"planar"`` for procedural chains.
        description: one line for listings.
        frame: operational frame.
        axes: task axes seen by the learner.
        targets: default target set, (N, n) [m].
        learner: per-robot learner defaults (keys among ``learning_rate``, ``sigma``,
            ``sigma_delta``, ``radius``, ``path_length``, ``p_home``).
        options: the remaining entries of the file (e.g. ``total_length``).
    """

    name: str
    source: str
    description: str
    frame: str
    axes: str
    targets: NDArray[np.float64]
    learner: dict[str, Any] = field(default_factory=dict)
    options: dict[str, Any] = field(default_factory=dict)

    @property
    def pattern(self) -> str:
        """The name users type (``planarN`` for the planar family)."""
        return f"{self.name}N" if self.source == "planar" else self.name


def _read_preset(text: str, filename: str) -> RobotPreset:
    try:
        raw = tomllib.loads(text)
        targets = raw.pop("targets")
        grid = grid_targets(targets["lower"], targets["upper"], targets["shape"])
        learner = {str(k): v for k, v in raw.pop("learner", {}).items()}
        unknown = set(learner) - set(_LEARNER_KEYS)
        if unknown:
            raise InvalidArgumentError(
                f"unknown learner keys {sorted(unknown)}; valid: {list(_LEARNER_KEYS)}"
            )
        return RobotPreset(
            name=str(raw.pop("name")),
            source=str(raw.pop("source")),
            description=str(raw.pop("description", "")),
            frame=str(raw.pop("frame")),
            axes=str(raw.pop("axes", "xyz")),
            targets=grid,
            learner=learner,
            options=raw,
        )
    except (tomllib.TOMLDecodeError, KeyError, TypeError, ValueError) as exc:
        raise InvalidArgumentError(f"malformed robot preset {filename}: {exc}") from exc


_PRESETS: dict[str, RobotPreset] | None = None


def _presets() -> dict[str, RobotPreset]:
    global _PRESETS
    if _PRESETS is None:
        found = {}
        for entry in sorted(resources.files("gb_pin.presets").iterdir(), key=lambda e: e.name):
            if entry.name.endswith(".toml"):
                preset = _read_preset(entry.read_text(encoding="utf-8"), entry.name)
                found[preset.name] = preset
        _PRESETS = found
    return _PRESETS


def robots() -> list[RobotPreset]:
    """All presets, sorted by name (the planar family appears once, as ``planarN``)."""
    return sorted(_presets().values(), key=lambda p: p.name)


def get_preset(name: str) -> tuple[RobotPreset, int | None]:
    """Find the preset for a robot name; for a family (``planarN``) also return N.

    Raises:
        UnknownRobotError: no preset of that name (the message lists the closest ones).
    """
    presets = _presets()
    valid = [p.pattern for p in presets.values()]
    if not isinstance(name, str):
        raise UnknownRobotError(
            f"robot name must be a string, got {name!r}; valid presets: {', '.join(valid)}"
        )
    for preset in presets.values():
        if preset.source != "planar":
            continue
        match = re.fullmatch(re.escape(preset.name) + r"(\d+)", name)
        if match:
            m = int(match.group(1))
            minimum = int(preset.options.get("min_joints", 2))
            if m < minimum:
                raise UnknownRobotError(f"robot {name!r}: {preset.name}N needs N >= {minimum}, got N = {m}")
            return preset, m
    if name in presets and presets[name].source != "planar":
        return presets[name], None
    close = difflib.get_close_matches(
        name, [*valid, *(f"{p.name}5" for p in presets.values())], n=3, cutoff=0.5
    )
    hint = f"; did you mean {', '.join(close)}?" if close else ";"
    raise UnknownRobotError(f"unknown robot {name!r}{hint} valid presets: {', '.join(valid)} (N >= 2)")


def load_robot(name: str) -> KinematicTarget:
    """Load a preset robot as a :class:`KinematicTarget` with its home posture and targets.

    Args:
        name: a preset name, e.g. ``"planar5"`` or ``"planar20"`` (any N >= 2).

    Raises:
        UnknownRobotError: unknown name (the message suggests the closest).
    """
    preset, m = get_preset(name)
    if preset.source == "planar":
        assert m is not None
        model = planar_chain(m, float(preset.options.get("total_length", 1.0)))
        home = planar_home(m)
        return KinematicTarget(
            model, preset.frame, home=home, axes=preset.axes, targets=preset.targets, name=name
        )
    raise UnknownRobotError(f"robot {name!r}: source {preset.source!r} is not supported")
