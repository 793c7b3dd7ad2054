"""What the meshcat viewer draws: the robot, targets, reached positions, a trail, the Fig. 3 overlay.

Every drawing becomes meshcat commands sent to a *window* (``send(command)``), so
the same scene goes to a live browser (:class:`gb_pin.viewer.server.LocalServer`)
or into a self-contained HTML file (:class:`gb_pin.viewer.server.OfflineWindow`).
A robot is drawn by a *figure*: a stick figure of its joints and links (any
``pin.Model``; procedural planar chains have no visual geometry) or, where the
target carries a visual ``pin.GeometryModel``, its meshes loaded by pinocchio's
``MeshcatVisualizer``. A figure turns a posture into (path, 4x4 transform) pairs;
the same pairs drive the live view and the keyframes of a replay animation.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any, Protocol

import numpy as np
import pinocchio as pin
import umsgpack
from numpy.typing import ArrayLike, NDArray

from gb_pin.exceptions import GbPinError
from gb_pin.robot.target import KinematicTarget
from gb_pin.viewer.server import encode

with warnings.catch_warnings():
    # meshcat 0.3.2 imports its zmq server, which imports a module pyzmq deprecated.
    warnings.simplefilter("ignore", DeprecationWarning)
    import meshcat
    import meshcat.geometry as mg

ROOT = "/meshcat/gb_pin"
ROBOT = f"{ROOT}/robot"
TRAIL = f"{ROOT}/trail"
TARGET = f"{ROOT}/target"
TARGET_SET = f"{ROOT}/targets"
OVERLAY = f"{ROOT}/overlay"

# Colours (0xRRGGBB): links orange, joints dark grey, effector and trail red, current target
# green, target grid grey, reached grid f(g(x*)) blue, postures g(x*) dark blue-grey.
LINK_COLOR = 0xE67E22
JOINT_COLOR = 0x34495E
EFFECTOR_COLOR = 0xC0392B
TARGET_COLOR = 0x27AE60
TARGET_SET_COLOR = 0x7F8C8D
REACHED_COLOR = 0x2980B9
POSTURE_COLOR = 0x2C3E50
# Vertical field of view of meshcat's default camera [deg] (viewer/src/index.js, create_camera).
CAMERA_FOV = 75.0


class Window(Protocol):
    """Where commands go: a live server or an offline recorder (see :mod:`gb_pin.viewer.server`)."""

    def send(self, command: Any) -> None:
        """Send one meshcat command."""

    def send_encoded(self, kind: str, path: str, data: bytes, prop: str = "") -> None:
        """Send one encoded command."""

    def send_batch(self, batch: Sequence[tuple[str, str, bytes, str]]) -> None:
        """Send encoded commands (kind, path, data, property) in order, at once."""


Transforms = list[tuple[str, NDArray[np.float64]]]


def translation(p: ArrayLike) -> NDArray[np.float64]:
    """Homogeneous transform of a pure translation."""
    T = np.eye(4)
    T[:3, 3] = np.asarray(p, dtype=float)
    return T


def align_y(direction: ArrayLike) -> NDArray[np.float64]:
    """Rotation taking the y-axis (meshcat's cylinder axis) onto ``direction``."""
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    y = np.array([0.0, 1.0, 0.0])
    v = np.cross(y, d)
    c = float(np.dot(y, d))
    if c < -1.0 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])
    vx = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    return np.eye(3) + vx + vx @ vx / (1.0 + c)


