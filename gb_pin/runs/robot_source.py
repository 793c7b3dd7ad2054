"""The robot source: how a result file or a checkpoint records a robot that is no preset, to rebuild it.

A run of a preset records the preset's name (the header's ``robot``). A run of another robot records,
in the header's ``robot_source``, a small JSON object saying how to build it again:

- ``{"kind": "urdf", "path": ABSOLUTE_PATH, "frame", "joints", "home", "axes", "name", "chain_sha256"}``:
  :meth:`~gb_pin.robot.target.KinematicTarget.from_urdf`;
- ``{"kind": "erd", "robot": NAME, "frame", "joints", "home", "axes", "name", "chain_sha256"}``:
  :meth:`~gb_pin.robot.target.KinematicTarget.from_example_robot_data`;
- ``{"kind": "module", "spec": "MODULE:NAME"}``: a robot of :mod:`gb_pin.robot.spec`;
- ``{"kind": "plant", "base": PRESET or a urdf/erd source, "offsets", "scales", "noise", "loss", "seed",
  "name", "chain_sha256"}``: a :class:`~gb_pin.robot.plant.Plant` (a mis-calibrated body and its sensor).

``home`` is the resolved home posture (numbers over ``joints``), ``chain_sha256`` the digest of the
kinematic chain the run learned on: a rebuilt robot whose kinematics differ (the URDF was edited) is
refused, never silently used. A stacked task (``--task pose``, docs/TASKS.md) adds ``task``, its
components as tables (``{"kind": "orientation", "frame", "scale", "reference"}``).
An onboarded robot (:mod:`gb_pin.robot.onboarding`) adds ``onboarding``,
what was chosen by measurement (the goal grid's half-width and shape, the radius...): the rebuilt robot
has the same goal grid and radius without measuring again. A file is untrusted input: :func:`check`
validates every entry (types, lengths, values) before anything is built. A module spec is never
imported on a file's word (importing runs the module's code): the user passes that robot (``--robot
MODULE:NAME``, ``target=``).
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
    "urdf": {"kind", "path", "frame", "joints", "home", "axes", "name", "chain_sha256", "onboarding", "task"},
    "erd": {"kind", "robot", "frame", "joints", "home", "axes", "name", "chain_sha256", "onboarding", "task"},
    "module": {"kind", "spec"},
    "plant": {"kind", "base", "offsets", "scales", "noise", "loss", "seed", "name", "chain_sha256"},
}
MAX_GRID_COUNT = 1000  # points per axis of a recorded goal grid


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
    from gb_pin.robot.plant import Plant
    from gb_pin.robot.spec import spec_of
    from gb_pin.robot.target import KinematicTarget

    if robot is not None:
        return None
    if isinstance(target, Plant):
        return _describe_plant(target)
    spec = spec_of(target)
    if spec is not None:
        module, _, attr = spec.rpartition(":")
        if module.endswith(".py"):
            spec = f"{os.path.abspath(module)}:{attr}"
        return {"kind": "module", "spec": spec} if _printable(spec, MAX_TEXT) else None
    if not isinstance(target, KinematicTarget) or target.urdf is None:
        return None
    common: dict[str, Any] = {
        "frame": target.frame,
        "joints": list(target.joints),
        "home": [float(v) for v in target.home],
        "axes": target.axes,
        "name": target.name,
        "chain_sha256": chain_digest(target.chain),
    }
    if target.onboarding is not None:
        common["onboarding"] = target.onboarding.to_json()
    if target.task is not None:
        common["task"] = [_task_table(spec) for spec in target.task]
    erd = _erd_name(target.urdf)
    if erd is not None:
        source = {"kind": "erd", "robot": erd, **common}
    else:
        source = {"kind": "urdf", "path": os.path.abspath(target.urdf), **common}
    try:  # record only what a reader accepts (e.g. not a name with control characters)
        return check("robot_source", source)
    except ResultFileError:
        return None


def _task_table(spec: Any) -> dict[str, Any]:
    """A task component as a JSON table (:func:`gb_pin.robot.task_spec.from_mapping` reads it)."""
    out: dict[str, Any] = {"kind": type(spec).__name__.lower()}
    for f in dataclasses.fields(spec):
        value = getattr(spec, f.name)
        out[f.name] = np.asarray(value, dtype=float).tolist() if isinstance(value, np.ndarray) else value
    return out


def _check_task(path: str, value: Any) -> None:
    """Raise unless ``value`` is a list of task component tables that build (kinds, keys, numbers)."""
    from gb_pin.robot.task_spec import from_mapping

    if not isinstance(value, list) or not 0 < len(value) <= 16:
        raise _fail(path, "task", value, "a list of 1 to 16 task component tables")
    for table in value:
        if not isinstance(table, dict) or not _printable(str(table.get("frame")), MAX_NAME):
            raise _fail(path, "task", table, "a table with kind, frame and the component's values")
        try:
            from_mapping(table)
        except (GbPinError, TypeError, ValueError) as exc:
            raise _fail(path, "task", table, f"a valid task component ({exc})") from exc


def _describe_plant(plant: Any) -> dict[str, Any] | None:
    """A plant's source: its model (a preset's name or a model's source) and how it differs, or None."""
    model = plant.target
    base: Any = plant.preset if plant.preset is not None else describe(model, None)
    if base is None or (isinstance(base, dict) and base["kind"] not in ("urdf", "erd")):
        return None
    source = {
        "kind": "plant",
        "base": base,
        "offsets": [float(v) for v in plant.calibration.offsets],
        "scales": [float(v) for v in plant.calibration.scales],
        "noise": [float(v) for v in np.atleast_1d(plant.sensor.noise)],
        "loss": float(plant.sensor.loss),
        "seed": int(plant.seed),
        "name": plant.name,
        "chain_sha256": chain_digest(plant.chain),
    }
    try:
        return check("robot_source", source)
    except ResultFileError:
        return None


