"""Meshcat viewer: watch babbling live, replay recorded runs, share them as one offline HTML file.

The only part of gb_pin that imports meshcat (with :mod:`gb_pin.viewer.server`, the
loopback-only server, and :mod:`gb_pin.viewer.scene`, the drawing). It imports
them lazily, so ``import gb_pin.viewer`` works without meshcat and a missing
meshcat is reported as a :class:`ViewerError` naming the extra to install.

>>> import gb_pin
>>> from gb_pin.viewer import Viewer
>>> with Viewer() as viewer:                     # doctest: +SKIP
...     print(viewer.url)                         # http://127.0.0.1:7000/static/
...     gb_pin.babble("planar20", movements=300, viewer=viewer)

What is drawn: the robot (a stick figure of joints and links, or its meshes when it
has a visual model), the target set X*, the current target x*_t, the reached
effector position with a fading trail, and the paper's Fig. 3 overlay (the
reached grid f(g(x*)) and the postures g(x*) of a few targets).
"""

from __future__ import annotations

import math
import os
import time
import warnings
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from gb_pin import _validation as check
from gb_pin.exceptions import GbPinError, InvalidArgumentError, ViewerError, ViewerWarning

if TYPE_CHECKING:
    from gb_pin.learn.history import RecordedSteps
    from gb_pin.learn.state import BabbleState
    from gb_pin.robot.target import KinematicTarget
    from gb_pin.runs.api import BabbleResult
    from gb_pin.viewer.scene import Scene, Window
    from gb_pin.viewer.server import LocalServer

INSTALL_HINT = "install the viewer with: pip install 'gb_pin[viz]'"
OVERLAY_PATH = "/meshcat/gb_pin/overlay"


def _require_meshcat() -> None:
    try:
        with warnings.catch_warnings():
            # meshcat 0.3.2 imports its zmq server, which imports a module pyzmq deprecated.
            warnings.filterwarnings("ignore", category=DeprecationWarning)
            import meshcat  # noqa: F401
        import tornado  # noqa: F401
        import umsgpack  # noqa: F401
    except ImportError as exc:
        raise ViewerError(f"the viewer needs meshcat ({exc}); {INSTALL_HINT}") from exc


def parse_range(text: str, name: str = "movements") -> tuple[int, int | None]:
    """Parse ``"A:B"`` (movements A <= r < B), ``"A:"`` or ``":B"`` into (first, last or None).

    Raises:
        InvalidArgumentError: not of that form, negative, or B <= A.
    """
    parts = text.split(":") if isinstance(text, str) else []
    try:
        if len(parts) != 2:
            raise ValueError
        first = int(parts[0]) if parts[0].strip() else 0
        last = int(parts[1]) if parts[1].strip() else None
    except ValueError:
        raise InvalidArgumentError(
            f"{name} must be a range FIRST:LAST of movement counts (e.g. 0:50, 100:), got {text!r}"
        ) from None
    if first < 0 or (last is not None and last <= first):
        raise InvalidArgumentError(f"{name} range {text!r} must satisfy 0 <= FIRST < LAST")
    return first, last


