"""The scene as a browser sees it, kept as commands: :class:`SceneCache`, and :class:`OfflineWindow`.

A live server replays the cache to each browser that connects; an offline window
only records into one, for HTML export (:mod:`gb_pin.viewer.page`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import umsgpack

from gb_pin.viewer.commands import Command, Encoded, encode, property_of
from gb_pin.viewer.legend import CONTROL, remove_control
from gb_pin.viewer.page import html_page


def _split(path: str) -> tuple[str, ...]:
    return tuple(p for p in path.split("/") if p)


class SceneCache:
    """The scene as a browser sees it: per path the last object, transform and properties; one animation.

    Unlike meshcat's server, repeated ``set_property`` calls replace each other (a
    live viewer toggles visibility at every frame), so the cache stays bounded. The legend's
    ``set_control`` (:mod:`~gb_pin.viewer.legend`) is kept last-only too: replayed to live
    browsers, and written as static HTML into exported pages (their policy runs no evaluated code).
    """

    def __init__(self) -> None:
        self._objects: dict[tuple[str, ...], bytes] = {}
        self._transforms: dict[tuple[str, ...], bytes] = {}
        self._properties: dict[tuple[tuple[str, ...], str], bytes] = {}
        self._animation: bytes | None = None
        self._legend: bytes | None = None
        self.legend_html = ""

    def apply(self, kind: str, path: str, data: bytes, prop: str = "") -> None:
        """Record one command."""
        key = _split(path)
        if kind == "set_object":
            self._objects[key] = data
        elif kind == "set_transform":
            self._transforms[key] = data
        elif kind == "set_property":
            self._properties[(key, prop)] = data
        elif kind == "set_animation":
            self._animation = data
        elif kind == "set_control":
            command = umsgpack.unpackb(data)
            if command.get("name") == CONTROL:
                self._legend, self.legend_html = data, str(command.get("html", ""))
        elif kind == "delete":
            n = len(key)
            for table in (self._objects, self._transforms):
                for k in [k for k in table if k[:n] == key]:
                    del table[k]
            for pk in [pk for pk in self._properties if pk[0][:n] == key]:
                del self._properties[pk]
            if n == 0:
                self._animation = None

    def messages(self) -> list[bytes]:
        """What rebuilds the scene in a live page: objects, properties, transforms, animation, legend."""
        out = self._scene_messages()
        if self._legend is not None:
            out += [self._legend, encode(remove_control())[2]]
        return out

    def _scene_messages(self) -> list[bytes]:
        out = [*self._objects.values(), *self._properties.values(), *self._transforms.values()]
        if self._animation is not None:
            out.append(self._animation)
        return out

    def html(self, title: str = "gb_pin") -> str:
        """One self-contained HTML page: the scene and its legend (:func:`~gb_pin.viewer.page.html_page`)."""
        return html_page(self._scene_messages(), title, overlay=self.legend_html)


class OfflineWindow:
    """A meshcat window without a server: it only records the scene, for HTML export."""

    web_url = ""

    def __init__(self) -> None:
        self.scene = SceneCache()

    def send(self, command: Command | dict[str, Any]) -> None:
        """Record a meshcat command."""
        self.send_encoded(*encode(command), prop=property_of(command))

    def send_encoded(self, kind: str, path: str, data: bytes, prop: str = "") -> None:
        """Record an already-encoded command."""
        self.scene.apply(kind, path, data, prop)

    def send_batch(self, batch: Sequence[Encoded]) -> None:
        """Record encoded commands (kind, path, data, property) in order."""
        for kind, path, data, prop in batch:
            self.scene.apply(kind, path, data, prop)

    def get_scene(self) -> str:
        """The scene as one self-contained HTML page (``meshcat.Visualizer.static_html``)."""
        return self.scene.html()

    def wait(self) -> str:
        """Nothing to wait for offline."""
        return "ok"

    def close(self) -> None:
        """Nothing to close offline."""
