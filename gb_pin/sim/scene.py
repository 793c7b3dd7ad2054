"""What the plant's camera sees: meshes, a floor, lights, a marker plate on the hand, the camera.

:func:`build_scene` writes the MJCF pieces that :func:`~gb_pin.sim.mjcf.mjcf` adds to a plant's
model; they are drawn only (no mass: the bodies' inertias are explicit; no contact: contacts
are off), so the arm's physics is the same with or without a camera (tested bit for bit).

- the URDF's visual meshes (:mod:`gb_pin.sim.meshes`, decimated), else capsules between joints;
- a floor at the base's height, a directional light without shadows and MuJoCo's headlight;
- a **marker plate** on the body that carries the task frame: a white square (``plate`` [m])
  with an ArUco marker (``size`` [m], OpenCV's ``generateImageMarker``), its centre ``offset``
  [m] from the task frame towards the camera, facing the camera at home;
- the **camera**: a preset (:data:`PRESETS`: ``side`` looks along the arm's flex axes from 50 cm,
  the plate always in view; ``front``) or a :class:`CameraPose` given as position and look-at point.

The plate's centre is the point a marker tracker reads: :attr:`Scene.marker_point` (body, offset)
gives the plant its true marker position (``MujocoPlant.true_marker``) for E^X.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin._names import suggest
from gb_pin.exceptions import InvalidArgumentError

PRESETS = ("side", "front")
"""Camera presets: ``side`` (along the flex axes: the plate faces it in every posture), ``front``."""
WIDTH, HEIGHT = 640, 480


@dataclass(frozen=True)
class CameraPose:
    """A pinhole camera looking at ``look_at`` from ``position`` (world frame [m]).

    Args:
        position: the camera's centre (3,) [m].
        look_at: a point on its optical axis (3,) [m].
        fovy: vertical field of view [deg].
        width, height: the picture [px].
    """

    position: tuple[float, float, float]
    look_at: tuple[float, float, float]
    fovy: float = 45.0
    width: int = WIDTH
    height: int = HEIGHT

    def __post_init__(self) -> None:
        p, t = np.asarray(self.position, float), np.asarray(self.look_at, float)
        if p.shape != (3,) or t.shape != (3,) or not np.all(np.isfinite(p)) or not np.all(np.isfinite(t)):
            raise InvalidArgumentError("a camera's position and look_at are 3 finite numbers [m] each")
        if np.linalg.norm(t - p) < 1e-6:
            raise InvalidArgumentError("a camera cannot look at its own position")
        if not 1.0 <= float(self.fovy) <= 170.0:
            raise InvalidArgumentError(f"fovy must be in [1, 170] degrees, got {self.fovy!r}")
        if not (16 <= int(self.width) <= 8192 and 16 <= int(self.height) <= 8192):
            raise InvalidArgumentError(f"a picture is 16-8192 px a side, got {self.width} x {self.height}")

    @property
    def rotation(self) -> NDArray[np.float64]:
        """OpenCV's camera axes in the world (3, 3): columns x right, y down, z forward."""
        p, t = np.asarray(self.position, float), np.asarray(self.look_at, float)
        z = (t - p) / np.linalg.norm(t - p)
        up = np.array([0.0, 0.0, 1.0]) if abs(z[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
        x = np.cross(z, up)
        x /= np.linalg.norm(x)
        y = np.cross(z, x)
        return np.column_stack([x, y, z])

    @property
    def focal(self) -> float:
        """The focal length [px] (square pixels)."""
        return 0.5 * self.height / math.tan(math.radians(self.fovy) / 2.0)

    def to_camera(self, points: ArrayLike) -> NDArray[np.float64]:
        """World points (..., 3) in the camera's frame (OpenCV's axes) [m]."""
        return (np.asarray(points, float) - np.asarray(self.position, float)) @ self.rotation

    def moved(self, shift: ArrayLike, rotation: ArrayLike) -> CameraPose:
        """The pose a user believes in: shifted by ``shift`` [m], turned by ``rotation`` (3, 3)."""
        p = np.asarray(self.position, float) + np.asarray(shift, float)
        d = np.asarray(rotation, float) @ (np.asarray(self.look_at, float) - np.asarray(self.position, float))
        return CameraPose(tuple(p), tuple(p + d), self.fovy, self.width, self.height)


def preset_pose(name: str, target: Any, distance: float = 0.5) -> CameraPose:
    """The camera of a preset, ``distance`` [m] from the centre of ``target``'s goal box (or home).

    Raises:
        InvalidArgumentError: an unknown preset.
    """
    if name not in PRESETS:
        raise InvalidArgumentError(f"unknown camera {name!r}; {suggest(name, list(PRESETS))}")
    goals = target.targets if target.targets is not None else None
    centre = (
        np.asarray(target.home_position, float) if goals is None else np.asarray(goals, float).mean(axis=0)
    )
    if centre.shape != (3,):
        raise InvalidArgumentError("a camera needs a robot whose task is a 3-D position (axes xyz)")
    out = np.array([centre[0], centre[1], 0.0])
    out = out / np.linalg.norm(out) if np.linalg.norm(out) > 1e-6 else np.array([1.0, 0.0, 0.0])
    side = np.cross([0.0, 0.0, 1.0], out)
    look = side if name == "side" else out
    position = centre + distance * (0.94 * look + 0.34 * np.array([0.0, 0.0, 1.0]))  # 20 deg above
    return CameraPose(tuple(position), tuple(centre))


@dataclass(frozen=True)
class Marker:
    """The ArUco marker plate on the hand.

    Args:
        marker_id: the marker's id in ``dictionary``.
        size: the marker's black square [m].
        plate: the white plate around it [m] (its quiet zone).
        offset: the plate's centre from the task frame towards the camera [m] (clear of the gripper).
        dictionary: OpenCV's predefined dictionary.
    """

    marker_id: int = 7
    size: float = 0.025
    plate: float = 0.035
    offset: float = 0.03
    dictionary: str = "DICT_4X4_50"

    def __post_init__(self) -> None:
        if not 0.002 <= float(self.size) <= 0.5 or float(self.plate) < float(self.size) * 1.1:
            raise InvalidArgumentError(
                f"a marker is 2-500 mm with a plate at least 10 % wider, got size {self.size!r}, "
                f"plate {self.plate!r}"
            )
        if not 0.0 <= float(self.offset) <= 0.5:
            raise InvalidArgumentError(f"the marker's offset must be in [0, 0.5] m, got {self.offset!r}")


@dataclass
class Scene:
    """MJCF pieces of a rendering plant, and where its marker is.

    Attributes:
        header: the ``<visual>`` and ``<asset>`` elements.
        bodies: extra elements per body (q index; -1: the world).
        assets: in-memory files (meshes, the marker's texture) for ``MjModel.from_xml_string``.
        camera: the :class:`CameraPose`.
        marker: the :class:`Marker`.
        marker_body: q index of the body carrying the plate (-1: the world).
        marker_offset: the plate's centre in that body's frame (3,) [m].
        triangles: triangles drawn of the robot.
    """

    header: list[str]
    bodies: dict[int, list[str]]
    assets: dict[str, bytes]
    camera: CameraPose
    marker: Marker
    marker_body: int
    marker_offset: NDArray[np.float64]
    triangles: int = 0
    digest_text: str = field(default="")


def build_scene(
    target: Any, camera: CameraPose, marker: Marker, frame_pose: Any, meshes: bool = True
) -> Scene:
    """The scene of ``target`` seen by ``camera``, the ``marker`` on its hand.

    Args:
        target: the :class:`~gb_pin.robot.target.KinematicTarget`.
        camera: the camera's pose.
        marker: the plate.
        frame_pose: ``(body q index, task frame in that body (3,), body rotation at home (3, 3), task frame
            at home in the world (3,))``: where the plate goes.
        meshes: the URDF's meshes (else capsules).
    """
    from gb_pin.sim.meshes import visuals
    from gb_pin.sim.mjcf import _v, quaternion
    from gb_pin.vision.aruco import marker_png

    body, local, R_home, p_home = frame_pose
    assets: dict[str, bytes] = {}
    bodies: dict[int, list[str]] = {}
    header_assets: list[str] = []
    drawn = visuals(target) if meshes else []
    for v in drawn:
        assets[f"{v.name}.stl"] = v.stl
        header_assets.append(f'<mesh name="{v.name}" file="{v.name}.stl"/>')
        bodies.setdefault(v.parent, []).append(
            f'<geom type="mesh" mesh="{v.name}" pos={_v(v.position)} quat={_v(quaternion(v.rotation))} '
            'material="robot" contype="0" conaffinity="0" mass="0"/>'
        )
    if not drawn:
        _capsules(target, bodies, _v)
    # the plate: facing the camera at home, its centre `offset` from the task frame towards it
    to_camera = np.asarray(camera.position, float) - np.asarray(p_home, float)
    n_world = to_camera / np.linalg.norm(to_camera)
    n_body = np.asarray(R_home, float).T @ n_world
    up_body = np.asarray(R_home, float).T @ np.array([0.0, 0.0, 1.0])
    x_axis = np.cross(up_body, n_body)
    x_axis = x_axis / np.linalg.norm(x_axis) if np.linalg.norm(x_axis) > 1e-6 else _any_normal(n_body)
    y_axis = np.cross(n_body, x_axis)
    centre = np.asarray(local, float) + marker.offset * n_body
    thickness = 0.001
    plate_pos = centre - 0.5 * thickness * n_body
    pixels = 240  # six cells of 40 px: the marker's black square is exactly `pixels`
    border = round(pixels * (marker.plate / marker.size - 1.0) / 2.0)
    assets["marker.png"] = marker_png(marker.marker_id, pixels, marker.dictionary, border=border)
    header_assets += [
        '<texture name="marker" type="2d" file="marker.png"/>',
        '<material name="marker" texture="marker" specular="0" shininess="0"/>',
    ]
    half = marker.size * (pixels + 2 * border) / pixels / 2.0  # the black square exactly `size`
    bodies.setdefault(body, []).append(
        f'<geom name="marker" type="box" size={_v([half, half, thickness / 2])} pos={_v(plate_pos)} '
        f'xyaxes={_v(np.concatenate([x_axis, y_axis]))} material="marker" contype="0" conaffinity="0" '
        'mass="0"/>'
    )
    cam = camera.rotation  # OpenCV axes; MuJoCo's camera: x right, y up, looking along -z
    bodies.setdefault(-1, []).extend([
        f'<camera name="view" pos={_v(camera.position)} xyaxes={_v(np.concatenate([cam[:, 0], -cam[:, 1]]))} '
        f'fovy={_v([camera.fovy])}/>',
        '<light name="sun" directional="true" castshadow="false" pos="0 0 2" dir="0.3 0.2 -1" '
        'diffuse="0.55 0.55 0.55"/>',
        '<geom name="floor" type="plane" size="1.5 1.5 0.01" material="floor" contype="0" conaffinity="0"/>',
    ])  # fmt: skip
    header = [
        "  <visual>",
        f'    <global offwidth="{camera.width}" offheight="{camera.height}"/>',
        '    <quality shadowsize="0" offsamples="0"/>',
        '    <headlight ambient="0.35 0.35 0.35" diffuse="0.45 0.45 0.45" specular="0 0 0"/>',
        "  </visual>",
        "  <asset>",
        '    <texture name="floor" type="2d" builtin="checker" rgb1="0.62 0.6 0.56" rgb2="0.55 0.53 0.5" '
        'width="256" height="256"/>',
        '    <material name="floor" texture="floor" texrepeat="12 12" specular="0"/>',
        '    <material name="robot" rgba="0.92 0.9 0.85 1" specular="0.1"/>',
        *(f"    {line}" for line in header_assets),
        "  </asset>",
    ]
    return Scene(header, bodies, assets, camera, marker, body, centre, sum(v.triangles for v in drawn))


def _any_normal(n: NDArray[np.float64]) -> NDArray[np.float64]:
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(a, n)
    return x / np.linalg.norm(x)


def _capsules(target: Any, bodies: dict[int, list[str]], _v: Any) -> None:
    """Capsules from each moved body to its children and to the task frame (a robot without meshes)."""
    chain = target.chain
    for i in range(chain.n_joints):
        parent = int(chain.parents[i])
        a = int(chain.q_index[parent]) if parent >= 0 else -1
        start = np.zeros(3)
        end = np.asarray(chain.translations[i], float)
        if parent < 0 or np.linalg.norm(end) < 1e-4:
            continue
        bodies.setdefault(a, []).append(
            f'<geom type="capsule" fromto={_v(np.concatenate([start, end]))} size="0.012" material="robot" '
            'contype="0" conaffinity="0" mass="0"/>'
        )
    if chain.frame_parent >= 0:
        a = int(chain.q_index[chain.frame_parent])
        end = np.asarray(chain.frame_translation, float)
        if np.linalg.norm(end) > 1e-4:
            bodies.setdefault(a, []).append(
                f'<geom type="capsule" fromto={_v(np.concatenate([np.zeros(3), end]))} size="0.01" '
                'material="robot" contype="0" conaffinity="0" mass="0"/>'
            )
