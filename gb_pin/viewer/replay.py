"""Replaying a recorded run: its recorded steps as a looping animation of the scene.

The learned model's Fig. 3 overlay is drawn too, but hidden: the final model would
contradict the early movements replayed (meshcat's scene panel shows it on demand).
Importable without meshcat (the scene is loaded by :func:`replay_window`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.viewer.legend import result_status
from gb_pin.viewer.ranges import Movements, recorded_steps
from gb_pin.viewer.style import OVERLAY

if TYPE_CHECKING:
    from gb_pin.learn.history import RecordedSteps
    from gb_pin.runs.result import BabbleResult
    from gb_pin.viewer.commands import Window
    from gb_pin.viewer.scene import Scene


def replay_animation(
    scene: Scene, recording: RecordedSteps, path_length: int, speed: float
) -> dict[str, Any]:
    """The ``set_animation`` command replaying ``recording`` at ``speed`` movements per second.

    Raises:
        InvalidArgumentError: a speed that is not positive, or no recorded step.
    """
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


def draw_replay(scene: Scene, result: BabbleResult, recording: RecordedSteps, speed: float) -> None:
    """Into a drawn ``scene``: the hidden overlay of ``result``'s model and the animation of ``recording``."""
    scene.overlay(result.model.predict(scene.targets, warn=False))
    scene.hide(OVERLAY)
    scene.send_animation(replay_animation(scene, recording, result.config.path_length, speed))
    first, last = int(recording.movement[0]), int(recording.movement[-1])
    scene.label(
        f"replaying movements {first}-{last} ({speed:g}/s); at the end: {result_status(result)}",
        "The final model (blue, dark lines) is hidden in a replay, where it would contradict the early "
        "movements: Open Controls > Scene > meshcat > gb_pin > overlay shows it.",
    )


def replay_window(
    window: Window,
    result: BabbleResult,
    movements: Movements | None = None,
    speed: float = 2.0,
    trail: int = 16,
    visual_model: Any | None = None,
) -> Scene:
    """Draw a recorded run into ``window`` as a looping animation; returns the scene.

    Raises:
        InvalidArgumentError: no recording, an empty range or a bad speed.
    """
    from gb_pin.viewer.scene import Scene  # the drawing loads meshcat

    recording = recorded_steps(result, movements)
    scene = Scene(
        window, result.target, result.targets, trail=trail, visual_model=visual_model,
        goal_targets=result.goal_targets,
    )  # fmt: skip
    scene.draw_static()
    draw_replay(scene, result, recording, speed)
    return scene
