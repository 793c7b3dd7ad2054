"""The viewer's third-party libraries (meshcat, tornado, umsgpack: the ``viz`` extra), checked before use.

The modules that draw (:mod:`gb_pin.viewer.shapes`) and serve (:mod:`gb_pin.viewer.server`)
import them when loaded. The entry points (:class:`~gb_pin.viewer.live.Viewer`, the
exports) call :func:`require_meshcat` before loading those, so that ``import gb_pin.viewer``
works without the extra and a missing library is a :class:`~gb_pin.exceptions.ViewerError`
naming the extra to install.
"""

from __future__ import annotations

import os
import warnings
from types import ModuleType

from gb_pin.exceptions import ViewerError

INSTALL_HINT = "install the viewer with: pip install 'gb_pin[viz]'"


def import_meshcat() -> ModuleType:
    """The ``meshcat`` package, imported without its import-time deprecation warning.

    Raises:
        ImportError: meshcat is not installed.
    """
    with warnings.catch_warnings():
        # meshcat 0.3.2 imports its zmq server, which imports a module pyzmq deprecated.
        warnings.filterwarnings("ignore", category=DeprecationWarning)
        import meshcat
    return meshcat


def require_meshcat() -> None:
    """Check that the viewer's libraries import.

    Raises:
        ViewerError: one is missing; the message names the extra to install.
    """
    try:
        import_meshcat()
        import tornado  # noqa: F401
        import umsgpack  # noqa: F401
    except ImportError as exc:
        raise ViewerError(f"the viewer needs meshcat ({exc}); {INSTALL_HINT}") from exc


def viewer_assets() -> str:
    """The folder of meshcat's bundled browser viewer (``meshcat/viewer/dist``: page and script)."""
    return os.path.join(import_meshcat().viewer_assets_path(), "dist")