class Viewer:
    """Live view of goal babbling in a browser; the web server listens on 127.0.0.1 only.

    Pass it to :func:`gb_pin.babble` (``viewer=``): :meth:`start` draws the robot and
    target set, :meth:`update` streams the posture, the current target and the
    reached position. Updates are throttled to ``max_fps`` frames per second (the
    others are dropped at the cost of a clock read), so that learning is slowed only
    a little; ``pace`` deliberately slows learning down to watch it. Call
    :meth:`finish` (or leave a ``with`` block) to draw the last state and the learned
    model; browsers keep showing it after :meth:`close`.

    Args:
        port: TCP port on 127.0.0.1; None: the first free one from 7000.
        max_fps: most frames sent per second.
        pace: if given, babbling waits so that it runs at most ``pace`` movements per
            second (slow motion for watching); None: full speed.
        trail: number of past reached positions drawn (fading).
        overlay: keep the Fig. 3 overlay (reached grid, a few postures) updated.
        overlay_period: seconds between overlay updates.
        visual_model: a ``pin.GeometryModel`` of the target's model to draw meshes
            (default: the target's ``visual_model`` attribute if any, else a stick figure).

    Raises:
        ViewerError: meshcat is missing or the port cannot be bound.
    """

    def __init__(
        self,
        port: int | None = None,
        *,
        max_fps: float = 30.0,
        pace: float | None = None,
        trail: int = 16,
        overlay: bool = True,
        overlay_period: float = 0.5,
        visual_model: Any | None = None,
    ) -> None:
        if port is not None:
            check.positive_int("port", port)
            if port > 65535:
                raise InvalidArgumentError(f"port must be in 1..65535, got {port!r}")
        self.max_fps = check.positive_float("max_fps", max_fps)
        self.pace = None if pace is None else check.positive_float("pace", pace)
        self.trail = check.positive_int("trail", trail, minimum=0)
        self.overlay = bool(overlay)
        self.overlay_period = check.positive_float("overlay_period", overlay_period)
        self.visual_model = visual_model
        _require_meshcat()
        from gb_pin.viewer.server import LocalServer

        try:
            self.server: LocalServer = LocalServer(port)
        except ViewerError:
            raise
        except OSError as exc:
            raise ViewerError(f"the viewer's server cannot start: {exc}") from exc
        self.url: str = self.server.web_url
        self.scene: Scene | None = None
        self.frames = 0
        self.dropped = 0
        self._latest: BabbleState | None = None
        self._reset_clocks()

    def _reset_clocks(self) -> None:
        self._last_frame = -math.inf
        self._last_overlay = -math.inf
        self._t0 = time.perf_counter()
        self._m0: int | None = None

    # -- babble() hooks -------------------------------------------------------------------------
    def start(self, target: KinematicTarget, targets: ArrayLike) -> None:
        """Draw the robot at home, the target set and the markers (called by :func:`gb_pin.babble`)."""
        from gb_pin.viewer.scene import Scene

        self.scene = Scene(self.server, target, targets, trail=self.trail, visual_model=self.visual_model)
        self.scene.draw_static()
        self._latest = None
        self._reset_clocks()

    def update(self, state: BabbleState) -> None:
        """Stream the state of the run, at most ``max_fps`` times per second (called while babbling)."""
        if self.pace is not None:
            if self._m0 is None:
                self._m0, self._t0 = state.movements, time.perf_counter()
            ahead = (state.movements - self._m0) / self.pace - (time.perf_counter() - self._t0)
            if ahead > 0:
                time.sleep(ahead)
        self._latest = state
        now = time.perf_counter()
        if now - self._last_frame < 1.0 / self.max_fps:
            self.dropped += 1
            return
        self._draw(state, now)

    def _draw(self, state: BabbleState, now: float, force_overlay: bool = False) -> None:
        scene = self._scene()
        self._last_frame = now
        scene.pose(state.posture, state.target, state.position)
        self.frames += 1
        if self.overlay and (force_overlay or now - self._last_overlay >= self.overlay_period):
            self._last_overlay = now
            scene.overlay(state.llm.predict(scene.targets))

    def finish(self) -> None:
        """Draw the last state received and the learned model (the Fig. 3 overlay)."""
        if self._latest is not None and self.scene is not None:
            self._draw(self._latest, time.perf_counter(), force_overlay=True)

    # -- other views -----------------------------------------------------------------------------------
    def _scene(self) -> Scene:
        if self.scene is None:
            raise ViewerError("the viewer has no scene yet: call start(target, targets) first")
        return self.scene

    def show_model(self, result: BabbleResult, few: int = 5) -> None:
        """Draw a learned model: robot at g of the target nearest the centre, and the Fig. 3 overlay."""
        if self.scene is None:
            self.start(result.target, result.targets)
        scene = self._scene()
        postures = result.inverse(scene.targets)
        scene.overlay(postures, few=few)
        from gb_pin.viewer.scene import spread_indices

        centre = spread_indices(scene.targets, 1)[0]
        scene.pose(postures[centre], scene.targets[centre], None)

    def play(
        self,
        recording: RecordedSteps,
        path_length: int,
        speed: float = 2.0,
    ) -> None:
        """Replay recorded steps as a looping animation at ``speed`` movements per second."""
        command = replay_animation(self._scene(), recording, path_length, speed)
        self._scene().send_animation(command)

    def wait_for_browser(self, timeout: float | None = None) -> bool:
        """Block until a browser is connected (True) or ``timeout`` seconds pass (False)."""
        return self.server.wait_for_client(timeout)

    @property
    def clients(self) -> int:
        """Browsers connected now."""
        return self.server.clients

    def static_html(self) -> str:
        """The current scene as one self-contained HTML page."""
        return self.server.get_scene()

    def close(self) -> None:
        """Send the last frames, then stop the server (browsers keep showing the scene)."""
        self.server.close()

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc: object) -> None:
        try:
            self.finish()
        finally:
            self.close()

    def __repr__(self) -> str:
        return f"Viewer({self.url!r}, frames={self.frames}, dropped={self.dropped})"


