"""A robot's joints and frames as text: what ``--frame`` and ``--joints`` may name (``robots --frames``).

Every model gb_pin loads can be listed: a preset (its full model, the preset's joints and frame
marked), an example-robot-data robot (``erd:NAME``), a URDF file, a ``MODULE:NAME`` robot. Frames
are listed in the model's order, those that end a chain (a link no other joint hangs from: where a
tool usually is) marked, so that a robot of 121 links shows its arm's tool frame among a handful.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import pinocchio as pin

_TYPES = {
    "JointModelRX": "revolute x",
    "JointModelRY": "revolute y",
    "JointModelRZ": "revolute z",
    "JointModelRevoluteUnaligned": "revolute",
    "JointModelRUBX": "continuous x",
    "JointModelRUBY": "continuous y",
    "JointModelRUBZ": "continuous z",
    "JointModelRevoluteUnboundedUnaligned": "continuous",
    "JointModelPX": "prismatic x",
    "JointModelPY": "prismatic y",
    "JointModelPZ": "prismatic z",
    "JointModelPrismaticUnaligned": "prismatic",
    "JointModelFreeFlyer": "floating",
    "JointModelPlanar": "planar",
    "JointModelSpherical": "spherical",
    "JointModelSphericalZYX": "spherical",
    "JointModelTranslation": "translation",
}


def joint_kind(model: pin.Model, joint: int) -> str:
    """``"revolute z"``, ``"prismatic x"``, ``"floating"``, ...: the joint's type in words."""
    short = model.joints[joint].shortname()
    return _TYPES.get(short, short.removeprefix("JointModel"))


def chain_ends(model: pin.Model) -> set[int]:
    """The joints no other joint hangs from: the ends of the model's chains."""
    parents = {int(model.parents[j]) for j in range(1, model.njoints)}
    return {j for j in range(1, model.njoints) if j not in parents}


def format_frames(model: pin.Model, name: str, moved: Iterable[str] = (), frame: str | None = None) -> str:
    """The joints (type, limits, parent) and frames (type, joint) of ``model`` as text.

    Args:
        model: the full Pinocchio model.
        name: the robot's name, for the heading.
        moved: joints the learner moves (a preset's), marked ``*``.
        frame: the effector frame (a preset's), marked ``*``.
    """
    import pinocchio as pin

    moved = set(moved)
    ends = chain_ends(model)
    lines = [
        f"{name}: {model.njoints - 1} joints ({model.nq} configuration values), {len(model.frames)} frames",
        "",
        "joints (--joints names them; * moved by the preset):",
    ]
    rows: list[tuple[str, ...]] = [("", "name", "type", "lower", "upper", "parent joint")]
    for j in range(1, model.njoints):
        jn = model.names[j]
        lo, hi = _limits(model, j)
        rows.append(
            ("*" if jn in moved else "", jn, joint_kind(model, j), lo, hi, model.names[model.parents[j]])
        )
    lines += _table(rows)
    lines += ["", "frames (--frame names them; > ends a chain, where a tool usually is; * the preset's):"]
    rows = [("", "name", "type", "on joint")]  # a new table
    for f in model.frames:
        if f.name == "universe":
            continue
        mark = (
            "*"
            if f.name == frame
            else (">" if int(f.parentJoint) in ends and f.type == pin.FrameType.BODY else "")
        )
        kind = str(f.type).rsplit(".", 1)[-1].lower()
        rows.append((mark, str(f.name), kind, str(model.names[int(f.parentJoint)])))
    lines += _table(rows)
    return "\n".join(lines)


def _limits(model: pin.Model, joint: int) -> tuple[str, str]:
    """The joint's position limits as text (its first value's; ``-`` where unbounded)."""
    nq = model.joints[joint].nq
    if nq != 1:
        return "-", "-"
    i = model.joints[joint].idx_q
    lo, hi = float(model.lowerPositionLimit[i]), float(model.upperPositionLimit[i])
    if not (np.isfinite(lo) and np.isfinite(hi)) or abs(lo) > 1e10 or abs(hi) > 1e10 or lo >= hi:
        return "-", "-"
    return f"{lo:.4g}", f"{hi:.4g}"


def _table(rows: Sequence[tuple[str, ...]]) -> list[str]:
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return ["  " + "  ".join(c.ljust(widths[i]) for i, c in enumerate(r)).rstrip() for r in rows]
