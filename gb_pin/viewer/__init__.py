"""Meshcat viewer: watch babbling live, replay recorded runs, share them as one offline HTML file.

The only part of gb_pin that imports meshcat. The public names are exported lazily
(PEP 562): ``import gb_pin.viewer`` loads nothing, works without meshcat, and a
missing meshcat is reported as a :class:`~gb_pin.exceptions.ViewerError` naming the
extra to install when a viewer starts or a page is exported.

>>> import gb_pin
>>> from gb_pin.viewer import Viewer
>>> with Viewer() as viewer:                     # doctest: +SKIP
...     print(viewer.url)                         # http://127.0.0.1:7000/static/
...     gb_pin.babble("planar20", movements=300, viewer=viewer)

What is drawn: the robot (a stick figure of joints and links, or its meshes when it
has a visual model), the target set X*, the current target x*_t, the reached
effector position with a fading trail, and the paper's Fig. 3 overlay (the
reached grid f(g(x*)) and the postures g(x*) of a few targets).

Modules, each one concept (none imports one that imports it back):

* entry points: :mod:`~gb_pin.viewer.live` (:class:`Viewer`, :func:`open_viewer`),
  :mod:`~gb_pin.viewer.serve` (live replay and model views),
  :mod:`~gb_pin.viewer.export` (offline HTML files),
  :mod:`~gb_pin.viewer.replay`, :mod:`~gb_pin.viewer.ranges` (which movements);
* what is drawn: :mod:`~gb_pin.viewer.scene` composes the robot's figure
  (:mod:`~gb_pin.viewer.figure`, :mod:`~gb_pin.viewer.stick`, :mod:`~gb_pin.viewer.meshes`:
  the viewer's only Pinocchio user), :mod:`~gb_pin.viewer.markers`,
  :mod:`~gb_pin.viewer.overlay`, :mod:`~gb_pin.viewer.animation` and :mod:`~gb_pin.viewer.legend`
  (the text box: robot, movement r, E^X, D^home, colours), from
  :mod:`~gb_pin.viewer.shapes`, :mod:`~gb_pin.viewer.geometry` and :mod:`~gb_pin.viewer.style`;
* transport: :mod:`~gb_pin.viewer.commands` (encoding, the window protocol),
  :mod:`~gb_pin.viewer.cache` (scene cache, offline window), :mod:`~gb_pin.viewer.page`
  (self-contained HTML), :mod:`~gb_pin.viewer.server` (127.0.0.1 only),
  :mod:`~gb_pin.viewer.dependencies` (the meshcat check).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gb_pin._lazy import lazy_exports

# public name -> the module that defines it (and the name there, if another)
_EXPORTS: dict[str, tuple[str, str]] = {
    "INSTALL_HINT": ("gb_pin.viewer.dependencies", "INSTALL_HINT"),
    "OVERLAY_PATH": ("gb_pin.viewer.style", "OVERLAY"),
    "Viewer": ("gb_pin.viewer.live", "Viewer"),
    "ViewerError": ("gb_pin.exceptions", "ViewerError"),
    "ViewerWarning": ("gb_pin.exceptions", "ViewerWarning"),
    "export_model": ("gb_pin.viewer.export", "export_model"),
    "export_replay": ("gb_pin.viewer.export", "export_replay"),
    "live_model": ("gb_pin.viewer.serve", "live_model"),
    "live_replay": ("gb_pin.viewer.serve", "live_replay"),
    "open_viewer": ("gb_pin.viewer.live", "open_viewer"),
    "parse_range": ("gb_pin.viewer.ranges", "parse_range"),
    "replay_animation": ("gb_pin.viewer.replay", "replay_animation"),
    "replay_window": ("gb_pin.viewer.replay", "replay_window"),
    "select_movements": ("gb_pin.viewer.ranges", "select_movements"),
    "serve_until_interrupted": ("gb_pin.viewer.serve", "serve_until_interrupted"),
}

__all__ = [
    "INSTALL_HINT",
    "OVERLAY_PATH",
    "Viewer",
    "ViewerError",
    "ViewerWarning",
    "export_model",
    "export_replay",
    "live_model",
    "live_replay",
    "open_viewer",
    "parse_range",
    "replay_animation",
    "replay_window",
    "select_movements",
    "serve_until_interrupted",
]


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())


if TYPE_CHECKING:  # what the lazy exports resolve to, for type checkers
    from gb_pin.exceptions import ViewerError, ViewerWarning
    from gb_pin.viewer.dependencies import INSTALL_HINT
    from gb_pin.viewer.export import export_model, export_replay
    from gb_pin.viewer.live import Viewer, open_viewer
    from gb_pin.viewer.ranges import parse_range, select_movements
    from gb_pin.viewer.replay import replay_animation, replay_window
    from gb_pin.viewer.serve import live_model, live_replay, serve_until_interrupted
    from gb_pin.viewer.style import OVERLAY as OVERLAY_PATH
