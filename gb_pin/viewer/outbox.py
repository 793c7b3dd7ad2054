"""One browser's bounded send queue: :class:`Outbox` (a slow browser cannot make the server grow).

Before it, every frame was written to every websocket at once: tornado kept what a browser did
not read in its write buffer, so a browser that stopped reading (a suspended tab) made the
server grow without bound (one such tab: +150 MB in 90 s; thirty: +537 MB in 60 s). Now each
browser has an :class:`Outbox` that the server thread fills and drains:

- at most :data:`BATCH_BYTES` (and at least one message) are handed to tornado at a time; the
  next batch is written only when that one has reached the kernel;
- frames that wait beyond :data:`QUEUE_BYTES` are dropped and replaced by the scene itself
  (:meth:`SceneCache.messages`): when the browser reads again it gets the current scene once,
  not every frame it missed (frames are coalesced, the queue holds references to the scene
  cache's bytes, shared by every browser);
- a browser whose batch has not reached the kernel for :data:`STALL_SECONDS` is disconnected
  (its stream aborted: tornado's buffer is freed at once, nothing waits on a close handshake).

A browser that reads keeps getting every frame in order; the others never slow it down.
"""

from __future__ import annotations

import collections
import time
from collections.abc import Callable
from typing import Any

BATCH_BYTES = 256 * 2**10
"""Bytes handed to tornado for one browser at a time (at least one message)."""
QUEUE_BYTES = 2**20
"""Bytes of frames waiting for one browser before they are dropped for a resend of the scene."""
STALL_SECONDS = 30.0
"""A browser that has not taken a batch for this long is disconnected [s]."""


class Outbox:
    """The messages waiting for one browser, bounded in bytes; run in the server's thread only.

    Args:
        write: writes one message to the browser, returning tornado's write future.
        scene: returns the messages that rebuild the current scene (sent after a drop).
        queue_bytes: bytes queued before frames are dropped for the scene.
        batch_bytes: bytes written to tornado at a time.
    """

    def __init__(
        self,
        write: Callable[[bytes], Any],
        scene: Callable[[], list[bytes]],
        queue_bytes: int = QUEUE_BYTES,
        batch_bytes: int = BATCH_BYTES,
    ) -> None:
        self._write = write
        self._scene = scene
        self.queue_bytes = queue_bytes
        self.batch_bytes = batch_bytes
        self.pending: collections.deque[bytes] = collections.deque()
        self.pending_bytes = 0
        self.in_flight: Any = None  # the write future of the last batch handed to tornado
        self.in_flight_bytes = 0
        self.since = time.monotonic()  # when the last batch was handed over (or taken)
        self.resync = False  # frames were dropped: send the scene when the browser reads again
        self.dropped = 0
        self.closed = False

    def put(self, messages: list[bytes]) -> None:
        """Queue ``messages`` (or drop them when the queue is full), then write what may be written."""
        if self.closed:
            return
        if not self.resync:
            self.pending.extend(messages)
            self.pending_bytes += sum(len(m) for m in messages)
            if self.pending_bytes > self.queue_bytes and self.busy():
                self.dropped += len(self.pending)
                self.pending.clear()
                self.pending_bytes = 0
                self.resync = True
        else:
            self.dropped += len(messages)
        self.pump()

    def busy(self) -> bool:
        """Whether the last batch has not reached the kernel yet."""
        return self.in_flight is not None and not self.in_flight.done()

    def stalled(self, now: float, seconds: float) -> bool:
        """Whether a batch has waited more than ``seconds`` to reach the kernel."""
        return self.busy() and now - self.since > seconds

    def pump(self) -> None:
        """Hand the next batch to tornado if the last one has reached the kernel."""
        while not self.closed and not self.busy():
            self.in_flight = None
            self.in_flight_bytes = 0
            if self.resync:
                self.resync = False
                self.pending = collections.deque(self._scene())
                self.pending_bytes = sum(len(m) for m in self.pending)
            if not self.pending:
                return
            sent = 0
            future = None
            while self.pending and (sent == 0 or sent + len(self.pending[0]) <= self.batch_bytes):
                data = self.pending.popleft()
                self.pending_bytes -= len(data)
                sent += len(data)
                future = self._write(data)
                if self.closed:
                    return
                if future is not None:
                    future.add_done_callback(_retrieve)
            self.in_flight = future
            self.in_flight_bytes = sent
            self.since = time.monotonic()
            if future is not None and not future.done():
                future.add_done_callback(self._taken)

    def _taken(self, future: Any) -> None:
        self.since = time.monotonic()
        self.pump()

    def held_bytes(self) -> int:
        """Bytes this browser holds in the server: queued plus handed to tornado and not yet sent."""
        return self.pending_bytes + (self.in_flight_bytes if self.busy() else 0)

    def close(self) -> None:
        """Forget everything queued (the browser is gone)."""
        self.closed = True
        self.pending.clear()
        self.pending_bytes = 0
        self.in_flight = None
        self.in_flight_bytes = 0


def _retrieve(future: Any) -> None:
    """Mark a write's error as seen: a closed browser is handled by the server's ``on_close``."""
    if not future.cancelled():
        future.exception()