def quaternions(R: NDArray[np.float64]) -> NDArray[np.float64]:
    """Unit quaternions (x, y, z, w) (three.js order) of rotation matrices (..., 3, 3), sign-continuous."""
    m = np.asarray(R, dtype=float)
    tr = m[..., 0, 0] + m[..., 1, 1] + m[..., 2, 2]
    q = np.empty((*m.shape[:-2], 4))
    # Shepperd's method: take the largest of w, x, y, z as pivot for accuracy.
    cand = np.stack([tr, m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]], axis=-1)
    pivot = np.argmax(cand, axis=-1)
    for k in range(4):
        sel = pivot == k
        if not np.any(sel):
            continue
        a = m[sel]
        if k == 0:
            s = np.sqrt(1.0 + a[:, 0, 0] + a[:, 1, 1] + a[:, 2, 2]) * 2.0
            q[sel] = np.stack(
                [
                    (a[:, 2, 1] - a[:, 1, 2]) / s,
                    (a[:, 0, 2] - a[:, 2, 0]) / s,
                    (a[:, 1, 0] - a[:, 0, 1]) / s,
                    s / 4,
                ],
                axis=-1,
            )
        elif k == 1:
            s = np.sqrt(1.0 + a[:, 0, 0] - a[:, 1, 1] - a[:, 2, 2]) * 2.0
            q[sel] = np.stack(
                [
                    s / 4,
                    (a[:, 0, 1] + a[:, 1, 0]) / s,
                    (a[:, 0, 2] + a[:, 2, 0]) / s,
                    (a[:, 2, 1] - a[:, 1, 2]) / s,
                ],
                axis=-1,
            )
        elif k == 2:
            s = np.sqrt(1.0 + a[:, 1, 1] - a[:, 0, 0] - a[:, 2, 2]) * 2.0
            q[sel] = np.stack(
                [
                    (a[:, 0, 1] + a[:, 1, 0]) / s,
                    s / 4,
                    (a[:, 1, 2] + a[:, 2, 1]) / s,
                    (a[:, 0, 2] - a[:, 2, 0]) / s,
                ],
                axis=-1,
            )
        else:
            s = np.sqrt(1.0 + a[:, 2, 2] - a[:, 0, 0] - a[:, 1, 1]) * 2.0
            q[sel] = np.stack(
                [
                    (a[:, 0, 2] + a[:, 2, 0]) / s,
                    (a[:, 1, 2] + a[:, 2, 1]) / s,
                    s / 4,
                    (a[:, 1, 0] - a[:, 0, 1]) / s,
                ],
                axis=-1,
            )
    if q.ndim == 2 and q.shape[0] > 1:
        # q and -q are the same rotation; keep neighbours in one hemisphere so keyframes interpolate short.
        flips = np.cumsum(np.einsum("ij,ij->i", q[1:], q[:-1]) < 0.0) % 2
        q[1:][flips == 1] *= -1.0
    return q


# A msgpack float64 is the byte 0xcb then the big-endian double; 16 of them follow an array16 header.
_F64 = np.dtype([("marker", "u1"), ("value", ">f8")])
_PREFIXES: dict[str, bytes] = {}


def _transform_message(path: str, T: NDArray[np.float64]) -> tuple[str, str, bytes, str]:
    """meshcat's ``set_transform`` command, msgpack-encoded (as ``umsgpack.packb`` would, ~5x faster).

    Live frames send dozens per frame; the map prefix of each path is encoded once and
    the 16 column-major matrix entries are packed in one numpy call.
    """
    prefix = _PREFIXES.get(path)
    if prefix is None:
        empty = umsgpack.packb({"type": "set_transform", "path": path, "matrix": []})
        prefix = _PREFIXES[path] = empty[:-1] + b"\xdc\x00\x10"  # drop the empty array, add array16 of 16
    rec = np.empty(16, dtype=_F64)
    rec["marker"] = 0xCB
    rec["value"] = np.asarray(T, dtype=float).T.ravel()
    return "set_transform", path, prefix + rec.tobytes(), ""


def _property_message(path: str, key: str, value: Any) -> tuple[str, str, bytes, str]:
    data = {"type": "set_property", "path": path, "property": key, "value": value}
    return "set_property", path, umsgpack.packb(data), key


