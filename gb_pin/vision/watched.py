"""WatchedRobot: a robot that moves, watched by a camera: the learner's task is the camera's frame.

>>> plant = MujocoPlant("so101", kp=10, camera="side")                            # doctest: +SKIP
>>> tracker = ArucoTracker(plant.camera.intrinsics(), 0.025)                       # doctest: +SKIP
>>> robot = WatchedRobot(plant, CameraSensor(plant, tracker))                      # doctest: +SKIP
>>> robot.targets = robot.teach_box(corner_postures)     # goals shown, not typed  # doctest: +SKIP
>>> result = gb_pin.babble(robot, movements=3000)                                 # doctest: +SKIP

Goal babbling does not care in which frame its readings are, as long as goals and readings share
it: so a robot can learn to reach in the camera's own frame, with no model of the arm (its
URDF, its servos' sag) and none of the camera (no hand-eye calibration). The robot is anything
that moves to a posture: a rendering :class:`~gb_pin.sim.plant.MujocoPlant` (its ``move``), or a
real arm's driver (its ``move`` or ``forward``, issue 31's bus); every ask moves it and reads
the sensor, a lost marker being ``None`` (``tell(None)``: nothing learnt, never a wrong pair).

Before anything else the robot is moved home and the marker must be seen there, else one
:class:`~gb_pin.exceptions.CameraError` line says so. E^X: a plant that knows where its marker
truly is (``true_marker``) gives it, projected like the tracker's readings; a real arm gives none
(``evaluate="movements"`` in a session measures it through the camera).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import CameraError, InvalidArgumentError
from gb_pin.robot.function import FunctionTarget
from gb_pin.vision.sensor import CameraSensor
from gb_pin.vision.taught import goal_box, teach


class WatchedRobot(FunctionTarget):
    """A robot moved by ``move(q)`` (or ``forward(q)``) whose hand a :class:`CameraSensor` reads.

    Args:
        robot: home, ``lower``, ``upper`` and ``move(q)`` or ``forward(q)`` (which moves it).
        sensor: the :class:`~gb_pin.vision.sensor.CameraSensor`.
        targets: the goal set in the sensor's frame and units (N, n); None: set it later
            (:meth:`teach_box`).
        home_tries: pictures read at home before giving up.
        name: a label.

    Attributes:
        preset: the robot's preset (its learner settings: radius, learning rate) where it has one.
        home_reading: the sensor's reading at home.

    Raises:
        CameraError: the marker was never seen at home (nothing else moved).
    """

    def __init__(
        self,
        robot: Any,
        sensor: CameraSensor,
        targets: ArrayLike | None = None,
        *,
        home_tries: int = 10,
        name: str | None = None,
    ) -> None:
        if not isinstance(sensor, CameraSensor):
            raise CameraError(f"sensor must be a gb_pin.vision.CameraSensor, got {sensor!r:.80}")
        self.robot, self.camera_sensor = robot, sensor
        move = getattr(robot, "move", None) or getattr(robot, "forward", None)
        if not callable(move):
            raise CameraError(f"a watched robot needs move(q) or forward(q), got {robot!r:.80}")
        self._move: Callable[[Any], Any] = move
        home = np.asarray(robot.home, dtype=np.float64)
        self._move(home)
        reading = None
        for _ in range(check.positive_int("home_tries", home_tries, 1, 10_000)):
            reading = sensor.read()
            if reading is not None:
                break
        if reading is None:
            raise CameraError(
                f"the marker was not seen at home in {home_tries} pictures ({sensor.tracker!r}): is it in "
                "view, lit, and the id and dictionary right? Nothing was learnt."
            )
        self.home_reading = reading
        self._true = getattr(robot, "true_marker", None)
        first: Callable[[Any], Any] = self._true_reading if self._true is not None else (lambda q: reading)
        label = name or f"{getattr(robot, 'name', 'robot')} seen by a camera"
        super().__init__(first, home, lower=robot.lower, upper=robot.upper, targets=targets, name=label)
        if self._true is not None:
            self.true_forward = self._true_reading
        self.preset = getattr(robot, "preset", None)
        self.axes = None
        self.units, self.scale = sensor.units, sensor.scale

    def _true_reading(self, q: ArrayLike) -> NDArray[np.float64]:
        """The plant's true marker point in the tracker's frame and units: (m,) -> (n,), (N, m) -> (N, n)."""
        assert self._true is not None
        X = np.asarray(self._true(q), dtype=np.float64)
        tracker = self.camera_sensor.tracker
        if getattr(tracker, "mode", "xyz") != "uv":
            return X
        K = tracker.intrinsics  # type: ignore[attr-defined]
        Y = np.atleast_2d(X)
        uv = np.column_stack([K.fx * Y[:, 0] / Y[:, 2], K.fy * Y[:, 1] / Y[:, 2]]) * tracker.scale
        return uv[0] if X.ndim == 1 else uv

    def forward(self, q: ArrayLike) -> NDArray[np.float64] | None:  # type: ignore[override]
        """One ask: move to ``q`` (m,), read the camera: the reading (n,), or None when the marker is lost.

        (N, m) postures give (N, n) readings (NaN rows where lost).
        """
        if np.ndim(q) == 2:
            rows = [self.forward(row) for row in check.points("q", q, self.n_joints)]
            return np.array([np.full(self.n_task, np.nan) if r is None else r for r in rows])
        self._move(check.vector("q", q, self.n_joints))
        return self.camera_sensor.read()

    def robot_state(self) -> dict[str, NDArray[Any]]:
        """The watched robot's own state (a simulated plant's, its camera's included), the sensor's counts.

        Saved in session checkpoints, so that a resumed run continues with the pictures it would
        have taken; a real arm has no state of its own (only the counts are kept).
        """
        save = getattr(self.robot, "robot_state", None)
        out = {} if save is None else {f"robot.{k}": np.asarray(v) for k, v in save().items()}
        out["sensor_counts"] = np.array([self.camera_sensor.reads, self.camera_sensor.lost], dtype=np.int64)
        return out

    def set_robot_state(self, arrays: dict[str, NDArray[Any]]) -> None:
        """Continue from :meth:`robot_state`'s arrays (a checkpoint's).

        Raises:
            InvalidArgumentError: the arrays do not fit this robot (another robot's, or malformed).
        """
        counts = np.asarray(arrays.get("sensor_counts", np.zeros(0)))
        if counts.dtype != np.int64 or counts.shape != (2,) or np.any(counts < 0) or counts[1] > counts[0]:
            raise InvalidArgumentError(
                f"a watched robot's sensor_counts must be two counts, got {counts!r:.80}"
            )
        own = {k[len("robot.") :]: v for k, v in arrays.items() if k.startswith("robot.")}
        unknown = sorted(set(arrays) - {"sensor_counts"} - {f"robot.{k}" for k in own})
        restore = getattr(self.robot, "set_robot_state", None)
        if unknown or (own and restore is None) or (restore is not None and not own):
            raise InvalidArgumentError(
                f"the checkpoint's robot state ({sorted(arrays)}) was not written by a robot like "
                f"{self.robot!r:.80}"
            )
        if restore is not None:
            restore(own)
        self.camera_sensor.reads, self.camera_sensor.lost = int(counts[0]), int(counts[1])

    def observe(self, q: ArrayLike) -> NDArray[np.float64] | None:
        """``forward``, named for ``result.reach(targets, robot.observe)``."""
        return self.forward(q)

    def teach(self, q: ArrayLike, readings: int = 10) -> NDArray[np.float64]:
        """Hold the arm at ``q`` and average ``readings`` readings (a place shown to the camera).

        Raises:
            InvalidArgumentError: the marker was seen too rarely there.
        """
        self._move(check.vector("q", q, self.n_joints))
        return teach(self.camera_sensor.read, readings)

    def teach_all(self, postures: ArrayLike, readings: int = 10) -> NDArray[np.float64]:
        """:meth:`teach` at each of (N, m) postures: (N, n) taught targets."""
        return np.array([self.teach(q, readings) for q in check.points("postures", postures, self.n_joints)])

    def teach_box(self, corners: ArrayLike, per_axis: int = 4, readings: int = 10) -> NDArray[np.float64]:
        """A goal grid over places the arm is held at: 2 or 8 corner postures (x fastest; goal_box)."""
        return goal_box(self.teach_all(corners, readings), per_axis)

    def __repr__(self) -> str:
        return f"WatchedRobot({self.name!r}, {self.camera_sensor!r})"
