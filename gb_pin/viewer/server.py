"""meshcat's viewer served on 127.0.0.1 only, by a tornado server in a background thread of this process.

meshcat 0.3.2's own server (``meshcat.servers.zmqserver``) binds its web port to
every interface and relays each command through a zmq round trip to a second
process. :class:`LocalServer` replaces it: it listens on 127.0.0.1 only, answers only
requests whose Host header names that address (no DNS rebinding), with bounded connections,
timeouts and request sizes (:mod:`gb_pin.viewer.listener`), serves meshcat's
bundled viewer (``meshcat/viewer/dist``, nothing from the network) and forwards
commands to the connected browsers, each through its own bounded queue
(:class:`~gb_pin.viewer.outbox.Outbox`: a browser that stops reading gets frames dropped,
then is disconnected; the others are served as before). It has the ``send(command)`` method of
``meshcat.visualizer.ViewerWindow``, so ``meshcat.Visualizer(window=...)`` (and with
it pinocchio's ``MeshcatVisualizer``) draws through it unchanged.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import socket
import threading
import time
import urllib.parse
from collections.abc import Iterator, Sequence
from concurrent.futures import Future
from typing import Any

import tornado.httpserver
import tornado.ioloop
import tornado.netutil
import tornado.web
import tornado.websocket

from gb_pin._names import printable
from gb_pin.exceptions import ViewerError
from gb_pin.viewer.cache import SceneCache
from gb_pin.viewer.commands import Command, Encoded, encode, property_of
from gb_pin.viewer.dependencies import viewer_assets
from gb_pin.viewer.listener import Listener, Notes, http_server, quiet_loop_errors
from gb_pin.viewer.outbox import STALL_SECONDS, Outbox

LOOPBACK = "127.0.0.1"
DEFAULT_PORT = 7000
PORT_ATTEMPTS = 20
VIEWER_ROOT = viewer_assets()
_log = logging.getLogger("gb_pin.viewer")


def sanitize(text: str, limit: int = 200) -> str:
    r"""``text`` with every non-printable character escaped (``\x1b``), cut to ``limit`` characters.

    Request lines are attacker-controlled: logged raw, ``%1b[...`` would write escape sequences
    to the user's terminal (:func:`gb_pin._names.printable`).
    """
    return printable(text, limit)


def _log_request(handler: tornado.web.RequestHandler) -> None:
    """tornado's access log: one sanitised line, at debug level (nothing on the terminal by default)."""
    request = handler.request
    _log.debug("%d %s %s", handler.get_status(), sanitize(request.method or ""), sanitize(request.uri or ""))


class _QuietErrors:
    """Request handlers that log a failed request as one sanitised line, never a traceback."""

    request: Any

    def log_exception(self, typ: Any, value: Any, tb: Any) -> None:
        if isinstance(value, tornado.web.HTTPError):
            return
        _log.warning("viewer: error %s answering %s", type(value).__name__, sanitize(self.request.uri or ""))


def bind_loopback(port: int | None) -> tuple[list[socket.socket], int]:
    """Listening sockets on 127.0.0.1: ``port``, or the first free one from 7000 on.

    Raises:
        ViewerError: the port is taken, or none of the ports tried is free.
    """
    if port is not None and not (isinstance(port, int) and 1 <= port <= 65535):
        raise ViewerError(f"port must be an integer in [1, 65535], got {port!r}")
    ports = [port] if port is not None else list(range(DEFAULT_PORT, DEFAULT_PORT + PORT_ATTEMPTS))
    errors = []
    for p in ports:
        try:
            return tornado.netutil.bind_sockets(p, address=LOOPBACK, family=socket.AF_INET), p
        except OSError as exc:
            errors.append(f"{p}: {exc.strerror or exc}")
    if port is not None:
        raise ViewerError(f"cannot listen on {LOOPBACK}:{port} ({errors[0]}); choose another port")
    raise ViewerError(f"no free port for the viewer on {LOOPBACK}:{ports[0]}-{ports[-1]} ({errors[-1]})")


class _StaticHandler(_QuietErrors, tornado.web.StaticFileHandler):
    def initialize(
        self,
        path: str,
        default_filename: str | None = None,
        allowed_symlink_directory: str | list[str] | None = None,
        server: LocalServer | None = None,
    ) -> None:
        assert server is not None
        self.server = server
        super().initialize(path, default_filename)

    async def prepare(self) -> None:
        if self.request.host not in self.server.allowed_hosts:
            raise tornado.web.HTTPError(403)
        path = urllib.parse.unquote(self.request.path)
        if not path.isprintable():  # NUL, escapes: no file of the viewer has such a name
            raise tornado.web.HTTPError(404)

    def set_extra_headers(self, path: str) -> None:
        self.set_header("Cache-Control", "no-store")


class _SocketHandler(_QuietErrors, tornado.websocket.WebSocketHandler):
    def initialize(self, server: LocalServer) -> None:
        self.server = server

    async def prepare(self) -> None:
        if self.request.host not in self.server.allowed_hosts:
            raise tornado.web.HTTPError(403)

    def open(self, *args: str, **kwargs: str) -> None:
        stream = getattr(self.ws_connection, "stream", None)
        if stream is not None:
            self.server._listener.keep(stream)  # a browser: never closed to make room
        self.server._opened(self)

    def on_message(self, message: str | bytes) -> None:
        # The viewer page only sends captured images on request; nothing is read from browsers.
        pass

    def on_close(self) -> None:
        self.server._closed(self)


class LocalServer:
    """meshcat's viewer served on 127.0.0.1 from a background thread of this process.

    It implements the window interface of ``meshcat.visualizer.ViewerWindow``
    (``send``, ``wait``, ``get_scene``, ``web_url``). ``send`` encodes in the calling
    thread and returns at once; the server thread writes to the browsers. A browser
    that connects later receives the cached scene.

    Args:
        port: TCP port on 127.0.0.1; None: the first free one from 7000.

    Raises:
        ViewerError: the port cannot be bound.
    """

    def __init__(self, port: int | None = None) -> None:
        sockets, self.port = bind_loopback(port)
        self.host = LOOPBACK
        self.web_url = f"http://{LOOPBACK}:{self.port}/static/"
        self.allowed_hosts = frozenset({f"{LOOPBACK}:{self.port}", f"localhost:{self.port}"})
        self.scene = SceneCache()
        self._lock = threading.Lock()
        self._clients: dict[_SocketHandler, Outbox] = {}  # client -> its bounded send queue
        self.stall_seconds = STALL_SECONDS
        self._connected = threading.Event()
        self._closed_flag = False
        self._notes = Notes(_log)
        self._ready: Future[tornado.ioloop.IOLoop] = Future()
        self._thread = threading.Thread(
            target=self._serve, args=(sockets,), name="gb_pin-viewer", daemon=True
        )
        self._thread.start()
        try:
            self._ioloop = self._ready.result(timeout=10)
        except Exception as exc:
            for s in sockets:
                s.close()
            raise ViewerError(f"the viewer's server thread failed to start: {exc}") from exc

    # -- server thread --------------------------------------------------------------
    def _serve(self, sockets: list[socket.socket]) -> None:
        loop = asyncio.new_event_loop()
        asyncio.set_event_loop(loop)
        try:
            ioloop = tornado.ioloop.IOLoop.current()
            quiet_loop_errors(loop, self._notes)
            http = self._make_server(sockets)
        except BaseException as exc:
            self._ready.set_exception(exc)
            loop.close()
            return
        self._ready.set_result(ioloop)
        tornado.ioloop.PeriodicCallback(self._drop_stalled, 1000.0).start()
        try:
            ioloop.start()
        finally:
            self._listener.close()
            http.stop()
            with contextlib.suppress(Exception):
                loop.run_until_complete(loop.shutdown_asyncgens())
            loop.close()

    def _make_server(self, sockets: list[socket.socket]) -> tornado.httpserver.HTTPServer:
        app = tornado.web.Application(
            [
                (
                    r"/static/(.*)",
                    _StaticHandler,
                    {"path": VIEWER_ROOT, "default_filename": "index.html", "server": self},
                ),
                (r"/", _SocketHandler, {"server": self}),
            ],
            log_function=_log_request,  # sanitised, at debug level: nothing on the user's terminal
        )
        http = http_server(app)  # timeouts, bounded headers, bodies and messages
        self._listener = Listener(http, sockets, self._notes)  # at most MAX_CONNECTIONS at once
        self._http = http
        return http

    def _opened(self, client: _SocketHandler) -> None:
        box = Outbox(lambda data: self._write(client, data), self._scene_messages)
        with self._lock:
            self._clients[client] = box
        box.put(self._scene_messages())
        self._connected.set()

    def _scene_messages(self) -> list[bytes]:
        with self._lock:
            return self.scene.messages()

    def _closed(self, client: _SocketHandler) -> None:
        with self._lock:
            box = self._clients.pop(client, None)
        if box is not None:
            box.close()

    def _write(self, client: _SocketHandler, data: bytes) -> Any:
        try:
            return client.write_message(data, binary=True)
        except tornado.websocket.WebSocketClosedError:
            self._closed(client)
            return None

    def _broadcast(self, messages: list[bytes]) -> None:
        for box in list(self._clients.values()):
            box.put(messages)

    def _drop_stalled(self) -> None:
        """Disconnect browsers that have not taken a batch for :attr:`stall_seconds`."""
        now = time.monotonic()
        for client, box in list(self._clients.items()):
            if box.stalled(now, self.stall_seconds):
                self._notes.warn(
                    "stalled",
                    f"viewer: a browser read nothing for {self.stall_seconds:g} s; disconnected it",
                )
                self._closed(client)
                stream = getattr(client.ws_connection, "stream", None)
                if stream is not None:
                    stream.close()  # frees tornado's buffer at once; no close handshake to wait on
                else:
                    client.close()

    def held_bytes(self) -> int:
        """Bytes of frames the server holds for its browsers now (bounded per browser)."""
        return sum(box.held_bytes() for box in list(self._clients.values()))

    async def _shutdown(self) -> None:
        # Let the last frames reach the browsers (they keep showing them after we close).
        deadline = time.monotonic() + 2.0
        while time.monotonic() < deadline and any(
            box.pending or box.busy() for box in self._clients.values()
        ):
            await asyncio.sleep(0.02)
        for client in list(self._clients):
            client.close()
        self._listener.close()
        self._http.stop()
        await asyncio.sleep(0.05)
        tornado.ioloop.IOLoop.current().stop()

    # -- window interface (any thread) ----------------------------------------------------
    def send(self, command: Command | dict[str, Any]) -> None:
        """Send a meshcat command to every browser (and to those connecting later)."""
        self.send_encoded(*encode(command), prop=property_of(command))

    def send_encoded(self, kind: str, path: str, data: bytes, prop: str = "") -> None:
        """Send an already-encoded command."""
        self.send_batch([(kind, path, data, prop)])

    def send_batch(self, batch: Sequence[Encoded]) -> None:
        """Send encoded commands (kind, path, data, property) in order; one wake-up of the server thread."""
        if self._closed_flag:
            return
        with self._lock:
            for kind, path, data, prop in batch:
                self.scene.apply(kind, path, data, prop)
        self._ioloop.add_callback(self._broadcast, [item[2] for item in batch])

    @property
    def clients(self) -> int:
        """Number of browsers connected now."""
        with self._lock:
            return len(self._clients)

    def wait_for_client(self, timeout: float | None = None) -> bool:
        """Block until a browser is connected (True) or ``timeout`` seconds pass (False)."""
        return self._connected.wait(timeout)

    def wait(self) -> str:
        """Block until a browser is connected (``meshcat.Visualizer.wait``)."""
        self._connected.wait()
        return "ok"

    def get_scene(self) -> str:
        """The current scene as one self-contained HTML page."""
        with self._lock:
            return self.scene.html()

    def close(self) -> None:
        """Flush the last frames to the browsers, then stop listening (idempotent)."""
        if self._closed_flag:
            return
        self._closed_flag = True
        self._ioloop.add_callback(self._shutdown)
        self._thread.join(timeout=5.0)

    def __enter__(self) -> LocalServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"LocalServer({self.web_url!r}, clients={self.clients})"


@contextlib.contextmanager
def serving(port: int | None = None) -> Iterator[LocalServer]:
    """A :class:`LocalServer` closed on exit."""
    server = LocalServer(port)
    try:
        yield server
    finally:
        server.close()
