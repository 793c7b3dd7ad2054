"""Robots named ``MODULE:NAME``: a robot (or a function returning one) in a Python module or file.

``gb-pin babble --robot examples/continuum_arm.py:robot`` and ``gb_pin.babble("mypkg.arms:arm")``
and trials (``run_trials(robot="mypkg.arms:arm")``: each worker loads it by the same spec) name
robots that are no presets this way, e.g. a :class:`~gb_pin.robot.function.FunctionTarget`.
Loading runs the module's code: name only modules you trust. Of what it finds, only a robot
object is taken and only a robot factory is called: a Python function defined in that module that
takes no argument (``sys:exit``, ``os:abort`` and other built-ins, classes, imported functions and
functions taking arguments are refused, saying what they are; so is any standard-library module).
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import sys
from pathlib import Path
from typing import Any

from gb_pin.exceptions import GbPinError, InvalidArgumentError

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


def import_module_or_file(module_name: str, label: str) -> Any:
    """The module ``module_name`` (dotted, or a ``.py`` file's path), run once imported.

    Raises:
        InvalidArgumentError: ``label``: no such file, or it cannot be imported.
    """
    try:
        if module_name.endswith(".py"):
            path = Path(module_name)
            if not path.is_file():
                raise InvalidArgumentError(f"{label}: no file {module_name}")
            loader = importlib.util.spec_from_file_location(path.stem, path)
            assert loader is not None and loader.loader is not None
            module = importlib.util.module_from_spec(loader)
            loader.loader.exec_module(module)
            return module
        return importlib.import_module(module_name)
    except ImportError as exc:
        raise InvalidArgumentError(f"{label}: cannot import {module_name!r} ({exc})") from exc


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
    if not module_name.endswith(".py") and module_name.split(".")[0] in sys.stdlib_module_names:
        raise InvalidArgumentError(
            f"robot {spec!r}: {module_name} is a module of Python's standard library, which holds no "
            "robot; name your own module or .py file (MODULE:NAME, e.g. examples/continuum_arm.py:robot)"
        )
    module = import_module_or_file(module_name, f"robot {spec!r}")
    if not hasattr(module, attr):
        raise InvalidArgumentError(f"robot {spec!r}: {module_name} has no {attr!r}")
    obj = getattr(module, attr)
    if is_robot(obj):
        robot = obj
    else:
        why = _not_a_factory(obj, module.__name__)
        if why is not None:
            raise InvalidArgumentError(
                f"robot {spec!r}: {attr} is {why}; give a robot (a KinematicTarget, ChangedBody or "
                f"FunctionTarget) or a robot factory (a function defined in {module_name} that takes no "
                "argument and returns one)"
            )
        try:
            robot = obj()
        except GbPinError:
            raise
        except Exception as exc:
            raise InvalidArgumentError(
                f"robot {spec!r}: {attr}() raised {type(exc).__name__}: {exc}"
            ) from exc
        if not is_robot(robot):
            raise InvalidArgumentError(
                f"robot {spec!r}: {attr}() returned {_kind(robot)}, not a robot (a KinematicTarget, "
                "ChangedBody or FunctionTarget)"
            )
    _LOADED[spec] = robot
    return robot


def is_robot(obj: Any) -> bool:
    """Whether ``obj`` is a robot object: an instance with home, lower, upper and forward (not a class)."""
    return not inspect.isclass(obj) and all(hasattr(obj, a) for a in ("home", "lower", "upper", "forward"))


def _not_a_factory(obj: Any, module: str) -> str | None:
    """Why ``obj`` is not a robot factory of ``module`` (what it is instead), or None if it is one.

    A factory is a Python function defined in that module (not imported into it, not a built-in,
    not a class) whose parameters all have defaults: nothing else is called.
    """
    if not inspect.isfunction(obj):
        return _kind(obj)
    if obj.__module__ != module:
        return f"the function {obj.__module__}.{obj.__qualname__} (imported into {module}, not defined there)"
    required = [
        p.name
        for p in inspect.signature(obj).parameters.values()
        if p.default is inspect.Parameter.empty and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
    ]
    if required:
        return f"a function taking arguments ({', '.join(required)})"
    return None


def _kind(obj: Any) -> str:
    """What ``obj`` is, for messages (``a built-in function (exit)``, ``a class (Foo)``, ...)."""
    if inspect.isbuiltin(obj) or inspect.ismethoddescriptor(obj):
        return f"a built-in function ({getattr(obj, '__name__', '?')})"
    if inspect.isclass(obj):
        return f"a class ({obj.__name__})"
    return f"an object of type {type(obj).__name__}"
