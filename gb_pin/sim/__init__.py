"""Physics plants: robots gb_pin loads, simulated by MuJoCo (the ``sim`` extra: ``pip install gb_pin[sim]``).

>>> import gb_pin
>>> from gb_pin.sim import MujocoPlant
>>> plant = MujocoPlant("so101", kp=10.0, settle=0.2, gravity=True, seed=0)   # doctest: +SKIP
>>> result = gb_pin.babble(plant, movements=3000)                              # doctest: +SKIP
>>> result = gb_pin.babble("so101@mujoco:kp=10,settle=0.2", movements=3000)    # doctest: +SKIP

The only part of gb_pin that imports MuJoCo. The public names are exported lazily (PEP 562):
``import gb_pin.sim`` loads nothing, works without MuJoCo, and a missing MuJoCo is one
:class:`~gb_pin.exceptions.SimulationError` naming the extra to install when a plant is built.

Modules, one concept each:

- :mod:`~gb_pin.sim.plant`: :class:`MujocoPlant`, the robot (ask = command, settle, read);
- :mod:`~gb_pin.sim.mjcf`: the MuJoCo model written from the learner's chain and Pinocchio's inertias;
- :mod:`~gb_pin.sim.servos`: the position servos (gain, damping, force limit, armature);
- :mod:`~gb_pin.sim.settling`: when a held posture is read (at rest, or a fixed period);
- :mod:`~gb_pin.sim.equilibrium`: the resting posture under a command (the plant's true body);
- :mod:`~gb_pin.sim.snapshot`: the plant's state in session checkpoints;
- :mod:`~gb_pin.sim.spec`: plants named by strings (``"so101@mujoco:kp=10"``);
- :mod:`~gb_pin.sim.scene`, :mod:`~gb_pin.sim.meshes`, :mod:`~gb_pin.sim.camera`, :mod:`~gb_pin.sim.gl`:
  what a camera sees (decimated meshes, the marker plate, the camera pose), rendering it offscreen;
- :mod:`~gb_pin.sim.dependency`: the MuJoCo check (and MUJOCO_GL=egl without a display).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gb_pin._lazy import lazy_exports

# public name -> the module that defines it (and the name there, if another)
_EXPORTS: dict[str, tuple[str, str]] = {
    "INSTALL_HINT": ("gb_pin.sim.dependency", "INSTALL_HINT"),
    "MujocoPlant": ("gb_pin.sim.plant", "MujocoPlant"),
    "Servos": ("gb_pin.sim.servos", "Servos"),
    "Settling": ("gb_pin.sim.settling", "Settling"),
    "SimulationError": ("gb_pin.exceptions", "SimulationError"),
    "is_plant_spec": ("gb_pin.sim.spec", "is_plant_spec"),
    "parse_plant": ("gb_pin.sim.spec", "parse_plant"),
    "plant_spec": ("gb_pin.sim.spec", "plant_spec"),
    "require_mujoco": ("gb_pin.sim.dependency", "require_mujoco"),
}

__all__ = [
    "INSTALL_HINT",
    "MujocoPlant",
    "Servos",
    "Settling",
    "SimulationError",
    "is_plant_spec",
    "parse_plant",
    "plant_spec",
    "require_mujoco",
]

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())


if TYPE_CHECKING:  # what the lazy exports resolve to, for type checkers
    from gb_pin.exceptions import SimulationError
    from gb_pin.sim.dependency import INSTALL_HINT, require_mujoco
    from gb_pin.sim.plant import MujocoPlant
    from gb_pin.sim.servos import Servos
    from gb_pin.sim.settling import Settling
    from gb_pin.sim.spec import is_plant_spec, parse_plant, plant_spec
