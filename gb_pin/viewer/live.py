"""Watching babbling live: :class:`Viewer` streams a run to browsers, :func:`open_viewer` tries to start one.

Importable without meshcat: the server and the scene are loaded when a viewer
starts, after :func:`~gb_pin.viewer.dependencies.require_meshcat`.

>>> import gb_pin
>>> from gb_pin.viewer import Viewer
>>> with Viewer() as viewer:                     # doctest: +SKIP
...     print(viewer.url)                         # http://127.0.0.1:7000/static/
...     gb_pin.babble("planar20", movements=300, viewer=viewer)
"""

from __future__ import annotations

import math
import time
import warnings
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError, ViewerError, ViewerWarning
from gb_pin.viewer.dependencies import require_meshcat
from gb_pin.viewer.replay import replay_animation

if TYPE_CHECKING:
    from gb_pin.learn.history import RecordedSteps
    from gb_pin.learn.state import BabbleState
    from gb_pin.robot.target import KinematicTarget
    from gb_pin.runs.result import BabbleResult
    from gb_pin.viewer.scene import Scene
    from gb_pin.viewer.server import LocalServer


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
        require_meshcat()
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
        self._last_label = -math.inf
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
        if (
            scene.goal_targets is None
            and state.goals.needs_targets
            and not np.array_equal(state.targets, scene.targets)
        ):
            scene.draw_goal_set(state.targets)  # goals from another set than the test set (eval_targets)
            scene.label()
        self._last_frame = now
        scene.pose(state.posture, state.target, state.position)
        self.frames += 1
        if self.overlay and (force_overlay or now - self._last_overlay >= self.overlay_period):
            self._last_overlay = now
            scene.overlay(state.llm.predict(scene.targets, warn=False))
        if force_overlay or now - self._last_label >= self.overlay_period:
            self._last_label = now
            scene.label(_status(state), "" if self.overlay else "the model's overlay is off (overlay=False)")

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
        scene.show_model(result.model.predict(scene.targets, warn=False), few=few)
        from gb_pin.viewer.legend import model_note, result_status

        scene.label(result_status(result), model_note(result))

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


def _status(state: BabbleState) -> str:
    """The legend's status line: movements run, and E^X and D^home at the last evaluation."""
    from gb_pin.viewer.legend import status_line

    done = np.flatnonzero(np.isfinite(state.errors))
    if not done.size:
        return status_line(state.movements, None, None)
    i = int(done[-1])
    return status_line(state.movements, state.errors[i], state.distances[i], int(state.schedule[i]))


def open_viewer(port: int | None = None, **kwargs: Any) -> Viewer | None:
    """A :class:`Viewer`, or None with a :class:`ViewerWarning` if it cannot start (run goes on without)."""
    try:
        return Viewer(port, **kwargs)
    except ViewerError as exc:
        warnings.warn(f"no viewer: {exc}; babbling goes on without it", ViewerWarning, stacklevel=2)
        return None
