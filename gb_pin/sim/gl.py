"""Offscreen rendering: the GL backend MuJoCo renders with, chosen before MuJoCo is imported.

MuJoCo reads ``MUJOCO_GL`` once, when it is imported. Without a display (a server, CI, a
container) its default (GLFW) cannot make a context; EGL can (Mesa's software llvmpipe, or a
GPU's driver). So :func:`configure` sets ``MUJOCO_GL=egl`` when neither ``MUJOCO_GL`` nor
``DISPLAY``/``WAYLAND_DISPLAY`` is set; a value the user set is kept. :func:`renderer` makes
MuJoCo's offscreen renderer and turns a missing backend into one line saying what to install.
"""

from __future__ import annotations

import os
import sys
from typing import Any

from gb_pin.exceptions import CameraError

PACKAGES = {
    "egl": "libegl1 libgl1-mesa-dri (Debian/Ubuntu: apt-get install -y libegl1 libgl1-mesa-dri)",
    "osmesa": "libosmesa6 (apt-get install -y libosmesa6)",
    "glfw": "a display (set DISPLAY) or MUJOCO_GL=egl",
}


def configure() -> str | None:
    """Set ``MUJOCO_GL=egl`` when there is no display and MuJoCo is not imported yet; the backend in use."""
    if (
        "MUJOCO_GL" not in os.environ
        and not os.environ.get("DISPLAY")
        and not os.environ.get("WAYLAND_DISPLAY")
        and "mujoco" not in sys.modules
    ):
        os.environ["MUJOCO_GL"] = "egl"
    return os.environ.get("MUJOCO_GL")


def renderer(mujoco: Any, model: Any, width: int, height: int) -> Any:
    """MuJoCo's offscreen ``Renderer`` for ``model`` at ``width`` x ``height``.

    Raises:
        CameraError: no GL backend could make a context (one line: the backend and what to install).
    """
    backend = os.environ.get("MUJOCO_GL", "glfw (MuJoCo's default)")
    try:
        return mujoco.Renderer(model, height=height, width=width)
    except Exception as exc:  # MuJoCo raises RuntimeError, ImportError or its FatalError here
        need = PACKAGES.get(backend.split()[0].lower(), "an OpenGL backend: MUJOCO_GL=egl, osmesa or glfw")
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise CameraError(
            f"cannot render offscreen with MUJOCO_GL={backend}: {first[:160]}; install {need}"
        ) from exc
