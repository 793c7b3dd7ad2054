"""``--plant mujoco[:key=value,...]``: the robot simulated by MuJoCo (``--robot so101 --plant mujoco``).

Registers the ``mujoco`` kind with ``--plant`` (:mod:`gb_pin.cli.body_options`): its keys are
:class:`gb_pin.sim.MujocoPlant`'s numeric arguments (``auto``: the plant's own default), and it builds
the plant on the robot ``--robot`` names. Without MuJoCo installed the run stops before any work with
one line saying how to install it. :func:`plant_summary` is the summary's line about the plant.
"""

from __future__ import annotations

import argparse
from typing import Any

from gb_pin.cli.body_options import register_plant
from gb_pin.exceptions import InvalidArgumentError

DEFAULTS: dict[str, float | str | None] = {
    "kp": 10.0,
    "damping": None,
    "force_limit": None,
    "armature": 0.01,
    "gravity": 1.0,
    "settle": None,
    "tolerance": None,
    "period": None,
    "timestep": 0.002,
    "noise": 0.0,
    "loss": 0.0,
    "seed": 0.0,
    "camera": "none",
    "meshes": 1.0,
    "pixel_noise": 3.0,
}
"""The keys of ``--plant mujoco``: MujocoPlant's arguments (None: its default)."""


def mujoco_plant(robot: Any, values: dict[str, Any]) -> Any:
    """The :class:`~gb_pin.sim.plant.MujocoPlant` of ``robot`` with ``--plant mujoco``'s values.

    Raises:
        SimulationError: MuJoCo is not installed (one line: how to install it).
        InvalidArgumentError: gravity not 0 or 1, a seed that is not an integer >= 0, a bad value.
    """
    from gb_pin.sim.dependency import require_mujoco

    require_mujoco()
    given = {k: v for k, v in values.items() if v is not None}
    given["camera"] = None if given["camera"] in ("none", "") else given["camera"]
    if given["meshes"] not in (0.0, 1.0):
        raise InvalidArgumentError(f"--plant mujoco: meshes must be 1 or 0, got {given['meshes']:g}")
    given["meshes"] = bool(given["meshes"])
    gravity = given["gravity"]
    if gravity not in (0.0, 1.0):
        raise InvalidArgumentError(f"--plant mujoco: gravity must be 1 (on) or 0 (off), got {gravity:g}")
    if given["seed"] != int(given["seed"]) or given["seed"] < 0:
        raise InvalidArgumentError(f"--plant mujoco: seed must be an integer >= 0, got {given['seed']:g}")
    given["gravity"], given["seed"] = bool(given["gravity"]), int(given["seed"])
    from gb_pin.sim.plant import MujocoPlant

    return MujocoPlant(robot, **given)


register_plant(
    "mujoco",
    DEFAULTS,
    mujoco_plant,
    "simulated by MuJoCo: servo gain kp [N m/rad], damping [N m s/rad] (auto: 0.05 kp), force_limit [N m] "
    "(auto: none), armature [kg m^2], gravity 1/0; each ask held until at rest (tolerance [rad/s], auto "
    "0.01) for at most settle [s] (auto 0.5), or exactly period [s]; noise [m], loss and seed of the "
    "readings; camera=side|front renders it (with --sensor aruco: docs/CAMERA.md), meshes 1/0, "
    "pixel_noise [grey levels]; needs pip install 'gb_pin[sim]' (docs/SIMULATION.md)",
)


def plant_summary(args: argparse.Namespace, robot: Any) -> str | None:
    """The summary's ``plant`` line (servos, gravity, settling, MuJoCo steps per ask); None: no MuJoCo."""
    if not str(getattr(args, "plant", None) or "").startswith("mujoco"):
        return None
    per_ask = robot.steps / max(robot.asks, 1)
    return (
        f"plant            MuJoCo: {robot.servos.describe()}; gravity {'on' if robot.gravity else 'off'}; "
        f"{robot.settling.describe()}; {robot.asks} asks, {per_ask:.0f} steps of {robot.timestep:g} s each"
    )
