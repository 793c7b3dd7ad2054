"""Plants named by strings: ``"so101@mujoco:kp=10,settle=0.2"`` for trials, files and the command line.

A trial worker receives its robot as a string and builds it itself; the command line takes
``--robot so101 --plant mujoco:kp=10,settle=0.2``. The grammar is the goal generators' one
(``name:key=value,...``), after the robot and an ``@``:

    ROBOT@mujoco[:key=value,...]

where ROBOT is a preset name (or ``MODULE:NAME``) and the keys are
:class:`~gb_pin.sim.plant.MujocoPlant`'s numeric arguments (:data:`OPTIONS`); ``gravity`` takes
``on``/``off``. This module parses and writes such strings; it imports neither MuJoCo nor the plant.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gb_pin._names import suggest
from gb_pin.exceptions import InvalidArgumentError

PLANTS = ("mujoco",)
"""The simulators a plant string may name."""
OPTIONS: dict[str, type] = {
    "kp": float,
    "damping": float,
    "force_limit": float,
    "armature": float,
    "gravity": bool,
    "settle": float,
    "tolerance": float,
    "period": float,
    "timestep": float,
    "noise": float,
    "loss": float,
    "seed": int,
    "speed": float,
}
"""The plant's options a string may set, and their types."""
_TRUE, _FALSE = ("on", "true", "yes", "1"), ("off", "false", "no", "0")


def is_plant_spec(robot: Any) -> bool:
    """Whether ``robot`` is a string naming a simulated plant (``ROBOT@mujoco...``)."""
    return isinstance(robot, str) and any(f"@{p}" in robot for p in PLANTS)


def split_spec(spec: str) -> tuple[str, dict[str, Any]]:
    """(the robot, the plant's options) of ``ROBOT@mujoco[:key=value,...]``.

    Raises:
        InvalidArgumentError: no robot, another simulator, or a bad option.
    """
    robot, at, plant = spec.rpartition("@")
    if not at or not robot:
        raise InvalidArgumentError(
            f"a plant is named ROBOT@mujoco[:key=value,...], e.g. so101@mujoco:kp=10; got {spec!r}"
        )
    return robot, parse_plant(plant)


def parse_plant(text: str) -> dict[str, Any]:
    """The options of a plant string ``mujoco[:key=value,...]`` (e.g. ``mujoco:kp=10,settle=0.2``).

    Raises:
        InvalidArgumentError: another simulator, an unknown key (the closest ones named), a repeated
            key or a value of the wrong type.
    """
    name, _, rest = str(text).partition(":")
    if name.strip() not in PLANTS:
        raise InvalidArgumentError(
            f"unknown plant {name.strip()!r}: the simulated plant is 'mujoco' (e.g. mujoco:kp=10,settle=0.2)"
        )
    options: dict[str, Any] = {}
    for item in (part.strip() for part in rest.split(",")):
        if not item:
            continue
        key, eq, value = (s.strip() for s in item.partition("="))
        if key not in OPTIONS:
            raise InvalidArgumentError(f"unknown plant option {key!r}; {suggest(key, list(OPTIONS))}")
        if not eq or not value:
            raise InvalidArgumentError(f"plant option {key!r} needs a value: {key}=VALUE")
        if key in options:
            raise InvalidArgumentError(f"plant option {key!r} given twice in {text!r}")
        options[key] = _value(key, value)
    return options


def plant_spec(robot: str, options: dict[str, Any]) -> str:
    """The string of a plant on ``robot`` with ``options`` (the inverse of :func:`split_spec`)."""
    items = [f"{k}={_text(v)}" for k, v in options.items()]
    return f"{robot}@mujoco" + (":" + ",".join(items) if items else "")


def spec_of(robot: str | None, given: dict[str, Any]) -> str | None:
    """The string of a plant on the robot named ``robot`` with the (checked) arguments ``given``.

    Arguments at their defaults are left out. None: a robot given as an object, or per-joint values.
    """
    defaults = {"kp": 10.0, "armature": 0.01, "gravity": True, "timestep": 0.002, "noise": 0.0, "loss": 0.0,
                "seed": 0}  # fmt: skip
    options = {k: v for k, v in given.items() if v is not None and not (k in defaults and v == defaults[k])}
    if robot is None or any(np.ndim(v) for v in options.values()):
        return None
    return plant_spec(robot, {k: v if OPTIONS[k] is bool else OPTIONS[k](v) for k, v in options.items()})


def _value(key: str, text: str) -> Any:
    kind = OPTIONS[key]
    if kind is bool:
        if text.lower() in _TRUE:
            return True
        if text.lower() in _FALSE:
            return False
        raise InvalidArgumentError(f"plant option {key} must be on or off, got {text!r}")
    try:
        value = kind(text)
    except ValueError as exc:
        what = "an integer" if kind is int else "a number"
        raise InvalidArgumentError(f"plant option {key} must be {what}, got {text!r}") from exc
    if kind is float and not math.isfinite(value):
        raise InvalidArgumentError(f"plant option {key} must be finite, got {text!r}")
    return value


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "on" if value else "off"
    return repr(value) if isinstance(value, float) else str(value)
