"""``--sensor aruco:...``: learn in a camera's own frame from an ArUco marker (docs/CAMERA.md).

``gb-pin babble --robot so101 --plant mujoco:kp=10,camera=side --sensor aruco:size=0.025`` renders
the simulated arm and tracks the marker on its hand; on a real arm the robot is the arm's driver
(``--plant`` of the real-arm issue) and ``camera=0`` (a device index or a video path) with
``calib=cam.yaml`` (OpenCV's calibration file; else the intrinsics are guessed from ``fov=``).

Keys: ``size`` [m] (the marker's black square), ``id`` (the marker's id; default: the only marker
seen), ``dict`` (OpenCV's dictionary), ``refine`` (apriltag, subpix, none), ``mode`` (xyz: metres
in the camera frame; uv: pixels, scaled by depth / focal at home so that the learner's radius and
Eq. 5 keep their metric meaning), ``camera``, ``calib``, ``fov`` [deg], ``readings`` (averaged per
taught goal corner). Goals: ``--targets FILE`` in the camera's frame, or, on a rendering plant,
taught: the arm is held at the 8 corners of the preset's goal box (10 readings each) and a 4 x 4
x 4 grid spans them. Every check (camera opens, marker seen at home) is done before learning.
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from gb_pin.cli.body_options import parse_spec
from gb_pin.exceptions import CameraError, InvalidArgumentError

DEFAULTS: dict[str, float | str | None] = {
    "size": 0.025,
    "id": None,
    "dict": "DICT_4X4_50",
    "refine": "apriltag",
    "mode": "xyz",
    "camera": "plant",
    "calib": "",
    "fov": 60.0,
    "readings": 10.0,
}


def wants_camera(args: argparse.Namespace) -> bool:
    """Whether ``--sensor`` names a camera tracker."""
    return str(getattr(args, "sensor", None) or "").startswith("aruco")


def options(text: str) -> dict[str, Any]:
    """The keys of ``aruco[:key=value,...]``, checked.

    Raises:
        InvalidArgumentError: an unknown key, a bad value.
    """
    kind, _, rest = text.partition(":")
    if kind.strip() != "aruco":
        raise InvalidArgumentError(f"--sensor: a camera tracker is aruco:..., got {kind!r}")
    values = parse_spec("--sensor aruco", rest, DEFAULTS)
    if values["id"] is not None and (values["id"] != int(values["id"]) or values["id"] < 0):
        raise InvalidArgumentError(f"--sensor aruco: id must be an integer >= 0, got {values['id']:g}")
    if values["readings"] != int(values["readings"]) or values["readings"] < 1:
        raise InvalidArgumentError(
            f"--sensor aruco: readings must be an integer >= 1, got {values['readings']:g}"
        )
    return values


def watched_robot(args: argparse.Namespace, robot: Any, targets: Any = None) -> Any:
    """The robot watched by ``--sensor aruco``'s camera (:class:`~gb_pin.vision.watched.WatchedRobot`).

    Raises:
        CameraError: OpenCV missing, a camera that cannot open, the marker not seen at home.
        InvalidArgumentError: bad keys; no goals (a real arm without --targets).
    """
    from gb_pin.vision import ArucoTracker, CameraSensor, Intrinsics, WatchedRobot, require_cv2

    require_cv2()
    values = options(args.sensor)
    plant_camera = getattr(robot, "camera", None)
    if values["camera"] == "plant":
        if plant_camera is None:
            raise InvalidArgumentError(
                "--sensor aruco: camera=INDEX|PATH (a webcam), or a plant that renders "
                "(--plant mujoco:camera=side)"
            )
        camera: Any = robot
        intrinsics = plant_camera.intrinsics()
    else:
        from gb_pin.vision import VideoCamera

        source: int | str = int(values["camera"]) if values["camera"].isdigit() else values["camera"]
        video = VideoCamera(source)  # one line if it cannot open, before anything moves
        camera = video
        width, height = video.read().shape[1::-1]
        intrinsics = Intrinsics.load(values["calib"]) if values["calib"] else Intrinsics.guess(
            width, height, values["fov"])  # fmt: skip
    common = {"marker_id": None if values["id"] is None else int(values["id"]), "dictionary": values["dict"],
              "refine": values["refine"]}  # fmt: skip
    xyz = ArucoTracker(intrinsics, values["size"], **common)
    tracker = xyz
    if values["mode"] == "uv":
        home = WatchedRobot(robot, CameraSensor(camera, xyz)).home_reading  # the marker must be seen at home
        tracker = ArucoTracker(intrinsics, values["size"], mode="uv", scale=float(home[2]) / intrinsics.fx,
                               **common)  # fmt: skip
    elif values["mode"] != "xyz":
        raise InvalidArgumentError(f"--sensor aruco: mode must be xyz or uv, got {values['mode']!r}")
    watched = WatchedRobot(robot, CameraSensor(camera, tracker))
    if targets is not None:
        watched.targets = watched.check_targets(targets)
        return watched
    kinematic = getattr(robot, "target", None)
    if plant_camera is None or kinematic is None or kinematic.targets is None:
        raise CameraError(
            "--sensor aruco on a real arm needs goals in the camera's frame: --targets FILE (taught with "
            "gb_pin.vision.teach, docs/CAMERA.md)"
        )
    watched.targets = watched.teach_box(_corner_postures(kinematic), 4, readings=int(values["readings"]))
    return watched


def _corner_postures(target: Any) -> np.ndarray:
    """Where a user would hold the arm: exact IK on the URDF of the preset goal box's 8 corners."""
    from gb_pin.ik import solve

    lo, hi = target.targets.min(axis=0), target.targets.max(axis=0)
    corners = np.array([[(hi if b else lo)[a] for a, b in enumerate((i, j, k))]
                        for k in (0, 1) for j in (0, 1) for i in (0, 1)])  # fmt: skip
    return np.asarray(solve(target, corners, seed="home").postures)


def camera_summary(robot: Any, error: float | None = None) -> str | None:
    """The summary's ``camera`` line: tracker, pictures, lost ones, units, E^X in pixels; None: none."""
    sensor = getattr(robot, "camera_sensor", None)
    if sensor is None:
        return None
    metric = getattr(sensor.tracker, "mode", "xyz") == "xyz"
    units = (
        "m in the camera's frame" if metric else f"pixels x {sensor.scale:.3g} m/px (depth / focal at home)"
    )
    if not metric and error is not None:
        units += f"; E^X = {error / sensor.scale:.2f} px"
    return (
        f"camera           {sensor.tracker!r}; {sensor.reads} pictures, {sensor.lost} without the marker; "
        f"task units: {units}"
    )
