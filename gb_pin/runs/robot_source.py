"""The robot source: how a result file or a checkpoint records a robot that is no preset, to rebuild it.

A run of a preset records the preset's name (the header's ``robot``). A run of another robot records,
in the header's ``robot_source``, a small JSON object saying how to build it again:

- ``{"kind": "urdf", "path": ABSOLUTE_PATH, "frame", "joints", "home", "axes", "name", "chain_sha256"}``:
  :meth:`~gb_pin.robot.target.KinematicTarget.from_urdf`;
- ``{"kind": "erd", "robot": NAME, "frame", "joints", "home", "axes", "name", "chain_sha256"}``:
  :meth:`~gb_pin.robot.target.KinematicTarget.from_example_robot_data`;
- ``{"kind": "module", "spec": "MODULE:NAME"}``: a robot of :mod:`gb_pin.robot.spec`.

``home`` is the resolved home posture (numbers over ``joints``), ``chain_sha256`` the digest of the
kinematic chain the run learned on: a rebuilt robot whose kinematics differ (the URDF was edited) is
refused, never silently used. A file is untrusted input: :func:`check` validates every entry (types,
lengths, values) before anything is built. A module spec is never imported on a file's word (importing
runs the module's code): the user passes that robot (``--robot MODULE:NAME``, ``target=``).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from gb_pin._names import listing, printable
from gb_pin.exceptions import GbPinError, ResultFileError

MAX_TEXT = 4096  # characters of a path or a module spec
MAX_NAME = 256  # characters of a robot, frame or joint name
MAX_JOINTS = 4096
_KEYS = {
    "urdf": {"kind", "path", "frame", "joints", "home", "axes", "name", "chain_sha256"},
    "erd": {"kind", "robot", "frame", "joints", "home", "axes", "name", "chain_sha256"},
    "module": {"kind", "spec"},
}


def chain_digest(chain: Any) -> str:
    """SHA-256 of a :class:`~gb_pin.learn.body.chain.KinematicChain` (field names, dtypes, shapes, bytes).

    Nested dataclasses (the task's components) are digested field by field, None as itself.
    """
    digest = hashlib.sha256()
    _feed(digest, "chain", chain)
    return digest.hexdigest()


def _feed(digest: Any, name: str, value: Any) -> None:
    if value is None:
        digest.update(f"{name}:None;".encode())
    elif dataclasses.is_dataclass(value):
        for f in dataclasses.fields(value):
            _feed(digest, f"{name}.{f.name}", getattr(value, f.name))
    else:
        array = np.ascontiguousarray(value)
        if array.dtype.hasobject:  # not expected in a chain: its text, never its pointers
            digest.update(f"{name}:{value!r};".encode())
            return
        digest.update(f"{name}:{array.dtype.str}:{array.shape};".encode())
        digest.update(array.tobytes())


def describe(target: Any, robot: str | None) -> dict[str, Any] | None:
    """The robot source of a run's ``target`` (None: a preset ``robot``, or a robot that cannot be rebuilt).

    URDF and example-robot-data targets are described by their file (or erd name), frame, joints,
    home, axes and name; robots loaded by ``MODULE:NAME`` by their spec (a ``.py`` path made absolute).
    """
    from gb_pin.robot.spec import spec_of
    from gb_pin.robot.target import KinematicTarget

    if robot is not None:
        return None
    spec = spec_of(target)
    if spec is not None:
        module, _, attr = spec.rpartition(":")
        if module.endswith(".py"):
            spec = f"{os.path.abspath(module)}:{attr}"
        return {"kind": "module", "spec": spec} if _printable(spec, MAX_TEXT) else None
    if not isinstance(target, KinematicTarget) or target.urdf is None:
        return None
    common = {
        "frame": target.frame,
        "joints": list(target.joints),
        "home": [float(v) for v in target.home],
        "axes": target.axes,
        "name": target.name,
        "chain_sha256": chain_digest(target.chain),
    }
    erd = _erd_name(target.urdf)
    if erd is not None:
        source = {"kind": "erd", "robot": erd, **common}
    else:
        source = {"kind": "urdf", "path": os.path.abspath(target.urdf), **common}
    try:  # record only what a reader accepts (e.g. not a name with control characters)
        return check("robot_source", source)
    except ResultFileError:
        return None


def _erd_name(urdf: str) -> str | None:
    """The example-robot-data robot whose URDF is ``urdf``, or None."""
    from gb_pin.robot.models import DESCRIPTIONS, example_robot_data_dir

    try:
        root = example_robot_data_dir()
    except GbPinError:
        return None
    path = Path(urdf).resolve()
    for name, entry in DESCRIPTIONS.items():
        if (root / entry.urdf).resolve() == path:
            return name
    return None


def _fail(path: str, what: str, value: Any, valid: str) -> ResultFileError:
    return ResultFileError(f"{path}: robot_source {what} must be {valid}, got {str(value)[:80]!r}")


def _printable(value: Any, limit: int) -> bool:
    """A non-empty string of at most ``limit`` characters, no control characters (they reach terminals)."""
    return isinstance(value, str) and 0 < len(value) <= limit and value.isprintable()


def _text(path: str, source: dict[str, Any], key: str, limit: int) -> str:
    value = source.get(key)
    if not _printable(value, limit):
        raise _fail(path, key, value, f"a non-empty printable string of at most {limit} characters")
    return str(value)


def check(path: str, value: Any) -> dict[str, Any] | None:
    """``value`` (the header's ``robot_source``) if it is None or a valid robot source.

    Raises:
        ResultFileError: naming the entry that is wrong and what is valid.
    """
    if value is None:
        return None
    if not isinstance(value, dict) or value.get("kind") not in _KEYS:
        raise _fail(path, "", value, f"an object of kind {' / '.join(sorted(_KEYS))}")
    kind = value["kind"]
    extra = sorted(set(value) - _KEYS[kind])
    if extra:
        raise _fail(path, "keys", extra, f"among {sorted(_KEYS[kind])}")
    if kind == "module":
        if ":" not in _text(path, value, "spec", MAX_TEXT):
            raise _fail(path, "spec", value["spec"], "MODULE:NAME")
        return dict(value)
    if kind == "urdf":
        if not os.path.isabs(_text(path, value, "path", MAX_TEXT)):
            raise _fail(path, "path", value["path"], "an absolute path")
    else:
        _text(path, value, "robot", MAX_NAME)
    for key in ("frame", "name"):
        _text(path, value, key, MAX_NAME)
    joints = value.get("joints")
    if not isinstance(joints, list) or not 0 < len(joints) <= MAX_JOINTS:
        raise _fail(path, "joints", joints, f"a list of 1 to {MAX_JOINTS} joint names")
    names_ok = all(_printable(j, MAX_NAME) for j in joints)
    if not names_ok or len(set(joints)) < len(joints):
        raise _fail(path, "joints", joints, f"distinct names of at most {MAX_NAME} characters")
    home = value.get("home")
    if (
        not isinstance(home, list)
        or len(home) != len(joints)
        or not all(isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in home)
    ):
        raise _fail(path, "home", home, f"{len(joints)} finite numbers (one per joint)")
    axes = value.get("axes")
    if not isinstance(axes, str) or not re.fullmatch("[xyz]{1,3}", axes) or len(set(axes)) < len(axes):
        raise _fail(path, "axes", axes, "distinct letters of xyz, e.g. 'xyz' or 'xy'")
    digest = value.get("chain_sha256")
    if not isinstance(digest, str) or not re.fullmatch("[0-9a-f]{64}", digest):
        raise _fail(path, "chain_sha256", digest, "64 hexadecimal digits")
    return dict(value)


def explain(source: dict[str, Any]) -> str:
    """What ``source`` records, and the CLI options that pass that robot explicitly."""
    if source["kind"] == "module":
        spec = printable(source["spec"])
        return f"the robot {spec!r} (MODULE:NAME); pass it: --robot {spec}"
    where = printable(source["path"] if source["kind"] == "urdf" else f"erd:{source['robot']}")
    home = ",".join(repr(v) for v in source["home"])
    frame = printable(source["frame"])  # names from a file: printable
    options = (
        f"--robot {where} --frame {frame} --joints {listing(source['joints'], ',')} "
        f"--home {home} --axes {source['axes']}"
    )
    kind = "the URDF model" if source["kind"] == "urdf" else "the example-robot-data model"
    return f"{kind} {where} (frame {frame!r}, {len(source['joints'])} joints); pass it: {options}"


def rebuild(path: str, source: dict[str, Any]) -> Any:
    """The robot ``source`` (checked by :func:`check`) records, built again and checked against the run's.

    Raises:
        ResultFileError: a module spec (never imported on a file's word), a model that cannot be built
            (file moved, example-robot-data missing) or whose kinematics differ from the run's; the
            message says what was recorded and how to pass the robot.
    """
    from gb_pin.robot.target import KinematicTarget

    hint = f"{explain(source)} (or target= in Python)"
    if source["kind"] == "module":
        raise ResultFileError(
            f"{path}: the run's robot was loaded from code, which gb_pin does not import on a file's "
            f"word (importing a module runs it); if you trust it, {hint}"
        )
    args = (source["frame"], source["joints"])
    options = {"home": np.asarray(source["home"], dtype=np.float64), "axes": source["axes"]}
    try:
        if source["kind"] == "urdf":
            target = KinematicTarget.from_urdf(source["path"], *args, **options, name=source["name"])
        else:
            target = KinematicTarget.from_example_robot_data(
                source["robot"], *args, **options, label=source["name"]
            )
    except (GbPinError, OSError, ValueError, RuntimeError) as exc:
        raise ResultFileError(f"{path}: cannot rebuild the run's robot ({exc}); it was {hint}") from exc
    if chain_digest(target.chain) != source["chain_sha256"]:
        raise ResultFileError(
            f"{path}: the rebuilt robot's kinematics differ from the run's (was the model edited "
            f"since?); it was {hint}"
        )
    return target
