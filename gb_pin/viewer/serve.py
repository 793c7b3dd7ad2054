"""Showing a finished run live: its replay or its learned model served to browsers until Ctrl-C."""

from __future__ import annotations

import signal
import threading
import time
from typing import TYPE_CHECKING

from gb_pin import _validation as check
from gb_pin.viewer.live import Viewer
from gb_pin.viewer.ranges import Movements, recorded_steps
from gb_pin.viewer.replay import draw_replay

if TYPE_CHECKING:
    from gb_pin.runs.result import BabbleResult


def live_replay(
    result: BabbleResult,
    movements: Movements | None = None,
    speed: float = 2.0,
    port: int | None = None,
) -> Viewer:
    """A live :class:`Viewer` replaying the recorded steps of ``result``, looping; close it when done.

    Browsers get meshcat's animation panel to pause, scrub and change the speed.

    Raises:
        InvalidArgumentError: no recording, an empty range or a bad speed (before the server starts).
        ViewerError: meshcat is missing or the port cannot be bound.
    """
    # Bad input fails before the server starts.
    recording = recorded_steps(result, movements)
    speed = check.positive_float("speed", speed)
    viewer = Viewer(port, overlay=False)
    try:
        viewer.start(result.target, result.targets)
        draw_replay(viewer._scene(), result, recording, speed)
    except BaseException:
        viewer.close()
        raise
    return viewer


def live_model(result: BabbleResult, port: int | None = None, few: int = 5) -> Viewer:
    """A live :class:`Viewer` showing the learned model of ``result`` (Fig. 3 overlay); close it when done."""
    viewer = Viewer(port, overlay=False)
    try:
        viewer.show_model(result, few=few)
    except BaseException:
        viewer.close()
        raise
    return viewer


def serve_until_interrupted(viewer: Viewer, seconds: float | None = None) -> None:
    """Keep ``viewer`` serving until Ctrl-C (or ``seconds``), then close it.

    Ctrl-C works even where SIGINT was ignored when the process started (a job started with ``&``
    inherits SIGINT ignored, and Python then keeps it so: such a server could only be killed), and
    SIGTERM closes the server the same way.
    """
    restore = []
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            restore.append((sig, signal.signal(sig, signal.default_int_handler)))
    try:
        if seconds is None:
            while True:
                time.sleep(3600.0)
        else:
            time.sleep(seconds)
    except KeyboardInterrupt:
        pass
    finally:
        viewer.close()
        for sig, handler in restore:
            signal.signal(sig, handler)
