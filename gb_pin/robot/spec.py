"""Robots named ``MODULE:NAME``: a robot (or a function returning one) in a Python module or file.

``gb-pin babble --robot examples/continuum_arm.py:robot`` and ``gb_pin.babble("mypkg.arms:arm")``
and trials (``run_trials(robot="mypkg.arms:arm")``: each worker loads it by the same spec) name
robots that are no presets this way, e.g. a :class:`~gb_pin.robot.function.FunctionTarget`.
Loading runs the module's code: name only modules you trust.
"""

from __future__ import annotations

import importlib
import importlib.util
from pathlib import Path
from typing import Any

from gb_pin.exceptions import InvalidArgumentError

_LOADED: dict[str, Any] = {}  # spec -> robot, once per process (trial workers run many trials)


def is_robot_spec(name: str) -> bool:
    """Whether ``name`` is ``MODULE:NAME`` rather than a preset name."""
    return ":" in name


def spec_of(robot: Any) -> str | None:
    """The ``MODULE:NAME`` spec this process loaded ``robot`` from (that very object), or None."""
    for spec, loaded in _LOADED.items():
        if loaded is robot:
            return spec
    return None


def load_robot_spec(spec: str) -> Any:
    """The robot named by ``MODULE:NAME``: a module (or a ``.py`` file) and a robot or robot factory in it.

    Loaded once per process and spec (the same object is returned after that).

    Raises:
        InvalidArgumentError: the module or the name cannot be found, or it is not a robot.
    """
    if spec in _LOADED:
        return _LOADED[spec]
    module_name, _, attr = spec.rpartition(":")
    if not module_name or not attr:
        raise InvalidArgumentError(
            f"robot {spec!r}: expected MODULE:NAME, e.g. examples/continuum_arm.py:robot"
        )
    try:
        if module_name.endswith(".py"):
            path = Path(module_name)
            if not path.is_file():
                raise InvalidArgumentError(f"robot {spec!r}: no file {module_name}")
            loader = importlib.util.spec_from_file_location(path.stem, path)
            assert loader is not None and loader.loader is not None
            module = importlib.util.module_from_spec(loader)
            loader.loader.exec_module(module)
        else:
            module = importlib.import_module(module_name)
    except ImportError as exc:
        raise InvalidArgumentError(f"robot {spec!r}: cannot import {module_name!r} ({exc})") from exc
    if not hasattr(module, attr):
        raise InvalidArgumentError(f"robot {spec!r}: {module_name} has no {attr!r}")
    obj = getattr(module, attr)
    robot = obj() if callable(obj) and not hasattr(obj, "home") else obj
    if not all(hasattr(robot, a) for a in ("home", "lower", "upper", "forward")):
        raise InvalidArgumentError(
            f"robot {spec!r}: {attr} is not a robot (a KinematicTarget, ChangedBody or FunctionTarget)"
        )
    _LOADED[spec] = robot
    return robot
