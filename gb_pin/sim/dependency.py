"""MuJoCo (the ``sim`` extra), checked before use.

``import gb_pin.sim`` works without MuJoCo: the modules that simulate import it when a plant
is built, after :func:`require_mujoco`, so that a missing MuJoCo is one
:class:`~gb_pin.exceptions.SimulationError` naming the extra to install.
"""

from __future__ import annotations

from types import ModuleType

from gb_pin.exceptions import SimulationError

INSTALL_HINT = "pip install 'gb_pin[sim]' (or: pip install mujoco)"


def require_mujoco() -> ModuleType:
    """The ``mujoco`` package.

    Raises:
        SimulationError: MuJoCo is not installed; the message says how to install it, in one line.
    """
    from gb_pin.sim.gl import configure

    configure()  # MUJOCO_GL=egl without a display: MuJoCo reads it once, at its import
    try:
        import mujoco
    except ImportError as exc:
        raise SimulationError(
            f"the MuJoCo plant needs MuJoCo, which is not installed: {INSTALL_HINT}"
        ) from exc
    return mujoco