def open_viewer(port: int | None = None, **kwargs: Any) -> Viewer | None:
    """A :class:`Viewer`, or None with a :class:`ViewerWarning` if it cannot start (run goes on without)."""
    try:
        return Viewer(port, **kwargs)
    except ViewerError as exc:
        warnings.warn(f"no viewer: {exc}; babbling goes on without it", ViewerWarning, stacklevel=2)
        return None


def select_movements(recording: RecordedSteps, movements: tuple[int, int | None] | None) -> RecordedSteps:
    """The recorded steps of movements ``first <= r < last``.

    Raises:
        InvalidArgumentError: no recorded step falls in the range.
    """
    from gb_pin.learn.history import RecordedSteps

    if movements is None:
        keep = np.ones(recording.step.shape[0], dtype=bool)
    else:
        first, last = movements
        keep = recording.movement >= first
        if last is not None:
            keep &= recording.movement < last
    if not np.any(keep):
        have = (
            f"{int(recording.movement.min())}..{int(recording.movement.max())}"
            if recording.movement.size
            else "none"
        )
        raise InvalidArgumentError(f"no recorded step in movements {movements!r}; recorded movements: {have}")
    return RecordedSteps(
        step=recording.step[keep],
        movement=recording.movement[keep],
        posture=recording.posture[keep],
        target=recording.target[keep],
        position=recording.position[keep],
    )


def replay_animation(
    scene: Scene, recording: RecordedSteps, path_length: int, speed: float
) -> dict[str, Any]:
    """The ``set_animation`` command replaying ``recording`` at ``speed`` movements per second."""
    speed = check.positive_float("speed", speed)
    if recording.step.shape[0] < 1:
        raise InvalidArgumentError("the recording holds no step")
    steps_per_second = speed * path_length
    times = (recording.step - recording.step[0]).astype(float)
    every = float(np.median(np.diff(recording.step))) if recording.step.shape[0] > 1 else 1.0
    # The trail spans about one movement (path_length steps).
    stride = max(1, round(path_length / (every * max(scene.trail, 1))))
    return scene.animation(
        recording.posture, recording.target, recording.position, times, steps_per_second, trail_stride=stride
    )


def _recording_of(result: BabbleResult) -> RecordedSteps:
    if result.recording is None or result.recording.step.shape[0] == 0:
        raise InvalidArgumentError(
            "this result has no recorded steps; record them with babble(record=gb_pin.Recording(...)) "
            "or gb-pin babble --record-every 1 --record-movements 0:50"
        )
    return result.recording