def grid_shape(X: NDArray[np.float64]) -> tuple[int, ...] | None:
    """The shape of ``X`` if it is a regular grid listed first axis slowest (as in presets), else None."""
    N, n = X.shape
    axes = [np.unique(np.round(X[:, a], 9)) for a in range(n)]
    shape = tuple(len(u) for u in axes)
    if math.prod(shape) != N or N < 2:
        return None
    mesh = np.meshgrid(*axes, indexing="ij")
    grid = np.stack([g.ravel() for g in mesh], axis=1)
    return shape if np.allclose(grid, X, atol=1e-8) else None


def grid_edges(shape: tuple[int, ...]) -> NDArray[np.int64]:
    """(E, 2) index pairs of neighbouring grid points."""
    idx = np.arange(math.prod(shape)).reshape(shape)
    pairs = []
    for a in range(len(shape)):
        if shape[a] < 2:
            continue
        lo = np.take(idx, np.arange(shape[a] - 1), axis=a).ravel()
        hi = np.take(idx, np.arange(1, shape[a]), axis=a).ravel()
        pairs.append(np.stack([lo, hi], axis=1))
    return np.concatenate(pairs) if pairs else np.zeros((0, 2), dtype=np.int64)


def spread_indices(X: NDArray[np.float64], k: int) -> list[int]:
    """``k`` indices of points spread over ``X``: the one nearest the centroid, then farthest-point picks."""
    k = min(k, X.shape[0])
    chosen = [int(np.argmin(np.linalg.norm(X - X.mean(axis=0), axis=1)))]
    dist = np.linalg.norm(X - X[chosen[0]], axis=1)
    while len(chosen) < k:
        nxt = int(np.argmax(dist))
        chosen.append(nxt)
        dist = np.minimum(dist, np.linalg.norm(X - X[nxt], axis=1))
    return chosen


def _path(p: str) -> Any:
    """meshcat Path of an absolute path string."""
    from meshcat.path import Path

    return Path(tuple(s for s in p.split("/") if s))


def _segments(points: NDArray[np.float64], color: int, opacity: float = 1.0) -> Any:
    """meshcat LineSegments object from (2S, 3) endpoints."""
    material = mg.LineBasicMaterial(color=color, opacity=opacity, transparent=opacity < 1.0)
    return mg.LineSegments(mg.PointsGeometry(points.astype(np.float32).T), material)


def _points(points: NDArray[np.float64], color: int, size: float) -> Any:
    """meshcat Points object; meshcat's PointsMaterial always uses vertex colours, so each point gets one."""
    rgb = np.array([(color >> 16) & 255, (color >> 8) & 255, color & 255], dtype=np.float32) / 255.0
    colors = np.tile(rgb, (points.shape[0], 1))
    geometry = mg.PointsGeometry(points.astype(np.float32).T, color=colors.T)
    return mg.Points(geometry, mg.PointsMaterial(size=size, color=color))