def _numbers(path: str, value: Any, key: str, count: int | None, minimum: float) -> None:
    ok = isinstance(value, list) and (count is None or len(value) == count) and 0 < len(value) <= MAX_JOINTS
    real = (isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in value or ())
    if not ok or not all(real) or min(value) < minimum:
        raise _fail(path, key, value, f"a list of finite numbers >= {minimum:g}")


def _check_plant(path: str, value: dict[str, Any]) -> dict[str, Any]:
    base = value.get("base")
    if isinstance(base, dict):
        if base.get("kind") not in ("urdf", "erd"):
            raise _fail(path, "base", base, "a preset name or a urdf / erd source")
        check(path, base)
    elif not (_printable(base, MAX_NAME) and re.fullmatch(r"[A-Za-z0-9_]+", str(base))):
        raise _fail(path, "base", base, "a preset name or a urdf / erd source")
    _numbers(path, value.get("offsets"), "offsets", None, -math.pi)
    _numbers(path, value.get("scales"), "scales", len(value["offsets"]) + 1, 1e-6)
    _numbers(path, value.get("noise"), "noise", None, 0.0)
    loss = value.get("loss")
    if isinstance(loss, bool) or not isinstance(loss, int | float) or not 0 <= loss < 1:
        raise _fail(path, "loss", loss, "a probability in [0, 1)")
    seed = value.get("seed")
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
        raise _fail(path, "seed", seed, "an integer in [0, 2^63)")
    _text(path, value, "name", MAX_NAME)
    digest = value.get("chain_sha256")
    if not isinstance(digest, str) or not re.fullmatch("[0-9a-f]{64}", digest):
        raise _fail(path, "chain_sha256", digest, "64 hexadecimal digits")
    return dict(value)


def _rebuild_plant(path: str, source: dict[str, Any]) -> Any:
    from gb_pin.robot.plant import Plant
    from gb_pin.robot.presets import load_robot

    base = source["base"]
    try:
        model = load_robot(base) if isinstance(base, str) else rebuild(path, base)
        noise = source["noise"][0] if len(source["noise"]) == 1 else source["noise"]
        plant = Plant(model, offsets=source["offsets"], scales=source["scales"], noise=noise,
                      loss=source["loss"], seed=source["seed"], name=source["name"])  # fmt: skip
    except (GbPinError, OSError, ValueError) as exc:
        raise ResultFileError(f"{path}: cannot rebuild the run's plant {source['name']!r} ({exc})") from exc
    if chain_digest(plant.chain) != source["chain_sha256"]:
        raise ResultFileError(f"{path}: the rebuilt plant's kinematics differ from the run's (model edited?)")
    return plant


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
    if kind == "plant":
        return _check_plant(path, value)
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
    if "task" in value:
        _check_task(path, value["task"])
    if "onboarding" in value:
        _check_onboarding(path, value["onboarding"], len(axes))
    return dict(value)


