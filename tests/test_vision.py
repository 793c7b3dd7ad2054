"""gb_pin.vision: the ArUco tracker on synthetic pictures, intrinsics, cameras, taught goals."""

from __future__ import annotations

import json

import numpy as np
import pytest

cv2 = pytest.importorskip("cv2")

from gb_pin.exceptions import CameraError, InvalidArgumentError  # noqa: E402
from gb_pin.vision import (  # noqa: E402
    ArucoTracker,
    CameraSensor,
    Intrinsics,
    VideoCamera,
    goal_box,
    marker_image,
    teach,
)

K = Intrinsics.guess(640, 480, 60.0)
PLATE = marker_image(7, 200, border=40)  # 200 px of marker = 25 mm, a 35 mm plate


def picture(
    t: np.ndarray, rvec: np.ndarray, intrinsics: Intrinsics = K, marker: np.ndarray = PLATE
) -> np.ndarray:
    """The plate at pose (rvec, t) in the camera frame (its z axis towards the camera), on grey."""
    P = marker.shape[0]
    s = 0.025 / 200 * P / 2
    obj = np.array([[-s, s, 0], [s, s, 0], [s, -s, 0], [-s, -s, 0]])
    dst, _ = cv2.projectPoints(obj, rvec, t, intrinsics.matrix, None)
    src = np.array([[0, 0], [P, 0], [P, P], [0, P]], np.float32)
    H = cv2.getPerspectiveTransform(src, dst.reshape(4, 2).astype(np.float32))
    return cv2.warpPerspective(marker, H, (intrinsics.width, intrinsics.height), borderValue=128)


def test_intrinsics_guess_and_validation() -> None:
    assert K.fx == pytest.approx(320 / np.tan(np.radians(30)))
    assert K.fov == pytest.approx(60.0)
    assert (K.cx, K.cy) == (320.0, 240.0)
    with pytest.raises(InvalidArgumentError, match="fov"):
        Intrinsics.guess(640, 480, 180)
    with pytest.raises(InvalidArgumentError, match="principal point"):
        Intrinsics(500, 500, 700, 240, 640, 480)
    with pytest.raises(InvalidArgumentError, match="distortion"):
        Intrinsics(500, 500, 320, 240, 640, 480, (0.1, 0.2, 0.3))


def test_intrinsics_load_opencv_yaml_and_json(tmp_path) -> None:
    path = str(tmp_path / "cam.yaml")
    store = cv2.FileStorage(path, cv2.FILE_STORAGE_WRITE)
    store.write("image_width", 640)
    store.write("image_height", 480)
    store.write("camera_matrix", np.array([[600.0, 0, 330], [0, 602.0, 250], [0, 0, 1]]))
    store.write("distortion_coefficients", np.array([[0.1, -0.2, 0.0, 0.0, 0.05]]))
    store.release()
    got = Intrinsics.load(path)
    assert (got.fx, got.fy, got.cx, got.cy, got.width, got.height) == (600, 602, 330, 250, 640, 480)
    assert got.distortion == pytest.approx((0.1, -0.2, 0.0, 0.0, 0.05))
    jpath = tmp_path / "cam.json"
    jpath.write_text(json.dumps({"K": [600.0, 0, 320, 0, 600.0, 240, 0, 0, 1], "D": [0, 0, 0, 0]}))
    assert Intrinsics.load(jpath).width == 640
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"K": [[600.0, 0, 320], [0, 600.0, 240], [0, 0, 2]]}))
    with pytest.raises(InvalidArgumentError, match="camera matrix"):
        Intrinsics.load(bad)
    (tmp_path / "none.yaml").write_text("%YAML:1.0\n---\nfoo: 1\n")
    with pytest.raises(InvalidArgumentError, match="no camera matrix"):
        Intrinsics.load(tmp_path / "none.yaml")
    with pytest.raises(InvalidArgumentError, match="no calibration file"):
        Intrinsics.load(tmp_path / "missing.yaml")


@pytest.mark.parametrize("z", [0.3, 0.5])
def test_aruco_tracker_finds_the_marker_centre(z: float) -> None:
    """On synthetic (aliased) pictures the refined centre is within a pixel across and 6 mm in depth."""
    tracker = ArucoTracker(K, 0.025, marker_id=7)
    rng = np.random.default_rng(0)
    for _ in range(5):
        t = np.array([rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), z])
        rvec = np.array([np.pi, 0, 0]) + rng.uniform(-0.3, 0.3, 3)
        x = tracker(picture(t, rvec))
        assert x is not None
        assert np.all(np.abs(x[:2] - t[:2]) < 0.001)  # about a pixel
        assert abs(x[2] - t[2]) < 0.006


def test_aruco_tracker_uv_mode_and_scale() -> None:
    t, rvec = np.array([0.03, -0.02, 0.4]), np.array([np.pi + 0.2, 0.1, 0.0])
    centre, _ = cv2.projectPoints(np.zeros((1, 3)), rvec, t, K.matrix, None)
    uv = ArucoTracker(K, 0.025, marker_id=7, mode="uv", refine="subpix")(picture(t, rvec))
    assert uv is not None and uv.shape == (2,)
    assert np.all(np.abs(uv - (centre.ravel() - [K.cx, K.cy])) < 0.6)
    scaled = ArucoTracker(K, 0.025, marker_id=7, mode="uv", refine="subpix", scale=0.4 / K.fx)
    assert scaled.units == "m" and scaled(picture(t, rvec)) == pytest.approx(uv * 0.4 / K.fx)


