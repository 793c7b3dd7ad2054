"""What a camera tracker is: a picture in, the task vector out, or None when the marker is not seen.

A :class:`Tracker` turns one picture (an (H, W) or (H, W, 3) uint8 array, OpenCV's BGR order)
into the learner's reading x (n,) in the camera's own frame, or None. None is the only answer a
tracker gives when it is not sure (the marker is occluded, out of view, another marker is seen):
a wrong reading would teach the learner a wrong posture-to-position pair, a missing one teaches
nothing (``session.tell(None)``). Goal babbling needs no extrinsics: goals and readings share
the camera's frame.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np
from numpy.typing import NDArray


class Tracker(ABC):
    """A picture -> the task vector (n,) in the camera frame, or None.

    Attributes:
        n_task: the task dimension n of the readings (3 for a position, 2 for a pixel).
        units: the readings' units, for messages (``"m"``, ``"px"``).
        scale: metres per unit of a reading near the work volume (1 for metres; for pixels the
            depth over the focal length): what Eq. 5's distances and the radius are measured in.
    """

    n_task: int
    units: str
    scale: float = 1.0

    @abstractmethod
    def __call__(self, image: NDArray[np.uint8]) -> NDArray[np.float64] | None:
        """The reading (n,) of ``image``, or None when the marker is not seen for sure."""
