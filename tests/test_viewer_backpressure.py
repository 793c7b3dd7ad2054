"""The viewer under browsers that stop reading: bounded memory, the others served (real sockets, 127.0.0.1).

Raw websocket clients on loopback: stalled ones complete the handshake and never read (a
suspended tab); a reading one parses every frame. Before the bounded per-browser queue
(:mod:`gb_pin.viewer.outbox`) every frame was queued for every browser: thirty stalled tabs
grew the server by +537 MB in 60 s.
"""

from __future__ import annotations

import http.client
import socket
import threading
import time
from typing import Any

import pytest

pytest.importorskip("meshcat")
psutil = pytest.importorskip("psutil")

from gb_pin.viewer.outbox import BATCH_BYTES, QUEUE_BYTES, Outbox  # noqa: E402
from gb_pin.viewer.server import LOOPBACK, LocalServer  # noqa: E402

FRAME = 64 * 2**10


def _handshake(port: int, rcvbuf: int | None = None) -> socket.socket:
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    if rcvbuf is not None:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
    sock.settimeout(5)
    sock.connect((LOOPBACK, port))
    sock.sendall(
        (
            f"GET / HTTP/1.1\r\nHost: {LOOPBACK}:{port}\r\nUpgrade: websocket\r\n"
            "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
            "Sec-WebSocket-Version: 13\r\n\r\n"
        ).encode()
    )
    head = b""
    while b"\r\n\r\n" not in head:
        chunk = sock.recv(1)
        assert chunk, "the server closed the handshake"
        head += chunk
    assert head.startswith(b"HTTP/1.1 101"), head[:80]
    return sock


class _Reader(threading.Thread):
    """Reads websocket frames (unmasked, from the server) and keeps the last frame number seen."""

    def __init__(self, sock: socket.socket) -> None:
        super().__init__(daemon=True)
        self.sock = sock
        self.last = -1
        self.count = 0
        self.stop = False

    def _exact(self, n: int) -> bytes:
        out = bytearray()
        while len(out) < n:
            chunk = self.sock.recv(n - len(out))
            if not chunk:
                raise ConnectionError
            out += chunk
        return bytes(out)

    def run(self) -> None:
        self.sock.settimeout(0.5)
        while not self.stop:
            try:
                _, b1 = self._exact(2)
                n = b1 & 0x7F
                if n == 126:
                    n = int.from_bytes(self._exact(2), "big")
                elif n == 127:
                    n = int.from_bytes(self._exact(8), "big")
                payload = self._exact(n)
            except TimeoutError:
                continue
            except (ConnectionError, OSError):
                return
            self.count += 1
            if payload[:1] == b"F":
                self.last = int.from_bytes(payload[1:5], "big")


def _frame(i: int) -> bytes:
    return b"F" + i.to_bytes(4, "big") + bytes(FRAME)


def _static_answers(port: int) -> bool:
    conn = http.client.HTTPConnection(LOOPBACK, port, timeout=5)
    conn.request("GET", "/static/", headers={"Host": f"{LOOPBACK}:{port}"})
    ok = conn.getresponse().status == 200
    conn.close()
    return ok


def test_thirty_stalled_browsers_keep_memory_bounded_and_a_reader_served() -> None:
    """30 tabs that never read: bounded queues, < 50 MB, a reading tab served, stalled tabs closed.

    The server holds at most a bounded queue per tab, grows by less than 50 MB, keeps serving a
    reading tab up to the last frame, answers handshakes and pages, and disconnects the stalled
    tabs after ``stall_seconds``.
    """
    process = psutil.Process()
    with LocalServer() as server:
        server.stall_seconds = 1.5
        stalled = [_handshake(server.port, rcvbuf=4096) for _ in range(30)]
        reader = _Reader(_handshake(server.port))
        reader.start()
        deadline = time.monotonic() + 5
        while server.clients < 31 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert server.clients == 31
        before = process.memory_info().rss
        frames = 400  # 25 MB a browser: 750 MB held if every frame were queued for every browser
        bound = 31 * (QUEUE_BYTES + BATCH_BYTES + 2 * FRAME)
        held = 0
        for i in range(frames):
            server.send_encoded("set_transform", "/frame", _frame(i))
            time.sleep(0.004)  # 250 frames a second
            if i % 20 == 0:
                held = max(held, server.held_bytes())
        time.sleep(0.3)
        grown = process.memory_info().rss - before
        assert held <= bound, f"{held} bytes held for the browsers, bound {bound}"
        assert grown < 50 * 2**20, f"the server grew by {grown / 2**20:.0f} MB under 30 stalled tabs"
        deadline = time.monotonic() + 5
        while reader.last != frames - 1 and time.monotonic() < deadline:
            time.sleep(0.02)
        assert reader.last == frames - 1, "the reading tab did not get the last frame"
        # It may miss frames only when it falls more than a queue behind (a loaded machine).
        assert reader.count >= frames // 2, f"the reading tab got {reader.count} of {frames} frames"
        late = _handshake(server.port)  # handshakes and pages still answered
        assert _static_answers(server.port)
        late.close()
        deadline = time.monotonic() + 6
        while server.clients > 1 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert server.clients == 1, "stalled tabs were not disconnected"
        server.send_encoded("set_transform", "/frame", _frame(frames))
        deadline = time.monotonic() + 3
        while reader.last != frames and time.monotonic() < deadline:
            time.sleep(0.02)
        assert reader.last == frames
        reader.stop = True
        for s in stalled:
            s.close()


class _Future:
    def __init__(self) -> None:
        self.flag = False
        self.callbacks: list[Any] = []

    def done(self) -> bool:
        return self.flag

    def cancelled(self) -> bool:
        return False

    def exception(self) -> None:
        return None

    def add_done_callback(self, fn: Any) -> None:
        self.callbacks.append(fn)

    def finish(self) -> None:
        self.flag = True
        for fn in self.callbacks:
            fn(self)


def test_an_outbox_coalesces_missed_frames_into_the_scene() -> None:
    """Frames beyond the queue's bytes are dropped; the next batch after the browser reads is the scene."""
    written: list[bytes] = []
    futures: list[_Future] = []

    def write(data: bytes) -> _Future:
        written.append(data)
        futures.append(_Future())
        return futures[-1]

    box = Outbox(write, lambda: [b"scene"], queue_bytes=100, batch_bytes=10)
    box.put([b"a" * 10])
    assert written == [b"a" * 10] and box.busy()
    for _ in range(20):
        box.put([b"b" * 10])  # the browser does not read: queued up to 100 bytes, then dropped
    assert box.resync and box.pending_bytes == 0 and box.dropped > 0
    assert box.held_bytes() <= 100 + 10
    futures[-1].finish()  # the browser reads again: it gets the scene, not the missed frames
    assert written[-1] == b"scene"
    assert box.stalled(time.monotonic() + 100, 30.0)
