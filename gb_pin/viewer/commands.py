"""meshcat commands as msgpack bytes, and the *window* protocol they are sent through.

meshcat's browser viewer takes msgpack-encoded commands (``set_object``,
``set_transform``, ``set_property``, ``set_animation``, ``delete``). Everything the
viewer draws becomes such commands sent to a window: a live server
(:class:`gb_pin.viewer.server.LocalServer`) or an offline recorder
(:class:`gb_pin.viewer.cache.OfflineWindow`), so that one scene serves both.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

import numpy as np
import umsgpack
from numpy.typing import NDArray

Encoded = tuple[str, str, bytes, str]
"""One encoded command: (kind, path, msgpack bytes, property name or "")."""


class Command(Protocol):
    """A meshcat command (``meshcat.commands.SetObject`` and friends)."""

    def lower(self) -> dict[str, Any]:
        """The command as a msgpack-able dict with ``type`` and ``path``."""


class Window(Protocol):
    """Where commands go: a live server or an offline recorder."""

    def send(self, command: Any) -> None:
        """Send one meshcat command."""

    def send_encoded(self, kind: str, path: str, data: bytes, prop: str = "") -> None:
        """Send one encoded command."""

    def send_batch(self, batch: Sequence[Encoded]) -> None:
        """Send encoded commands (kind, path, data, property) in order, at once."""


def encode(command: Command | dict[str, Any], single: bool = False) -> tuple[str, str, bytes]:
    """(type, path, msgpack bytes) of a command; ``single`` packs floats as float32 (animations)."""
    data = command if isinstance(command, dict) else command.lower()
    packed = umsgpack.packb(data, force_float_precision="single") if single else umsgpack.packb(data)
    return str(data["type"]), str(data.get("path", "")), packed


def property_of(command: Command | dict[str, Any]) -> str:
    """The property a ``set_property`` command sets ("" for other commands)."""
    if isinstance(command, dict):
        return str(command.get("property", ""))
    return str(getattr(command, "key", ""))


# A msgpack float64 is the byte 0xcb then the big-endian double; 16 of them follow an array16 header.
_F64 = np.dtype([("marker", "u1"), ("value", ">f8")])
_PREFIXES: dict[str, bytes] = {}


def transform_message(path: str, T: NDArray[np.float64]) -> Encoded:
    """meshcat's ``set_transform`` command, msgpack-encoded (as ``umsgpack.packb`` would, ~5x faster).

    Live frames send dozens per frame; the map prefix of each path is encoded once and
    the 16 column-major matrix entries are packed in one numpy call.
    """
    prefix = _PREFIXES.get(path)
    if prefix is None:
        empty = umsgpack.packb({"type": "set_transform", "path": path, "matrix": []})
        prefix = _PREFIXES[path] = empty[:-1] + b"\xdc\x00\x10"  # drop the empty array, add array16 of 16
    rec = np.empty(16, dtype=_F64)
    rec["marker"] = 0xCB
    rec["value"] = np.asarray(T, dtype=float).T.ravel()
    return "set_transform", path, prefix + rec.tobytes(), ""


def property_message(path: str, key: str, value: Any) -> Encoded:
    """meshcat's ``set_property`` command, msgpack-encoded."""
    data = {"type": "set_property", "path": path, "property": key, "value": value}
    return "set_property", path, umsgpack.packb(data), key