def replay_window(
    window: Window,
    result: BabbleResult,
    movements: tuple[int, int | None] | None = None,
    speed: float = 2.0,
    trail: int = 16,
    visual_model: Any | None = None,
) -> Scene:
    """Draw a recorded run into ``window`` as a looping animation; returns the scene."""
    from gb_pin.viewer.scene import Scene

    recording = select_movements(_recording_of(result), movements)
    scene = Scene(window, result.target, result.targets, trail=trail, visual_model=visual_model)
    scene.draw_static()
    # The final model's overlay would contradict the early movements replayed: drawn, but hidden
    # (meshcat's scene panel shows it on demand).
    scene.overlay(result.inverse(scene.targets))
    scene.hide(OVERLAY_PATH)
    command = replay_animation(scene, recording, result.config.path_length, speed)
    scene.send_animation(command)
    return scene


def _write(path: str | os.PathLike[str], html: str) -> None:
    path = os.fspath(path)
    tmp = path + ".tmp"
    try:
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(html)
        os.replace(tmp, path)
    except OSError as exc:
        raise InvalidArgumentError(f"cannot write {path!r}: {exc.strerror or exc}") from exc


def export_replay(
    result: BabbleResult,
    path: str | os.PathLike[str],
    movements: tuple[int, int | None] | None = None,
    speed: float = 2.0,
    visual_model: Any | None = None,
) -> None:
    """Write one self-contained HTML file that replays the recorded steps of ``result`` offline.

    The animation loops at ``speed`` movements per second (meshcat's animation panel
    pauses, scrubs and changes speed); the learned model's Fig. 3 overlay is drawn too.

    Args:
        result: a result with a recording (``babble(record=...)``).
        path: the ``.html`` file to write.
        movements: (first, last) movements to replay; None for all recorded.
        speed: movements per second.
        visual_model: optional ``pin.GeometryModel`` to draw meshes.

    Raises:
        InvalidArgumentError: no recording, empty range, bad speed, unwritable path.
        ViewerError: meshcat is missing.
    """
    _require_meshcat()
    from gb_pin.viewer.server import OfflineWindow

    window = OfflineWindow()
    replay_window(window, result, movements, speed, visual_model=visual_model)
    _write(path, window.scene.html(title=f"gb_pin replay: {result.target.name}"))


def export_model(
    result: BabbleResult, path: str | os.PathLike[str], few: int = 5, visual_model: Any | None = None
) -> None:
    """Write one self-contained HTML file showing the learned model (the paper's Fig. 3 overlay).

    Raises:
        InvalidArgumentError: unwritable path.
        ViewerError: meshcat is missing.
    """
    _require_meshcat()
    from gb_pin.viewer.scene import Scene, spread_indices
    from gb_pin.viewer.server import OfflineWindow

    window = OfflineWindow()
    scene = Scene(window, result.target, result.targets, trail=0, visual_model=visual_model)
    scene.draw_static()
    postures = result.inverse(scene.targets)
    scene.overlay(postures, few=few)
    centre = spread_indices(scene.targets, 1)[0]
    scene.pose(postures[centre], scene.targets[centre], None)
    _write(path, window.scene.html(title=f"gb_pin model: {result.target.name}"))


def live_replay(
    result: BabbleResult,
    movements: tuple[int, int | None] | None = None,
    speed: float = 2.0,
    port: int | None = None,
) -> Viewer:
    """A live :class:`Viewer` replaying the recorded steps of ``result``, looping; close it when done.

    Browsers get meshcat's animation panel to pause, scrub and change the speed.
    """
    # Bad input fails before the server starts.
    recording = select_movements(_recording_of(result), movements)
    speed = check.positive_float("speed", speed)
    viewer = Viewer(port, overlay=False)
    try:
        viewer.start(result.target, result.targets)
        scene = viewer._scene()
        scene.overlay(result.inverse(scene.targets))
        scene.hide(OVERLAY_PATH)
        viewer.play(recording, result.config.path_length, speed)
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
    """Keep ``viewer`` serving until Ctrl-C (or ``seconds``), then close it."""
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
