"""The viewer draws any robot whole: humanoid replays, the camera's frame, models shown, function robots.

Issue 25: the TALOS replay drew no right arm and no right leg (their meshes are mirrored, a
reflection no quaternion describes), the camera cropped humanoids (it framed the arm's chain, not
the body), ``show`` drew a current goal and listed a trail a learned model does not have, its
spheres hid small grids, and a robot given as a function could not be shown or replayed.
"""

from __future__ import annotations

import base64
import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import umsgpack

pytest.importorskip("meshcat")

import gb_pin
from gb_pin.viewer import export_model, export_replay
from gb_pin.viewer.animation import rotation_and_scale
from gb_pin.viewer.cache import OfflineWindow
from gb_pin.viewer.geometry import quaternions
from gb_pin.viewer.replay import replay_window
from gb_pin.viewer.scene import Scene
from gb_pin.viewer.style import CAMERA_FOV, ROBOT, TARGET

SMALL_URDF = Path(__file__).parent / "data" / "small_arm.urdf"


def html_commands(html: str) -> list[dict[str, Any]]:
    """The meshcat commands embedded in an exported HTML page."""
    match = re.search(r"var commands = (\[.*?\]);", html, re.S)
    assert match is not None
    return [umsgpack.unpackb(base64.b64decode(c)) for c in json.loads(match.group(1))]


def float32s(ext: Any) -> np.ndarray:
    """A Float32Array sent as msgpack extension 0x17."""
    return np.frombuffer(ext.data, dtype=np.float32).astype(float)


def rotation(q: np.ndarray) -> np.ndarray:
    """The rotation matrix of a unit quaternion (x, y, z, w), as three.js builds it."""
    x, y, z, w = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def test_rotation_and_scale_recovers_mirrored_and_scaled_placements() -> None:
    """M = R diag(s) for a rotation R (det +1) and any scales s, mirrored (negative) ones included."""
    rng = np.random.default_rng(0)
    for _ in range(50):
        R0 = quaternion_rotation(rng)
        s0 = rng.uniform(0.1, 2.0, 3) * rng.choice([-1.0, 1.0], 3)
        M = np.eye(4)
        M[:3, :3] = R0 * s0[None, :]
        R, s = rotation_and_scale(M[None])
        assert abs(np.linalg.det(R[0]) - 1.0) < 1e-12
        np.testing.assert_allclose(R[0] * s[0][None, :], M[:3, :3], atol=1e-12)
        np.testing.assert_allclose(rotation(quaternions(R)[0]), R[0], atol=1e-12)


def quaternion_rotation(rng: np.random.Generator) -> np.ndarray:
    """A random rotation matrix."""
    q = rng.normal(size=4)
    return rotation(q)


@pytest.fixture(scope="module")
def talos_replay() -> tuple[gb_pin.BabbleResult, Scene, list[dict[str, Any]]]:
    """A short TALOS run with a recording, replayed into an offline window (its meshes drawn)."""
    result = gb_pin.babble(
        "talos_left_arm", movements=4, seed=0, record=gb_pin.Recording(every=5, first=0, last=4)
    )
    window = OfflineWindow()
    scene = replay_window(window, result)
    return result, scene, html_commands(window.scene.html())


def test_talos_replay_animates_every_mesh_where_pinocchio_places_it(
    talos_replay: tuple[gb_pin.BabbleResult, Scene, list[dict[str, Any]]],
) -> None:
    """Every mesh's first keyframe (position, quaternion, scale) rebuilds its placement, mirrored ones too.

    TALOS's right arm and leg are its left ones mirrored (a negative mesh scale): before the fix
    their quaternions were computed from reflections and came out NaN, and the browser hid them.
    """
    result, scene, commands = talos_replay
    assert type(scene.figure).__name__ == "MeshFigure"
    (animation,) = [c for c in commands if c["type"] == "set_animation"]
    clips = {
        a["path"]: {t["name"]: t["values"] for t in a["clip"]["tracks"]} for a in animation["animations"]
    }
    expected = dict(scene.figure.transforms(result.recording.posture[0]))
    visuals = [p for p in expected if p.startswith(f"{ROBOT}/visuals/")]
    assert any("arm_right" in p for p in visuals) and any("leg_right" in p for p in visuals)
    mirrored = 0
    for path in visuals:
        tracks = clips[path]
        position = float32s(tracks[".position"])[:3]
        quaternion = float32s(tracks[".quaternion"])[:4]
        scale = float32s(tracks[".scale"])[:3] if ".scale" in tracks else np.ones(3)
        assert np.all(np.isfinite(quaternion)), path
        mirrored += bool(np.any(scale < 0))
        T = expected[path]
        np.testing.assert_allclose(position, T[:3, 3], atol=1e-5, err_msg=path)
        np.testing.assert_allclose(rotation(quaternion) * scale[None, :], T[:3, :3], atol=1e-5, err_msg=path)
    assert mirrored > 0  # the test covers mirrored meshes