def _number(value: Any, minimum: float, none: bool = False) -> bool:
    """A finite real number >= ``minimum`` (or None where ``none``)."""
    if value is None:
        return none
    return isinstance(value, int | float) and not isinstance(value, bool) and minimum <= value < math.inf


def _check_onboarding(path: str, value: Any, n_axes: int) -> None:
    """Raise unless ``value`` is an :meth:`Onboarding.to_json` record of a robot with ``n_axes`` task axes."""
    from gb_pin.robot.onboarding import CHOSEN

    keys = {"chosen", "dropped", "margin", "sigma_min", "half_width", "largest_half_width", "shape", "radius"}
    keys.add("sigma")
    if not isinstance(value, dict) or set(value) != keys:
        raise _fail(path, "onboarding", value, f"an object with keys {sorted(keys)}")
    chosen, dropped, shape = value["chosen"], value["dropped"], value["shape"]
    if not isinstance(chosen, list) or not set(chosen) <= set(CHOSEN) or len(set(chosen)) < len(chosen):
        raise _fail(path, "onboarding.chosen", chosen, f"distinct names among {list(CHOSEN)}")
    if (
        not isinstance(dropped, list)
        or len(dropped) > MAX_JOINTS
        or not all(_printable(j, MAX_NAME) for j in dropped)
    ):
        raise _fail(path, "onboarding.dropped", dropped, "a list of joint names")
    grid = "targets" in chosen
    if (
        not isinstance(shape, list)
        or len(shape) != (n_axes if grid else 0)
        or not all(isinstance(c, int) and not isinstance(c, bool) and 1 <= c <= MAX_GRID_COUNT for c in shape)
    ):
        raise _fail(
            path, "onboarding.shape", shape, f"{n_axes if grid else 0} counts in [1, {MAX_GRID_COUNT}]"
        )
    for key, minimum, none in (
        ("margin", 0.0, True), ("sigma_min", 0.0, True), ("half_width", 0.0, False),
        ("largest_half_width", 0.0, False), ("radius", 1e-9, not grid),
        ("sigma", 1e-12, True),
    ):  # fmt: skip
        if not _number(value[key], minimum, none):
            raise _fail(path, f"onboarding.{key}", value[key], f"a finite number >= {minimum:g}")
    if grid and not value["half_width"] > 0:
        raise _fail(path, "onboarding.half_width", value["half_width"], "> 0 for a chosen goal grid")


def explain(source: dict[str, Any]) -> str:
    """What ``source`` records, and the CLI options that pass that robot explicitly."""
    if source["kind"] == "plant":
        return f"the plant {source['name']!r} (a mis-calibrated body of {source['base']!r}); pass it: robot="
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

    if source["kind"] == "plant":
        return _rebuild_plant(path, source)
    hint = f"{explain(source)} (or target= in Python)"
    if source["kind"] == "module":
        raise ResultFileError(
            f"{path}: the run's robot was loaded from code, which gb_pin does not import on a file's "
            f"word (importing a module runs it); if you trust it, {hint}"
        )
    args = (source["frame"], source["joints"])
    options = {"home": np.asarray(source["home"], dtype=np.float64), "axes": source["axes"], "onboard": False}
    if "task" in source:
        options["task"] = source["task"]
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
    if "onboarding" in source:
        restore_onboarding(target, source["onboarding"])
    return target


def restore_onboarding(target: Any, raw: dict[str, Any]) -> None:
    """Give a rebuilt ``target`` its onboarding record ``raw`` (checked) and goal grid, not measured again."""
    from gb_pin.robot.grids import regular_grid
    from gb_pin.robot.onboarding import Onboarding

    record = Onboarding.from_json(raw)
    if "targets" in record.chosen:
        target.targets = regular_grid(target.home_position, record.half_width, record.shape)
    count = 0 if target.targets is None else len(target.targets)
    home = tuple(float(v) for v in target.home)
    target.onboarding = dataclasses.replace(record, joints=tuple(target.joints), home=home, n_targets=count)
