"""Sharing a run as one self-contained HTML file: its replay, or its learned model, viewable offline.

The file inlines meshcat's viewer and the scene (:mod:`gb_pin.viewer.page`: no network,
a Content-Security-Policy forbids every fetch) and is written atomically
(:func:`gb_pin._files.write_text`).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

from gb_pin._files import write_text
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.viewer.dependencies import require_meshcat
from gb_pin.viewer.legend import model_note, result_status
from gb_pin.viewer.replay import replay_window

if TYPE_CHECKING:
    from gb_pin.runs.result import BabbleResult
    from gb_pin.viewer.ranges import Movements


def write_html(path: str | os.PathLike[str], html: str) -> None:
    """Write ``html`` to ``path`` atomically.

    Raises:
        InvalidArgumentError: the file cannot be written (the message names it).
    """
    try:
        write_text(path, html)
    except OSError as exc:
        raise InvalidArgumentError(f"cannot write {os.fspath(path)!r}: {exc.strerror or exc}") from exc


def export_replay(
    result: BabbleResult,
    path: str | os.PathLike[str],
    movements: Movements | None = None,
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
    require_meshcat()
    from gb_pin.viewer.cache import OfflineWindow

    window = OfflineWindow()
    replay_window(window, result, movements, speed, visual_model=visual_model)  # labels the scene
    write_html(path, window.scene.html(title=f"gb_pin replay: {result.target.name}"))


def export_model(
    result: BabbleResult, path: str | os.PathLike[str], few: int = 5, visual_model: Any | None = None
) -> None:
    """Write one self-contained HTML file showing the learned model (the paper's Fig. 3 overlay).

    Raises:
        InvalidArgumentError: unwritable path.
        ViewerError: meshcat is missing.
    """
    require_meshcat()
    from gb_pin.viewer.cache import OfflineWindow
    from gb_pin.viewer.scene import Scene

    window = OfflineWindow()
    scene = Scene(
        window,
        result.target,
        result.targets,
        trail=0,
        visual_model=visual_model,
        goal_targets=result.goal_targets,
    )
    scene.draw_static()
    scene.show_model(result.model.predict(scene.targets, warn=False), few=few)
    scene.label(result_status(result), model_note(result))
    write_html(path, window.scene.html(title=f"gb_pin model: {result.target.name}"))
