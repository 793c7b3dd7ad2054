"""The viewer server's listening side: capped connections, timeouts, bounded requests, quiet logs.

The server answers local browsers only (127.0.0.1), but any local process can connect. What it
accepts is bounded (:func:`http_server`): a request must send its header within
:data:`IDLE_SECONDS` (an idle keep-alive connection is closed after as long), a header holds at
most :data:`MAX_HEADER_BYTES`, a body (the server is GET-only) :data:`MAX_BODY_BYTES`, a browser's
websocket message :data:`MAX_MESSAGE_BYTES`. :class:`Listener` accepts connections itself instead
of tornado's accept loop: beyond :data:`MAX_CONNECTIONS` open ones the oldest connection that is
not a browser's websocket is closed (idle connections cannot starve the browser), and when the
process runs out of file descriptors it pauses accepting for :data:`PAUSE_SECONDS` instead of
failing on every turn of the event loop (which wrote a traceback each time: 10^5 in 8 s). Each
such event is logged as one sanitised line, at most once per :data:`NOTE_SECONDS` per kind
(:class:`Notes`), so nothing floods the terminal.
"""

from __future__ import annotations

import asyncio
import logging
import socket
import time
from typing import Any

import tornado.httpserver
import tornado.iostream
import tornado.web

from gb_pin._names import printable

MAX_CONNECTIONS = 64
"""Connections open at once (browsers open a few: the page, its scripts, the websocket)."""
IDLE_SECONDS = 10.0
"""A connection that sends no complete request header within this time is closed [s]."""
MAX_HEADER_BYTES = 16 * 2**10
MAX_BODY_BYTES = 4 * 2**10
"""The largest request body read: the viewer serves GET requests only."""
MAX_MESSAGE_BYTES = 2**20
"""The largest websocket message read from a browser (nothing a browser sends is used)."""
PAUSE_SECONDS = 1.0
NOTE_SECONDS = 10.0


class Notes:
    """Log lines at most once per :data:`NOTE_SECONDS` per kind, saying how many were left out."""

    def __init__(self, log: logging.Logger, every: float = NOTE_SECONDS) -> None:
        self.log = log
        self.every = every
        self._last: dict[str, float] = {}
        self._skipped: dict[str, int] = {}

    def warn(self, kind: str, message: str) -> None:
        """Log ``message`` (sanitised) unless a line of this ``kind`` was logged recently."""
        now = time.monotonic()
        if now - self._last.get(kind, -1e9) < self.every:
            self._skipped[kind] = self._skipped.get(kind, 0) + 1
            return
        skipped = self._skipped.pop(kind, 0)
        self._last[kind] = now
        more = f" ({skipped} more like it not shown)" if skipped else ""
        self.log.warning("%s%s", printable(message, 300), more)


def http_server(app: tornado.web.Application) -> tornado.httpserver.HTTPServer:
    """The HTTP server of ``app`` with the bounds of this module (timeouts, header and body sizes)."""
    app.settings.setdefault("websocket_max_message_size", MAX_MESSAGE_BYTES)
    return tornado.httpserver.HTTPServer(
        app,
        idle_connection_timeout=IDLE_SECONDS,  # also the time a request has to send its header
        body_timeout=IDLE_SECONDS,
        max_header_size=MAX_HEADER_BYTES,
        max_body_size=MAX_BODY_BYTES,
        max_buffer_size=MAX_MESSAGE_BYTES + MAX_HEADER_BYTES,
    )


class Listener:
    """Accept connections on ``sockets`` for ``http``, at most :data:`MAX_CONNECTIONS` open at once.

    Runs in the server's thread (its asyncio loop must be current).
    """

    def __init__(
        self, http: tornado.httpserver.HTTPServer, sockets: list[socket.socket], notes: Notes
    ) -> None:
        self.http = http
        self.sockets = sockets
        self.notes = notes
        self.streams: dict[tornado.iostream.IOStream, None] = {}  # open connections, oldest first
        self.kept: set[Any] = set()
        self.loop = asyncio.get_event_loop()
        self.closed = False
        for sock in sockets:
            sock.setblocking(False)
            self.loop.add_reader(sock.fileno(), self._accept, sock)

    def _accept(self, sock: socket.socket) -> None:
        for _ in range(128):  # as tornado: a bounded batch per wake-up
            try:
                connection, address = sock.accept()
            except (BlockingIOError, InterruptedError):
                return
            except ConnectionAbortedError:
                continue
            except OSError as exc:  # out of file descriptors (EMFILE, ENFILE) or buffers: pause
                self.loop.remove_reader(sock.fileno())
                self.loop.call_later(PAUSE_SECONDS, self._resume, sock)
                self.notes.warn(
                    "accept", f"viewer: cannot accept connections ({exc.strerror or exc}); pausing"
                )
                return
            if not self._make_room():
                connection.close()
                self.notes.warn("cap", f"viewer: {MAX_CONNECTIONS} viewers connected; refusing more")
                continue
            stream = tornado.iostream.IOStream(connection, max_buffer_size=self.http.max_buffer_size)
            self.streams[stream] = None
            self.http.handle_stream(stream, address)

    def _make_room(self) -> bool:
        """Whether a connection may be added: under the cap, or after closing the oldest plain one.

        Connections that became websockets (:meth:`keep`: a browser showing the scene) are never
        closed to make room, so connections left open by another local process cannot starve them.
        """
        self.streams = {s: None for s in self.streams if not s.closed()}
        if len(self.streams) < MAX_CONNECTIONS:
            return True
        for stream in self.streams:  # oldest first
            if stream not in self.kept:
                del self.streams[stream]
                stream.close()
                self.notes.warn("cap", f"viewer: {MAX_CONNECTIONS} connections open; closing the oldest")
                return True
        return False

    def keep(self, stream: Any) -> None:
        """Never close ``stream`` (a browser's websocket) to make room for another connection."""
        self.kept = {s for s in self.kept if not s.closed()}
        self.kept.add(stream)

    def _resume(self, sock: socket.socket) -> None:
        if not self.closed:
            self.loop.add_reader(sock.fileno(), self._accept, sock)

    def close(self) -> None:
        """Stop listening (the open connections are the server's to close); idempotent."""
        if self.closed:
            return
        self.closed = True
        for sock in self.sockets:
            self.loop.remove_reader(sock.fileno())
            sock.close()


def quiet_loop_errors(loop: asyncio.AbstractEventLoop, notes: Notes) -> None:
    """Report an exception escaping a callback of ``loop`` as one rate-limited line, not a traceback."""

    def handler(loop: asyncio.AbstractEventLoop, context: dict[str, Any]) -> None:
        exc = context.get("exception")
        what = f"{type(exc).__name__}: {exc}" if exc is not None else context.get("message", "error")
        notes.warn("loop", f"viewer: {what}")

    loop.set_exception_handler(handler)
