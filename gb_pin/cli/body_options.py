"""The options of a robot that is not its model: ``--plant``, ``--sensor``, ``--max-joint-step``.

``--plant KIND[:key=value,...]`` wraps the robot in a plant (:data:`PLANTS`): ``miscalibrated``
(joint zero offsets and link lengths off, :class:`~gb_pin.robot.plant.Plant`), and others that
register themselves here (a physics simulator). ``--sensor noise=M,loss=P,seed=S`` observes the
hand through a :class:`~gb_pin.learn.sensor.Sensor`. Every key is checked, with the valid ones named.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import Any

from gb_pin._names import suggest
from gb_pin.exceptions import InvalidArgumentError

PlantBuilder = Callable[[Any, dict[str, Any]], Any]
PLANTS: dict[str, tuple[dict[str, float | str | None], PlantBuilder, str]] = {}
"""Plant kinds: name -> (keys with their defaults (None: "auto"), builder(robot, values), help)."""


def register_plant(
    name: str, defaults: dict[str, float | str | None], build: PlantBuilder, text: str
) -> None:
    """Make ``--plant NAME[:key=value,...]`` build ``build(robot, values)``."""
    PLANTS[name] = (defaults, build, text)


def _miscalibrated(robot: Any, values: dict[str, float]) -> Any:
    from gb_pin.robot.plant import Plant

    seed = values["seed"]
    if seed != int(seed) or seed < 0:
        raise InvalidArgumentError(f"--plant miscalibrated: seed must be an integer >= 0, got {seed:g}")
    return Plant(
        robot, offset_std=math.radians(values["offsets"]), length_std=values["lengths"] / 100.0,
        noise=values["noise"], loss=values["loss"], seed=int(seed),
    )  # fmt: skip


register_plant(
    "miscalibrated",
    {"offsets": 3.0, "lengths": 3.0, "noise": 0.0, "loss": 0.0, "seed": 0},
    _miscalibrated,
    "joint zero offsets ~ N(0, offsets^2) [deg] and link lengths x (1 + N(0, (lengths/100)^2)); "
    "noise [m] and loss of the readings; seed draws the body and the sensor",
)


def add_body_options(b: argparse.ArgumentParser) -> None:
    """``--plant``, ``--sensor`` and ``--max-joint-step``."""
    kinds = "; ".join(
        f"{name}:{','.join(f'{k}={_default(v)}' for k, v in d.items())} ({text})"
        for name, (d, _, text) in PLANTS.items()
    )
    b.add_argument(
        "--plant",
        default=None,
        help=f"learn a robot that is not its model: {kinds}".replace("%", "%%"),
    )
    b.add_argument(
        "--sensor",
        default=None,
        help="observe the hand through a sensor: noise=M (std per axis [m]),loss=P (missing readings),"
        "seed=S, e.g. noise=0.0015,loss=0.1; or a camera and an ArUco marker, learning in the camera's "
        "frame: aruco:size=0.025,id=7,camera=0,calib=cam.yaml,mode=xyz|uv (docs/CAMERA.md)",
    )
    b.add_argument(
        "--max-joint-step",
        type=float,
        default=None,
        help="no step moves a joint farther than this from the last ([rad] or [m]; default no limit)",
    )
    add_safety_options(b)


def add_safety_options(b: argparse.ArgumentParser) -> None:
    """``--table``, ``--obstacle``, ``--self-collision``, ``--collision-geometry``, ``--clearance``, ...

    ``--no-slide`` too.
    """
    b.add_argument(
        "--table", type=float, default=None, help="a table top at this height [m]: no ask goes below it"
    )
    b.add_argument(
        "--obstacle",
        action="append",
        default=None,
        help="an obstacle no ask touches (repeatable): box:center=X,Y,Z,half=A,B,C or "
        "sphere:center=X,Y,Z,radius=R [m], world frame",
    )
    b.add_argument(
        "--self-collision", action="store_true", help="check every ask against the robot's own shapes"
    )
    b.add_argument(
        "--collision-geometry",
        choices=("urdf", "capsules"),
        default="urdf",
        help="the robot's shapes: its URDF's collision geometry (default) or one capsule per link",
    )
    b.add_argument(
        "--clearance", type=float, default=0.01, help="the margin every checked pair keeps [m] (default 0.01)"
    )
    b.add_argument(
        "--no-slide",
        action="store_true",
        help="a cut ask stops at the last safe posture of its move (default: it slides along the obstacle)",
    )


def safety(args: argparse.Namespace) -> dict[str, Any]:
    """The run options of ``--table``, ``--obstacle``, ... ({} when none is given: nothing checked)."""
    from gb_pin.safety.obstacles import Table, parse_obstacle

    obstacles: list[Any] = [] if getattr(args, "table", None) is None else [Table(args.table)]
    obstacles += [parse_obstacle(text) for text in getattr(args, "obstacle", None) or []]
    if not obstacles and not getattr(args, "self_collision", False):
        return {}
    return {
        "obstacles": obstacles or None,
        "self_collision": bool(args.self_collision),
        "collision_geometry": args.collision_geometry,
        "clearance": args.clearance,
        **({"slide": False} if getattr(args, "no_slide", False) else {}),
    }


def _default(value: float | str | None) -> str:
    return "auto" if value is None else value if isinstance(value, str) else f"{value:g}"


def parse_spec(option: str, text: str, defaults: dict[str, float | str | None]) -> dict[str, Any]:
    """``key=value,...`` over ``defaults``' keys: numbers, or words where a default is a word.

    ``auto`` gives a key its own default, as --help shows.

    Raises:
        InvalidArgumentError: an unknown key (the closest named), a key given twice, a value that is
            not a finite number.
    """
    values = dict(defaults)
    seen: set[str] = set()
    for item in filter(None, (part.strip() for part in text.split(","))):
        key, sep, raw = item.partition("=")
        key = key.strip()
        if not sep or key not in defaults:
            raise InvalidArgumentError(f"{option}: unknown key {key!r}; {suggest(key, list(defaults))}")
        if key in seen:
            raise InvalidArgumentError(f"{option}: {key} given twice in {text!r}; give each key once")
        seen.add(key)
        if raw.strip().lower() == "auto" and defaults[key] is None:
            continue  # the default --help shows as auto
        if isinstance(defaults[key], str):
            values[key] = raw.strip()
            continue
        try:
            value = float(raw)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            raise InvalidArgumentError(f"{option}: {key} must be a finite number, got {raw.strip()!r}")
        values[key] = value
    return values


def plant(args: argparse.Namespace, robot: Any) -> Any:
    """The robot wrapped in ``--plant``'s plant, or the robot itself.

    Raises:
        InvalidArgumentError: an unknown kind or key, a bad value.
    """
    if getattr(args, "plant", None) is None:
        return robot
    kind, _, rest = args.plant.partition(":")
    if kind not in PLANTS:
        raise InvalidArgumentError(f"--plant: unknown kind {kind!r}; {suggest(kind, list(PLANTS))}")
    defaults, build, _ = PLANTS[kind]
    return build(robot, parse_spec(f"--plant {kind}", rest, defaults))


def sensor(args: argparse.Namespace) -> Any:
    """``--sensor``'s :class:`~gb_pin.learn.sensor.Sensor`, or None.

    Raises:
        InvalidArgumentError: an unknown key or a bad value.
    """
    if getattr(args, "sensor", None) is None or str(args.sensor).startswith("aruco"):
        return None  # (a camera: gb_pin.cli.camera_options builds the watched robot)
    from gb_pin.learn.sensor import Sensor

    values = parse_spec("--sensor", args.sensor, {"noise": 0.0, "loss": 0.0, "seed": 0})
    seed = values["seed"]
    if seed != int(seed) or seed < 0:
        raise InvalidArgumentError(f"--sensor: seed must be an integer >= 0, got {seed:g}")
    return Sensor(values["noise"], values["loss"], int(seed))
