"""``--plant``: run the robot in a physics simulator (``gb-pin babble --robot so101 --plant mujoco:kp=10``).

The option's value is a plant string of :mod:`gb_pin.sim.spec` without the robot
(``mujoco[:key=value,...]``); the robot is the one ``--robot`` (and the model options) name.
Without MuJoCo installed the run stops before any work with one line saying how to install it.
"""

from __future__ import annotations

import argparse
from typing import Any

from gb_pin.exceptions import InvalidArgumentError


def add_plant_option(parser: argparse.ArgumentParser) -> None:
    """``--plant mujoco[:key=value,...]``."""
    parser.add_argument(
        "--plant",
        default=None,
        help="simulate the robot in MuJoCo and learn from the simulated arm: mujoco[:key=value,...] with "
        "kp (servo gain, N m/rad; default 10), damping, force_limit, armature, gravity (on/off), settle "
        "(longest hold per ask, s), tolerance (rad/s), period (a fixed hold instead, s), timestep, noise "
        "(m), loss, seed; e.g. mujoco:kp=10,settle=0.2 (needs pip install 'gb_pin[sim]'; docs/SIMULATION.md)",
    )


def plant_robot(args: argparse.Namespace, robot: Any) -> Any:
    """``robot`` (a preset name or a loaded robot) as the simulated plant ``--plant`` asks for, or as is.

    Raises:
        InvalidArgumentError: a malformed plant string, ``--plant`` with ``--resume``, a robot
            without a Pinocchio model.
        SimulationError: MuJoCo is not installed (one line: how to install it).
    """
    if getattr(args, "plant", None) is None:
        return robot
    from gb_pin.sim.dependency import require_mujoco
    from gb_pin.sim.spec import parse_plant

    options = parse_plant(args.plant)
    require_mujoco()
    if args.resume:
        raise InvalidArgumentError(
            "--resume with --plant: a simulated plant's checkpoint continues from Python, "
            "gb_pin.resume_session(path, robot=gb_pin.sim.MujocoPlant(...)) (docs/SIMULATION.md)"
        )
    from gb_pin.sim.plant import MujocoPlant

    return MujocoPlant(robot, **options)


def plant_summary(args: argparse.Namespace, robot: Any) -> str | None:
    """The summary's ``plant`` line (servos, gravity, settling, MuJoCo steps per ask); None: no plant."""
    from gb_pin.sim.plant import MujocoPlant

    if getattr(args, "plant", None) is None or not isinstance(robot, MujocoPlant):
        return None
    per_ask = robot.steps / max(robot.asks, 1)
    return (
        f"plant            MuJoCo: {robot.servos.describe()}; gravity {'on' if robot.gravity else 'off'}; "
        f"{robot.settling.describe()}; {robot.asks} asks, {per_ask:.0f} steps of {robot.timestep:g} s each"
    )