def test_aruco_tracker_gives_none_never_a_wrong_reading() -> None:
    scene = picture(np.array([0.0, 0.0, 0.4]), np.array([np.pi, 0, 0]))
    assert ArucoTracker(K, 0.025, marker_id=3)(scene) is None  # another id
    assert ArucoTracker(K, 0.025, marker_id=7)(np.full((480, 640), 200, np.uint8)) is None  # nothing
    half = scene.copy()
    half[:, :320] = 128  # the marker half occluded
    assert ArucoTracker(K, 0.025, marker_id=7)(half) is None
    two = np.minimum(scene, np.roll(scene, 150, axis=1))  # the same id twice
    assert ArucoTracker(K, 0.025, marker_id=7)(two) is None
    other = picture(
        np.array([0.1, 0.0, 0.4]), np.array([np.pi, 0, 0]), marker=marker_image(3, 200, border=40)
    )
    assert ArucoTracker(K, 0.025)(np.minimum(scene, other)) is None  # two markers, no id given: which?
    assert ArucoTracker(K, 0.025, marker_id=7)(np.minimum(scene, other)) is not None


def test_aruco_tracker_refuses_bad_arguments() -> None:
    with pytest.raises(InvalidArgumentError, match="DICT_4X4_50"):
        ArucoTracker(K, 0.025, dictionary="DICT_4X4_5O")
    with pytest.raises(InvalidArgumentError, match="metres"):
        ArucoTracker(K, 25)
    with pytest.raises(InvalidArgumentError, match="marker_id"):
        ArucoTracker(K, 0.025, marker_id=50)
    with pytest.raises(InvalidArgumentError, match="refine"):
        ArucoTracker(K, 0.025, refine="best")
    with pytest.raises(InvalidArgumentError, match="uint8"):
        ArucoTracker(K, 0.025)(np.zeros((10, 10), np.float32))


def test_video_camera_errors_in_one_line_and_reads_a_file(tmp_path) -> None:
    with pytest.raises(CameraError, match="cannot open camera 97") as info:
        VideoCamera(97)
    assert "\n" not in str(info.value)
    with pytest.raises(CameraError, match="cannot open video"):
        VideoCamera(str(tmp_path / "missing.avi"))
    path = str(tmp_path / "clip.avi")
    writer = cv2.VideoWriter(path, cv2.VideoWriter_fourcc(*"MJPG"), 30, (640, 480))
    if not writer.isOpened():
        pytest.skip("this OpenCV build writes no MJPG")
    frame = cv2.cvtColor(picture(np.array([0.0, 0.0, 0.35]), np.array([np.pi, 0, 0])), cv2.COLOR_GRAY2BGR)
    for _ in range(3):
        writer.write(frame)
    writer.release()
    with VideoCamera(path) as camera:
        sensor = CameraSensor(camera, ArucoTracker(K, 0.025, marker_id=7))
        readings = [sensor.read() for _ in range(3)]
        assert all(r is not None and abs(r[2] - 0.35) < 0.01 for r in readings)
        with pytest.raises(CameraError, match="no frame"):
            sensor.read()


def test_teach_averages_and_goal_box_spans_taught_corners() -> None:
    readings = iter([None, np.array([1.0, 2.0]), None, np.array([3.0, 4.0])])
    assert teach(lambda: next(readings), 2) == pytest.approx([2.0, 3.0])
    with pytest.raises(InvalidArgumentError, match="seen 0 times"):
        teach(lambda: None, 3)
    box = goal_box([[0, 0, 0], [1, 2, 3]], 3)
    assert box.shape == (27, 3) and box.min(axis=0) == pytest.approx([0, 0, 0])
    R = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    unit = np.array([[i, j, k] for k in (0, 1) for j in (0, 1) for i in (0, 1)], dtype=float)
    corners = unit @ R.T + 5.0  # a box shown corner by corner, turned 90 degrees
    grid = goal_box(corners, 4, shrink=0.5)
    expected = (goal_box([[0, 0, 0], [1, 1, 1]], 4, shrink=0.5)) @ R.T + 5.0
    assert grid == pytest.approx(expected)
    with pytest.raises(InvalidArgumentError, match="span no box"):
        goal_box(np.zeros((3, 3)))
    assert goal_box(unit[:, :2], 2).tolist() == [[0, 0], [0, 1], [1, 0], [1, 1]]  # 8 points in 2-D: a box


def test_external_robot_from_a_preset_with_goals_in_the_camera_frame() -> None:
    from gb_pin.robot.external import ExternalRobot

    goals = goal_box([[-0.05, -0.04, 0.45], [0.05, 0.04, 0.55]], 3)
    robot = ExternalRobot.from_preset("so101", targets=goals)
    preset = ExternalRobot.from_preset("so101")
    assert np.array_equal(robot.targets, goals) and robot.preset == "so101"
    assert np.array_equal(robot.home, preset.home) and np.array_equal(robot.upper, preset.upper)
    with pytest.raises(InvalidArgumentError, match="targets"):
        ExternalRobot.from_preset("so101", targets=np.zeros((4, 2)))
