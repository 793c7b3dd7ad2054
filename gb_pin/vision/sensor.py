"""CameraSensor: a camera and a tracker, read as the learner's sensor: ``read() -> x | None``.

>>> sensor = CameraSensor(VideoCamera(0), ArucoTracker(Intrinsics.load("cam.yaml"), 0.025))  # doctest: +SKIP
>>> session.tell(sensor.read())                                      # doctest: +SKIP
>>> result.reach(targets, sensor.observer(arm.move_to))              # doctest: +SKIP

Anything with ``read() -> (H, W, 3) uint8`` is a camera: a :class:`~gb_pin.vision.camera.VideoCamera`,
or a rendering plant (:class:`gb_pin.sim.MujocoPlant` with ``camera=``, whose ``read`` renders).
A picture where the tracker is not sure gives None: ``tell(None)`` teaches nothing.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.vision.tracker import Tracker


class CameraSensor:
    """A camera and a tracker.

    Args:
        camera: an object with ``read() -> picture``.
        tracker: a :class:`~gb_pin.vision.tracker.Tracker` (e.g. an ArucoTracker).

    Attributes:
        reads, lost: pictures read, and those in which the tracker saw nothing for sure.
    """

    def __init__(self, camera: Any, tracker: Tracker) -> None:
        if not callable(getattr(camera, "read", None)):
            raise InvalidArgumentError(
                f"a camera needs a read() method returning a picture, got {camera!r:.80}"
            )
        if not isinstance(tracker, Tracker):
            raise InvalidArgumentError(f"tracker must be a gb_pin.vision.Tracker, got {tracker!r:.80}")
        self.camera, self.tracker = camera, tracker
        self.n_task, self.units, self.scale = tracker.n_task, tracker.units, tracker.scale
        self.reads = 0
        self.lost = 0

    def read(self) -> NDArray[np.float64] | None:
        """The tracker's reading of a fresh picture (n,), or None when the marker is not seen."""
        x = self.tracker(self.camera.read())
        self.reads += 1
        if x is None:
            self.lost += 1
        return x

    def observer(self, move: Callable[[NDArray[np.float64]], Any]) -> Callable[[ArrayLike], Any]:
        """``observe(q)`` for :meth:`BabbleResult.reach`: ``move(q)`` (to rest), then :meth:`read`."""

        def observe(q: ArrayLike) -> NDArray[np.float64] | None:
            move(np.asarray(q, dtype=np.float64))
            return self.read()

        return observe

    def __repr__(self) -> str:
        return f"CameraSensor({self.camera!r}, {self.tracker!r})"