class StickFigure:
    """A robot drawn with simple geometry: a sphere per joint, a cylinder per link, a sphere on the frame.

    Works for any ``pin.Model`` (procedural planar chains carry no visual geometry):
    a link joins a joint to each child joint and to the operational frame; every
    piece hangs under its joint's node, so a posture moves one node per joint.

    Args:
        target: the robot.
        root: meshcat path of the figure.
    """

    def __init__(self, target: KinematicTarget, root: str = ROBOT) -> None:
        self.target = target
        self.root = root
        self.model = target.model
        self.data = self.model.createData()
        model = self.model
        self.frame_id = target.frame_id
        frame = model.frames[self.frame_id]
        # Links in the parent joint's frame: (joint, start, end); joint 0 is the fixed world.
        links: list[tuple[int, NDArray[np.float64], NDArray[np.float64]]] = []
        for j in range(1, model.njoints):
            links.append((int(model.parents[j]), np.zeros(3), np.array(model.jointPlacements[j].translation)))
        links.append((int(frame.parentJoint), np.zeros(3), np.array(frame.placement.translation)))
        self.links = [(j, a, b) for j, a, b in links if np.linalg.norm(b - a) > 1e-9]
        length = sum(float(np.linalg.norm(b - a)) for _, a, b in self.links)
        self.size = length if length > 0 else 1.0
        shortest = min((float(np.linalg.norm(b - a)) for _, a, b in self.links), default=self.size)
        # Thin enough that joints do not merge on arms of many short links (planar50: 2 cm links).
        self.joint_radius = min(0.016 * self.size, 0.25 * shortest)
        self.link_radius = min(0.008 * self.size, 0.5 * self.joint_radius)
        self.effector_radius = 0.02 * self.size

    def joint_path(self, j: int) -> str:
        """meshcat path of joint ``j``'s node (``j`` = 0: the fixed base)."""
        return f"{self.root}/base" if j == 0 else f"{self.root}/j{j}"

    @property
    def effector_path(self) -> str:
        """meshcat path of the operational frame's marker."""
        return f"{self.root}/effector"

    def load(self, window: Window) -> None:
        """Send the geometry (once)."""
        from meshcat.commands import SetObject, SetTransform
        from meshcat.path import Path

        def path(p: str) -> Path:
            return Path(tuple(s for s in p.split("/") if s))

        link_mat = mg.MeshLambertMaterial(color=LINK_COLOR)
        joint_mat = mg.MeshLambertMaterial(color=JOINT_COLOR)
        for j in range(1, self.model.njoints):
            window.send(
                SetObject(mg.Sphere(self.joint_radius), joint_mat, path(f"{self.joint_path(j)}/joint"))
            )
        for i, (j, a, b) in enumerate(self.links):
            d = b - a
            p = f"{self.joint_path(j)}/link{i}"
            window.send(SetObject(mg.Cylinder(float(np.linalg.norm(d)), self.link_radius), link_mat, path(p)))
            T = translation((a + b) / 2.0)
            T[:3, :3] = align_y(d)
            window.send(SetTransform(T, path(p)))
        window.send(
            SetObject(
                mg.Sphere(self.effector_radius),
                mg.MeshLambertMaterial(color=EFFECTOR_COLOR),
                path(f"{self.effector_path}/sphere"),
            )
        )

    def _forward(self, q: NDArray[np.float64]) -> None:
        pin.forwardKinematics(self.model, self.data, self.target.to_pinocchio(q))
        pin.updateFramePlacement(self.model, self.data, self.frame_id)

    def transforms(self, q: NDArray[np.float64]) -> Transforms:
        """(path, world transform) of each moving node at posture ``q``."""
        self._forward(q)
        out = [(self.joint_path(j), self.data.oMi[j].homogeneous) for j in range(1, self.model.njoints)]
        out.append((self.effector_path, self.data.oMf[self.frame_id].homogeneous))
        return out

    def skeleton(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """(2S, 3) endpoints of the links at posture ``q`` (world frame) [m]."""
        self._forward(q)
        pts = []
        for j, a, b in self.links:
            M = self.data.oMi[j]
            pts.append(M.act(a))
            pts.append(M.act(b))
        return np.array(pts)

    def effector(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """3-D position of the operational frame at ``q`` [m]."""
        self._forward(q)
        return np.array(self.data.oMf[self.frame_id].translation)


class MeshFigure(StickFigure):
    """A robot drawn with its visual meshes, loaded by pinocchio's ``MeshcatVisualizer``.

    The meshes belong to the target's full model (``target.full_model`` where the
    target has one: locked joints stay at the reference posture), else to
    ``target.model``. Their placements come from ``pinocchio.updateGeometryPlacements``,
    so live frames and replay keyframes are computed alike. The operational frame
    keeps its sphere marker.

    Args:
        target: the robot.
        visual_model: the ``pin.GeometryModel`` of visual meshes of that model.
        root: meshcat path of the figure.
    """

    def __init__(self, target: KinematicTarget, visual_model: Any, root: str = ROBOT) -> None:
        super().__init__(target, root)
        self.mesh_model = getattr(target, "full_model", target.model)
        self.mesh_data = self.mesh_model.createData()
        configure = getattr(target, "full_configuration", None)
        self._configure = configure if callable(configure) else target.to_pinocchio
        self.visual_model = visual_model
        self.visual_data = visual_model.createData()

    def load(self, window: Window) -> None:
        """Load the meshes through pinocchio's MeshcatVisualizer (its camera helpers are not used)."""
        from meshcat.commands import SetObject
        from pinocchio.visualize import MeshcatVisualizer

        viz = MeshcatVisualizer(self.mesh_model, None, self.visual_model)
        viz.initViewer(viewer=meshcat.Visualizer(window=window))
        viz.loadViewerModel(rootNodeName=self.root.removeprefix("/meshcat/"))
        window.send(
            SetObject(
                mg.Sphere(self.effector_radius),
                mg.MeshLambertMaterial(color=EFFECTOR_COLOR),
                _path(f"{self.effector_path}/sphere"),
            )
        )

    def transforms(self, q: NDArray[np.float64]) -> Transforms:
        """(path, world transform) of each visual mesh and of the frame marker at ``q``."""
        pin.forwardKinematics(self.mesh_model, self.mesh_data, self._configure(q))
        pin.updateGeometryPlacements(self.mesh_model, self.mesh_data, self.visual_model, self.visual_data)
        out: Transforms = []
        for gid, obj in enumerate(self.visual_model.geometryObjects):
            T = self.visual_data.oMg[gid].homogeneous.copy()
            T[:3, :3] = T[:3, :3] * np.asarray(obj.meshScale, dtype=float)[None, :]
            out.append((f"{self.root}/visuals/{obj.name}", T))
        self._forward(q)
        out.append((self.effector_path, self.data.oMf[self.frame_id].homogeneous))
        return out


def make_figure(target: KinematicTarget, visual_model: Any | None = None) -> StickFigure:
    """How to draw ``target``: its meshes where there are some, else a stick figure.

    Args:
        target: the robot.
        visual_model: a ``pin.GeometryModel``; None: the target's own meshes
            (``target.visual_model()``) if it has any; False: always a stick figure.
    """
    if visual_model is False:
        return StickFigure(target)
    if visual_model is None:
        loader = getattr(target, "visual_model", None)
        if callable(loader) and getattr(target, "urdf", None) is not None:
            try:
                visual_model = loader()
            except GbPinError as exc:
                from gb_pin.exceptions import ViewerWarning

                warnings.warn(
                    f"{exc}; drawing {target.name!r} as a stick figure", ViewerWarning, stacklevel=3
                )
        elif loader is not None and not callable(loader):
            visual_model = loader
        # else: built from a pin.Model (e.g. a planar chain): no meshes to load
    if visual_model is not None and len(visual_model.geometryObjects) > 0:
        return MeshFigure(target, visual_model)
    return StickFigure(target)


class Scene:
    """A goal-babbling scene: the robot, target set X*, current target, trail, Fig. 3 overlay, camera.

    Args:
        window: where commands go.
        target: the robot.
        targets: (N, n) target set X* on the task axes [m].
        trail: number of trail spheres (past reached positions).
        visual_model: optional ``pin.GeometryModel`` to draw meshes.
    """

    def __init__(
        self,
        window: Window,
        target: KinematicTarget,
        targets: ArrayLike,
        *,
        trail: int = 16,
        visual_model: Any | None = None,
    ) -> None:
        self.window = window
        self.target = target
        self.targets = np.atleast_2d(np.asarray(targets, dtype=float))
        self.figure = make_figure(target, visual_model)
        self.trail = trail
        self.task_axes = np.array(target.chain.task_axes, dtype=np.int64)
        self.home3 = self.figure.effector(target.home)
        self.marker_radius = self.figure.effector_radius
        self.center, self.extent = self._bounds()
        self._trail_buffer: list[NDArray[np.float64]] = []
        self._trail_shown = 0
        self._target_shown: bool | None = None

    # -- geometry ----------------------------------------------------------------------------
    def embed(self, X: ArrayLike) -> NDArray[np.float64]:
        """Task-space points (N, n) as 3-D points: other coordinates from the home effector position."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        out = np.tile(self.home3, (X.shape[0], 1))
        out[:, self.task_axes] = X
        return out

    def _bounds(self) -> tuple[NDArray[np.float64], float]:
        pts = np.vstack([self.figure.skeleton(self.target.home), self.embed(self.targets), np.zeros((1, 3))])
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        return (lo + hi) / 2.0, float(max(np.max(hi - lo) / 2.0, 0.1 * self.figure.size))

    @property
    def planar_normal(self) -> int | None:
        """The world axis normal to a 2-D task (e.g. 2 = z for ``axes="xy"``), else None."""
        if len(self.task_axes) == 2:
            return int(({0, 1, 2} - set(self.task_axes.tolist())).pop())
        return None

    # -- static scene ----------------------------------------------------------------------------
    def draw_static(self) -> None:
        """Background, camera, robot geometry, target set X* and markers (sent once)."""
        from meshcat.commands import Delete, SetObject
        from meshcat.path import Path

        w = self.window
        w.send(Delete(_path(ROOT)))  # a viewer reused for another run starts from a clean scene
        w.send_encoded(*_property_message("/Background", "top_color", [1.0, 1.0, 1.0]))
        w.send_encoded(*_property_message("/Background", "bottom_color", [0.88, 0.90, 0.93]))
        # Everything is shifted so that the workspace centre sits at the camera's orbit centre (the origin).
        shift = translation(-self.center)
        for p in (ROOT, "/Grid", "/Axes"):
            w.send_encoded(*_transform_message(p, shift))
        self._camera()
        self.figure.load(w)

        def path(p: str) -> Path:
            return Path(tuple(s for s in p.split("/") if s))

        w.send(
            SetObject(
                mg.Sphere(self.marker_radius),
                mg.MeshLambertMaterial(color=TARGET_COLOR),
                path(f"{TARGET}/sphere"),
            )
        )
        for k in range(self.trail):
            fade = 1.0 - k / max(self.trail, 1)
            w.send(
                SetObject(
                    mg.Sphere(self.marker_radius * (0.35 + 0.35 * fade)),
                    mg.MeshLambertMaterial(color=EFFECTOR_COLOR, opacity=0.15 + 0.6 * fade, transparent=True),
                    path(f"{TRAIL}/t{k}/sphere"),
                )
            )
            w.send_encoded(*_property_message(f"{TRAIL}/t{k}", "visible", False))
        X3 = self.embed(self.targets) + self._below()
        w.send(
            SetObject(
                _points(X3, TARGET_SET_COLOR, 0.012 * self.figure.size), path=path(f"{TARGET_SET}/points")
            )
        )
        shape = grid_shape(self.targets)
        if shape is not None:
            e = grid_edges(shape)
            w.send(
                SetObject(_segments(X3[e.ravel()], TARGET_SET_COLOR, 0.6), path=path(f"{TARGET_SET}/grid"))
            )
        self.pose(self.target.home, None, None)

    def _below(self) -> NDArray[np.float64]:
        """A small offset away from the camera, so that flat overlays never hide the robot."""
        off = np.zeros(3)
        normal = self.planar_normal
        off[2 if normal is None else normal] = -0.01 * self.figure.size
        return off

    def _camera(self) -> None:
        """Place meshcat's default camera (properties set directly: pinocchio's helpers raise on 0.3.2)."""
        # The arm explores beyond the targets and its home posture: leave a margin around them.
        half = self.extent * 1.5
        # Distance at which the vertical field of view spans the workspace (4:3 window or wider).
        dist = half / math.tan(math.radians(CAMERA_FOV / 2.0))
        normal = self.planar_normal
        if normal is None:
            view = np.array([1.0, -1.2, 0.9])
        else:
            view = np.zeros(3)
            view[normal] = 1.0
            # A hair off-axis: OrbitControls cannot look exactly along its up vector.
            view[1 if normal == 2 else 2] = -1e-3
        offset = view / np.linalg.norm(view) * dist
        # meshcat's camera sits in a frame rotated +90 deg about x (three.js is y-up):
        # world (a, b, c) is (a, c, -b) there.
        rotated = [float(offset[0]), float(offset[2]), float(-offset[1])]
        cam = "/Cameras/default/rotated/<object>"
        self.window.send_encoded(*_property_message(cam, "position", rotated))
        self.window.send_encoded(*_property_message(cam, "near", 0.01 * dist))
        self.window.send_encoded(*_property_message(cam, "far", 100.0 * dist))
        self.camera_distance = dist

    # -- frames -------------------------------------------------------------------------------------
    def frame_transforms(
        self, q: NDArray[np.float64], target: NDArray[np.float64] | None
    ) -> tuple[Transforms, NDArray[np.float64]]:
        """Transforms of the robot and the current-target marker, and the 3-D effector position."""
        tf = self.figure.transforms(q)
        effector = tf[-1][1][:3, 3].copy()
        if target is not None and np.all(np.isfinite(target)):
            tf.append((TARGET, translation(self.embed(target)[0])))
        return tf, effector

    def pose(
        self, q: NDArray[np.float64], target: NDArray[np.float64] | None, reached: NDArray[np.float64] | None
    ) -> None:
        """Draw one live frame: posture ``q``, target x* (hidden if None or NaN), the trail of reached points.

        The frame's commands go to the window in one batch (one wake-up of the server thread).
        """
        tf, _ = self.frame_transforms(q, target)
        batch = [_transform_message(p, T) for p, T in tf]
        show_target = target is not None and bool(np.all(np.isfinite(target)))
        if show_target != self._target_shown:
            batch.append(_property_message(TARGET, "visible", show_target))
            self._target_shown = show_target
        if reached is not None and self.trail > 0:
            self._trail_buffer.insert(0, self.embed(reached)[0])
            del self._trail_buffer[self.trail :]
            batch.extend(
                _transform_message(f"{TRAIL}/t{k}", translation(p3))
                for k, p3 in enumerate(self._trail_buffer)
            )
            # Each sphere is shown once, when it first has a position.
            while self._trail_shown < len(self._trail_buffer):
                batch.append(_property_message(f"{TRAIL}/t{self._trail_shown}", "visible", True))
                self._trail_shown += 1
        self.window.send_batch(batch)

    def hide(self, path: str, hidden: bool = True) -> None:
        """Hide (or show) a part of the scene, e.g. :data:`OVERLAY`."""
        self.window.send_encoded(*_property_message(path, "visible", not hidden))

    # -- Fig. 3 overlay ------------------------------------------------------------------------------
    def overlay(self, postures: NDArray[np.float64], few: int = 5) -> dict[str, NDArray[np.float64]]:
        """Draw the paper's Fig. 3: target grid X*, reached grid f(g(x*)), postures g(x*) for ``few`` targets.

        Args:
            postures: (N, m) estimates g(x*) for the target set.
            few: number of postures drawn.

        Returns:
            The drawn arrays (``reached`` (N, 3), ``skeletons`` (few, 2S, 3)), for tests.
        """
        from meshcat.commands import SetObject
        from meshcat.path import Path

        def path(p: str) -> Path:
            return Path(tuple(s for s in p.split("/") if s))

        postures = np.atleast_2d(postures)
        reached = np.array([self.figure.effector(q) for q in postures])
        w = self.window
        below = self._below()
        w.send(
            SetObject(
                _points(reached + below, REACHED_COLOR, 0.014 * self.figure.size),
                path=path(f"{OVERLAY}/reached_points"),
            )
        )
        shape = grid_shape(self.targets)
        if shape is not None:
            e = grid_edges(shape)
            segs = reached[e.ravel()]
        else:
            # No grid: join each target to where its estimate reaches.
            segs = np.stack([self.embed(self.targets), reached], axis=1).reshape(-1, 3)
        w.send(SetObject(_segments(segs + below, REACHED_COLOR), path=path(f"{OVERLAY}/reached_grid")))
        chosen = spread_indices(self.targets, few)
        skeletons = np.array([self.figure.skeleton(postures[i]) for i in chosen])
        w.send(
            SetObject(
                _segments(skeletons.reshape(-1, 3) + below, POSTURE_COLOR, 0.7),
                path=path(f"{OVERLAY}/postures"),
            )
        )
        return {"reached": reached, "skeletons": skeletons}

    # -- replay animation ----------------------------------------------------------------------------
    def animation(
        self,
        postures: NDArray[np.float64],
        targets: NDArray[np.float64],
        positions: NDArray[np.float64],
        times: NDArray[np.float64],
        fps: float,
        trail_stride: int = 1,
    ) -> dict[str, Any]:
        """A ``set_animation`` command replaying recorded steps (looping forever).

        Args:
            postures: (R, m) executed postures.
            targets: (R, n) targets x*_t, NaN during home returns [m].
            positions: (R, n) reached positions [m].
            times: (R,) keyframe times in frames (e.g. time steps since the first recorded).
            fps: frames per second of playback.
            trail_stride: recorded steps between trail spheres.
        """
        R = postures.shape[0]
        per_path: dict[str, list[NDArray[np.float64]]] = {}
        for q in postures:
            for p, T in self.figure.transforms(q):
                per_path.setdefault(p, []).append(T)
        t32 = np.asarray(times, dtype=np.float32)
        clips: list[dict[str, Any]] = []

        def f32(a: NDArray[Any]) -> umsgpack.Ext:
            return umsgpack.Ext(0x17, np.ascontiguousarray(a, dtype=np.float32).tobytes())

        def clip(path: str, tracks: list[dict[str, Any]]) -> None:
            clips.append({"path": path, "clip": {"fps": float(fps), "name": "default", "tracks": tracks}})

        for p, Ts in per_path.items():
            M = np.array(Ts)
            tracks = [
                {"name": ".position", "type": "vector3", "times": f32(t32), "values": f32(M[:, :3, 3])},
                {
                    "name": ".quaternion",
                    "type": "quaternion",
                    "times": f32(t32),
                    "values": f32(quaternions(M[:, :3, :3])),
                },
            ]
            scale = np.linalg.norm(M[:, :3, :3], axis=1)
            if not np.allclose(scale, 1.0):
                tracks.append({"name": ".scale", "type": "vector3", "times": f32(t32), "values": f32(scale)})
            clip(p, tracks)
        finite = np.all(np.isfinite(targets), axis=1)
        T3 = self.embed(np.where(finite[:, None], targets, 0.0))
        clip(
            TARGET,
            [
                {"name": ".position", "type": "vector3", "times": f32(t32), "values": f32(T3)},
                {"name": ".visible", "type": "boolean", "times": f32(t32), "values": finite.tolist()},
            ],
        )
        P3 = self.embed(positions)
        for k in range(self.trail):
            lag = k * trail_stride
            idx = np.maximum(np.arange(R) - lag, 0)
            clip(
                f"{TRAIL}/t{k}",
                [
                    {"name": ".position", "type": "vector3", "times": f32(t32), "values": f32(P3[idx])},
                    {
                        "name": ".visible",
                        "type": "boolean",
                        "times": f32(t32),
                        "values": (np.arange(R) >= lag).tolist(),
                    },
                ],
            )
        return {
            "type": "set_animation",
            "path": "",
            "animations": clips,
            "options": {"play": True, "repetitions": math.inf},
        }

    def send_animation(self, command: dict[str, Any]) -> None:
        """Send an animation built by :meth:`animation` (floats packed as float32)."""
        self.window.send_encoded(*encode(command, single=True))