def test_the_camera_frames_the_whole_humanoid(
    talos_replay: tuple[gb_pin.BabbleResult, Scene, list[dict[str, Any]]],
) -> None:
    """Every corner of every mesh's box (head and feet included) lies within the camera's vertical view.

    The vertical field of view is the narrower one (the page is wider than tall); the camera looks
    at the orbit centre, where the scene is shifted to (a little right of the workspace centre).
    """
    result, scene, _ = talos_replay
    points = scene.figure.outline(result.target.home) - scene.center + scene._beside_legend()
    camera = scene._view_direction() * scene.camera_distance
    rays = points - camera
    cosine = rays @ -camera / (np.linalg.norm(rays, axis=1) * np.linalg.norm(camera))
    angles = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
    assert angles.max() < CAMERA_FOV / 2
    head = points[:, 2].max() - points[:, 2].min()
    assert head > 1.2  # the outline spans TALOS from its feet to its head (1.5 m), not just the arm


def test_show_draws_no_current_goal_and_lists_no_trail(tmp_path: Path) -> None:
    """A learned model shown has no current goal nor trail: its marker hidden, the legend without both."""
    result = gb_pin.babble("planar5", movements=30, seed=1, record=gb_pin.Recording(every=5, last=10))
    export_model(result, tmp_path / "m.html")
    html = (tmp_path / "m.html").read_text()
    commands = html_commands(html)
    hidden = [c for c in commands if c["type"] == "set_property" and c["path"] == TARGET]
    assert hidden and hidden[-1]["value"] is False
    assert "current goal" not in html and "trail" not in html
    export_replay(result, tmp_path / "r.html")
    replayed = (tmp_path / "r.html").read_text()
    assert "current goal" in replayed and "the trail" in replayed


def test_points_and_spheres_never_hide_a_small_grid() -> None:
    """On a grid small for the robot (1 cm steps on a 1.2 m arm) the markers shrink with the grid's step."""
    arm = gb_pin.KinematicTarget.from_urdf(
        SMALL_URDF, "tool", ["j1", "j2", "j3"], onboard=False, home=[0.3, -0.5, 0.05]
    )
    step = 0.01
    grid = arm.home_position + step * np.array(
        [[i, j, k] for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)]
    )
    scene = Scene(OfflineWindow(), arm, grid, visual_model=False)
    assert scene.figure.size > 1.0
    assert scene.marker_radius <= 0.02 * 8 * step + 1e-12  # 1.6 mm instead of 2.4 cm
    assert scene.mark_size <= 8 * step + 1e-12
    wide = Scene(
        OfflineWindow(), arm, arm.home_position + 0.3 * (grid - arm.home_position) / step, visual_model=False
    )
    assert wide.marker_radius == pytest.approx(
        0.02 * wide.figure.size
    )  # a grid of the robot's size: as before


def spiral(q: np.ndarray) -> np.ndarray:
    """A two-link planar arm given as a function (links 0.5 m and 0.4 m)."""
    return np.array(
        [
            0.5 * math.cos(q[0]) + 0.4 * math.cos(q[0] + q[1]),
            0.5 * math.sin(q[0]) + 0.4 * math.sin(q[0] + q[1]),
        ]
    )


def test_a_robot_given_as_a_function_is_shown_and_replayed(tmp_path: Path) -> None:
    """show and replay draw a FunctionTarget as its effector: a sphere at forward(q) on x, y."""
    home = np.array([0.3, 1.2])
    X = np.array(
        [spiral(home + d) for d in np.linspace(-0.3, 0.3, 9).reshape(-1, 1) * np.array([[1.0, -1.0]])]
    )
    robot = gb_pin.FunctionTarget(spiral, home, lower=[-3, -3], upper=[3, 3], targets=X, name="two links")
    result = gb_pin.babble(robot, movements=20, seed=0, record=gb_pin.Recording(every=1, last=5))
    export_model(result, tmp_path / "m.html")
    export_replay(result, tmp_path / "r.html")
    for page in ("m.html", "r.html"):
        html = (tmp_path / page).read_text()
        assert "no links to draw" in html
    (animation,) = [
        c for c in html_commands((tmp_path / "r.html").read_text()) if c["type"] == "set_animation"
    ]
    clip = next(a for a in animation["animations"] if a["path"] == f"{ROBOT}/effector")
    first = float32s(clip["clip"]["tracks"][0]["values"])[:3]
    np.testing.assert_allclose(first[:2], spiral(result.recording.posture[0]), atol=1e-6)
